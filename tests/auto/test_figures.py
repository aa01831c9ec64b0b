"""``whirl figures`` on the real AUTO: sheets run the studies they need, draw one PNG per
sheet and an index; a second run reuses every result; a figure that cannot be drawn is
reported and the others still are; every shipped sheet is valid."""

from __future__ import annotations

from pathlib import Path

import h5py
import pytest
from click.testing import CliRunner

from whirl_cli.cli import cli
from whirl_cli.figures.build import load_sheets, make_figures
from whirl_cli.output import store

from ..conftest import ROOT
from .helpers import copy_studies

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def sheets(folder: Path) -> Path:
    folder.mkdir()
    (folder / "fig9_1.yaml").write_text(
        'figure: "9.1"\ncaption: bifurcation and linear sweep\nlayout: [1, 2]\npanels:\n'
        "  - {kind: bifurcation, study: ../studies/linear_case2.yaml}\n"
        "  - {kind: linear, study: ../studies/linear_datum_airspeed.yaml}\n")
    (folder / "fig9_2.yaml").write_text(
        'figure: "9.2"\ncaption: two results on one axes\npanels:\n'
        "  - kind: bifurcation\n    overlay:\n"
        "      - {study: ../studies/linear_case2.yaml, label: case 2}\n"
        "      - {study: ../studies/linear_datum_airspeed.yaml, label: datum}\n")
    return folder


def test_figures_run_draw_index_and_reuse(tmp_path):
    copy_studies(tmp_path / "studies")
    folder = sheets(tmp_path / "sheets")
    out, results = tmp_path / "figures", tmp_path / "results"
    outcomes = make_figures([folder], out, results, jobs=2)
    assert [o.problem for o in outcomes] == ["", ""]
    assert sorted(p.name for p in out.iterdir()) == [
        "fig9_1.pdf", "fig9_1.png", "fig9_2.pdf", "fig9_2.png", "index.html"]  # PNG and PDF
    for name in ("fig9_1", "fig9_2"):
        assert (out / f"{name}.png").read_bytes()[:8] == PNG_MAGIC
        assert (out / f"{name}.pdf").read_bytes()[:5] == b"%PDF-"
    page = (out / "index.html").read_text()
    assert page.index("Figure 9.1") < page.index("Figure 9.2")
    assert "studies/linear_case2.yaml" in page and "whirl figures" in page
    # the results behind them are the studies' own results (stored, readable)
    stored = sorted(p.name for p in results.iterdir())
    assert stored == ["linear-case2.h5", "linear-datum-airspeed.h5"]
    assert store.read(results / "linear-case2.h5").continuations
    stamps = {p: p.stat().st_mtime_ns for p in [*results.iterdir(), *out.glob("fig*")]}
    again = make_figures([folder], out, results, jobs=2)
    assert [(o.image.name, o.reused) for o in again] == [("fig9_1.png", True),
                                                         ("fig9_2.png", True)]
    # nothing rerun, nothing redrawn
    assert {p: p.stat().st_mtime_ns for p in [*results.iterdir(), *out.glob("fig*")]} == stamps
    (out / "fig9_1.pdf").unlink()  # a format missing: that figure is drawn again
    assert [o.reused for o in make_figures([folder], out, results, jobs=2)] == [False, True]
    stamps = {p: p.stat().st_mtime_ns for p in [*results.iterdir(), *out.glob("fig*")]}
    sheet = folder / "fig9_2.yaml"
    sheet.write_text(sheet.read_text().replace("two results", "2 results"))
    changed = make_figures([folder], out, results, jobs=2)
    assert [o.reused for o in changed] == [True, False]  # only the edited sheet is redrawn


def test_a_figure_that_cannot_be_drawn_is_reported(tmp_path):
    copy_studies(tmp_path / "studies", ("linear_datum_airspeed",))
    folder = tmp_path / "sheets"
    folder.mkdir()
    (folder / "good.yaml").write_text(
        'figure: "9.1"\ncaption: c\npanels:\n'
        "  - {kind: linear, study: ../studies/linear_datum_airspeed.yaml}\n")
    (folder / "bad.yaml").write_text(
        'figure: "9.2"\ncaption: c\npanels:\n'
        "  - {kind: period, study: ../studies/linear_datum_airspeed.yaml}\n")
    out = tmp_path / "figures"
    result = CliRunner().invoke(cli, ["figures", str(folder), "-o", str(out), "--results",
                                      str(tmp_path / "results"), "-j", "1"])
    assert result.exit_code == 1
    assert "figure 9.2: not drawn" in result.output
    assert "nothing to draw as period: no periodic branch" in result.output
    assert sorted(p.name for p in out.iterdir()) == ["fig9_1.pdf", "fig9_1.png", "index.html"]
    assert "not drawn" in (out / "index.html").read_text()


def test_bad_sheet_runs_nothing(tmp_path):
    """A sheet that is not valid runs nothing; it is listed in the index as not drawn."""
    folder = tmp_path / "sheets"
    folder.mkdir()
    (folder / "bad.yaml").write_text('figure: "9.1"\ncaption: c\npanels:\n'
                                     "  - {kind: linear, study: nowhere.yaml}\n")
    result = CliRunner().invoke(cli, ["figures", str(folder), "-o", str(tmp_path / "f"),
                                      "--results", str(tmp_path / "r")])
    assert result.exit_code == 1
    assert "bad.yaml:4: panels[0].study: no study file" in result.output
    assert not (tmp_path / "r").exists()
    assert [p.name for p in (tmp_path / "f").iterdir()] == ["index.html"]
    assert "not drawn: " in (tmp_path / "f" / "index.html").read_text()


#: The 28 result figures of thesis chapter 3 (shared/figures.md: 3.3 to 3.30).
CHAPTER_3 = {"3.3", "3.4", "3.5", "3.6", "3.7", "3.8", "3.9", "3.10", "3.11", "3.12", "3.13",
             "3.14", "3.15", "3.16", "3.17", "3.18", "3.19", "3.20", "3.21", "3.22", "3.23",
             "3.24", "3.25", "3.26", "3.27", "3.28", "3.29", "3.30"}


def test_shipped_sheets_are_valid_and_cover_the_figures_list():
    shipped, refused = load_sheets([ROOT / "sheets" / "thesis_ch3"])
    assert refused == []
    assert len(CHAPTER_3) == 28
    assert {s.figure for s in shipped} == CHAPTER_3
    for sheet in shipped:
        for path in sheet.studies():
            assert path.is_relative_to(ROOT / "studies"), path


@pytest.mark.parametrize("name", ["linear-case2.h5"])
def test_results_of_figures_are_sweep_results(tmp_path, name):
    """The figures' results folder is a sweep's: `whirl sweep` then finds them up to date."""
    copy_studies(tmp_path / "studies")
    make_figures([sheets(tmp_path / "sheets")], tmp_path / "f", tmp_path / "r", jobs=1)
    with h5py.File(tmp_path / "r" / name) as stored:
        assert stored.attrs["study_sha256"]
    result = CliRunner().invoke(cli, ["sweep", str(tmp_path / "studies"), "-o",
                                      str(tmp_path / "r"), "--no-plots"])
    assert result.exit_code == 0 and "2 up to date" in result.output


def test_piped_figures_say_when_each_study_starts_and_ends(tmp_path):
    """Not on a terminal (a pipe, a batch log) there is no progress bar: a line as each study
    starts, before its line as it ends, so a long first study is not silence."""
    import subprocess

    from ..robustness.helpers import WHIRL, environment

    copy_studies(tmp_path / "studies")
    folder = sheets(tmp_path / "sheets")
    done = subprocess.run([str(WHIRL), "figures", str(folder), "-o", str(tmp_path / "figures"),
                           "--results", str(tmp_path / "results"), "-j", "2"],
                          env=environment(), capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    lines = done.stderr.splitlines()
    for name in ("linear-case2", "linear-datum-airspeed"):
        started = [k for k, line in enumerate(lines) if line.split() == ["start", name]]
        ended = [k for k, line in enumerate(lines) if line.split()[1:3] == ["ok", name]]
        assert len(started) == len(ended) == 1 and started[0] < ended[0], lines


def test_index_numbers_are_the_results_and_the_sheets_and_its_command_redraws(tmp_path):
    """Two shipped sheets (3.5, 3.14) with their studies, drawn by the console script from
    their folder as `make figures` does: the index's table holds each sheet's `thesis:` values
    and, beside them, the special points stored in the result files (read with h5py); its
    redraw command, run as printed from that folder, redraws nothing and succeeds."""
    import html
    import re
    import subprocess

    import yaml

    from ..robustness.helpers import WHIRL, environment

    copy_studies(tmp_path / "studies" / "thesis_ch3",
                 ("linear_case2", "linear_ktheta", "linear_datum_airspeed"))
    sheets = tmp_path / "sheets" / "thesis_ch3"
    sheets.mkdir(parents=True)
    for name in ("fig3_5", "fig3_14"):
        (sheets / f"{name}.yaml").write_text(
            (ROOT / "sheets" / "thesis_ch3" / f"{name}.yaml").read_text())
    command = [str(WHIRL), "figures", "sheets/thesis_ch3", "-o", "figs", "--results", "res"]
    done = subprocess.run(command, cwd=tmp_path, env=environment(), capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    page = (tmp_path / "figs" / "index.html").read_text()

    declared = {}
    for name in ("fig3_5", "fig3_14"):
        sheet = yaml.safe_load((sheets / f"{name}.yaml").read_text())
        for number in sheet["thesis"]:
            study = number.get("study", sheet["panels"][0]["study"])
            declared[number["name"]] = (number, Path(study).stem.replace("_", "-"))
    rows = re.findall(r"<tr><td><a [^>]*>([\d.]+)</a></td><td>([^<]*)</td><td>(\w+)</td>"
                      r'<td class="n">([^<]*)</td><td class="n" data-value="([^"]+)">', page)
    assert sorted(html.unescape(r[1]) for r in rows) == sorted(declared)
    for _, name, point, thesis, whirl in rows:
        number, stem = declared[html.unescape(name)]
        assert point == number["point"]
        expected = (f"{number['between'][0]:g} to {number['between'][1]:g}"
                    if "between" in number else f"{number['value']:g}")
        assert thesis == expected
        with h5py.File(tmp_path / "res" / f"{stem}.h5") as stored:
            (group,) = stored["continuations"].values()
            points = group["special_points"]
            values = [float(v) for v, kind in zip(points["parameters"][:, 0],
                                                  points["type_name"][()], strict=True)
                      if kind.decode() == point]
        assert float(whirl) in values

    redraw = html.unescape(re.search(r"<li>redraw: <code>([^<]*)</code>", page).group(1))
    assert redraw == " ".join(command)
    again = subprocess.run(redraw, shell=True, cwd=tmp_path, env=environment(),
                           capture_output=True, text=True, timeout=300)
    assert again.returncode == 0, again.stderr
    assert "2 of 2 figures (2 up to date, not redrawn)" in again.stdout
