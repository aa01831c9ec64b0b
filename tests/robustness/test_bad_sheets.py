"""Bad sheets through ``whirl figures``: a sheet that is not valid, or whose drawing fails,
is reported as not drawn with its reason and the others are still drawn; the index is
written and the exit status is 1."""

from __future__ import annotations

from click.testing import CliRunner

from whirl_cli.cli import cli
from whirl_cli.figures import draw

LINEAR = ("name: lin\nmodel: classical\nplots: []\n"
          "linear:\n  sweeps:\n    - {parameter: V, range: [10, 100], points: 20}\n")
PANEL = "panels:\n  - {kind: linear, study: ../lin.yaml}\n"
SHEETS = {
    "good.yaml": 'figure: "9.1"\ncaption: drawn\n' + PANEL,
    "pixels.yaml": 'figure: "9.2"\ncaption: in pixels\nsize: [1200, 560]\n' + PANEL,
    "empty.yaml": "",
    "crash.yaml": 'figure: "9.4"\ncaption: its drawing fails\n' + PANEL,
    "invalid_study.yaml": 'figure: "9.5"\ncaption: c\n'
                          "panels:\n  - {kind: linear, study: ../bad.yaml}\n",
}


def test_one_bad_sheet_does_not_stop_the_others(tmp_path, monkeypatch):
    (tmp_path / "lin.yaml").write_text(LINEAR)
    (tmp_path / "bad.yaml").write_text("name: bad\nmodel: classical\nparameters: {V: ten}\n")
    folder = tmp_path / "sheets"
    folder.mkdir()
    for name, text in SHEETS.items():
        (folder / name).write_text(text)
    drawn = draw.draw_sheet

    def failing(sheet, results):
        if sheet.figure == "9.4":
            raise MemoryError("drawing needs too much memory")
        return drawn(sheet, results)

    monkeypatch.setattr(draw, "draw_sheet", failing)
    out = tmp_path / "figures"
    result = CliRunner().invoke(cli, ["figures", str(folder), "-o", str(out), "--results",
                                      str(tmp_path / "results"), "-j", "1"])
    assert result.exit_code == 1, result.output
    assert "internal error" not in result.output and "Traceback" not in result.output
    assert sorted(p.name for p in out.iterdir()) == ["fig9_1.pdf", "fig9_1.png", "index.html"]
    lines = result.output.splitlines()
    for expected in (
            f"figure 9.2: not drawn: {folder / 'pixels.yaml'}:3: size[0]: expected inches, 1 "
            "to 40, got 1200 (the size is in inches, not pixels)",
            f"figure empty.yaml: not drawn: {folder / 'empty.yaml'}: the sheet file is empty",
            f"figure 9.4: not drawn: {folder / 'crash.yaml'}: MemoryError: drawing needs too "
            "much memory",
            # the invalid study's messages name its file once
            f"figure 9.5: not drawn: {tmp_path / 'bad.yaml'}:3: parameters.V: expected a "
            "number, got 'ten'"):
        assert expected in lines, result.output
    assert "4 of 5 figures not drawn" in result.output
    page = (out / "index.html").read_text()
    assert page.count("<section") == 5 and page.count("not drawn: ") == 4
