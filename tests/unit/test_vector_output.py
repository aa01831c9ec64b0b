"""Figures as vector files beside the PNG: PDF with its fonts embedded as TrueType, SVG with
text as paths, both well formed (the PDF's cross-reference table points at its objects, the
SVG parses as XML), the same bytes run to run, carrying the figure's key; `whirl plot
--format` writes them."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import pytest
from click.testing import CliRunner

from whirl_cli.cli import cli
from whirl_cli.output import store
from whirl_cli.plots.diagrams import bifurcation_diagram
from whirl_cli.plots.files import rendered_formats, stored_key_in
from whirl_cli.results import StudyResult

KEY = "0123456789abcdef" * 4


def check_pdf(data: bytes) -> None:
    """A PDF whose trailer's startxref points at its cross-reference table, each of whose
    in-use entries points at the object it numbers; fonts embedded as TrueType, none type 3."""
    assert data.startswith(b"%PDF-1.") and data.rstrip().endswith(b"%%EOF")
    start = int(re.search(rb"startxref\s+(\d+)\s+%%EOF\s*$", data).group(1))
    assert data[start:start + 4] == b"xref"
    head = re.match(rb"xref\s+(\d+) (\d+)\s+", data[start:])
    first, count = int(head.group(1)), int(head.group(2))
    entries = re.findall(rb"(\d{10}) (\d{5}) ([nf])", data[start + head.end():])[:count]
    assert len(entries) == count
    for number, (offset, _, used) in enumerate(entries, start=first):
        if used == b"n":
            assert re.match(rb"%d 0 obj" % number, data[int(offset):]), number
    assert b"/FontFile2" in data and b"/Type3" not in data


def check_svg(data: bytes) -> None:
    """An SVG document that parses as XML, sized in points, with no text element (text is
    drawn as paths, needing no font)."""
    root = ET.fromstring(data)
    assert root.tag == "{http://www.w3.org/2000/svg}svg"
    assert root.get("width").endswith("pt") and root.get("height").endswith("pt")
    assert not root.findall(".//{http://www.w3.org/2000/svg}text")
    assert root.findall(".//{http://www.w3.org/2000/svg}path")


def test_vector_files_parse_embed_fonts_repeat_and_carry_the_key(continuation):  # noqa: F811
    files = [rendered_formats(bifurcation_diagram(continuation, title="theta"),
                              ("png", "pdf", "svg"), 100, KEY) for _ in range(2)]
    assert files[0] == files[1]  # the same bytes each time
    check_pdf(files[0]["pdf"])
    check_svg(files[0]["svg"])
    assert stored_key_in(files[0]["pdf"]) == stored_key_in(files[0]["svg"]) == KEY
    assert files[0]["png"].startswith(b"\x89PNG")


def test_plot_command_writes_each_format(tmp_path, continuation):  # noqa: F811
    result_file = tmp_path / "r.h5"
    store.write(StudyResult("study", "classical", (continuation,), (), ()), result_file)
    done = CliRunner().invoke(cli, ["plot", str(result_file), "--kind", "bifurcation",
                                    "--format", "pdf,svg"])
    assert done.exit_code == 0, done.output
    stem = tmp_path / "r_hopf_K1_bifurcation"
    check_pdf(stem.with_suffix(".pdf").read_bytes())
    check_svg(stem.with_suffix(".svg").read_bytes())
    assert stem.with_suffix(".png").read_bytes().startswith(b"\x89PNG")


@pytest.mark.parametrize("given", ["jpg", "png,eps", ","])
def test_unknown_format_is_refused(tmp_path, given):
    done = CliRunner().invoke(cli, ["figures", str(tmp_path), "--format", given])
    assert done.exit_code == 2
    assert "expected formats among png, pdf, svg" in done.output


def text_sizes(pdf: bytes) -> list[float]:
    """The size of every text the PDF sets (its ``Tf`` operators), points."""
    import zlib

    sizes = []
    for stream in re.findall(rb"stream\r?\n(.*?)\r?\nendstream", pdf, re.S):
        try:
            content = zlib.decompress(stream)
        except zlib.error:
            continue
        sizes += [float(s) for s in re.findall(rb"/F\d+ ([\d.]+) Tf", content)]
    return sizes


@pytest.mark.parametrize("column, width", [("single", 3.5), ("double", 7.2)])
def test_a_sheet_set_in_a_journal_column_is_that_wide_with_legible_text(
        tmp_path, continuation, column, width):  # noqa: F811
    from tests.unit.plot_data import STUDY, result_with
    from whirl_cli.figures.draw import sheet_files
    from whirl_cli.figures.sheet import load_sheet

    (tmp_path / "a.yaml").write_text(STUDY)
    (tmp_path / "f.yaml").write_text(
        f'figure: "3.1"\ncaption: a bifurcation diagram and its period\ncolumn: {column}\n'
        "layout: [2, 1]\nsize: [6, 7]\npanels:\n  - {kind: bifurcation, study: a.yaml}\n"
        "  - {kind: period, study: a.yaml}\n")
    sheet = load_sheet(tmp_path / "f.yaml")
    assert sheet.figure_size == pytest.approx((width, width * 7 / 6))
    files = sheet_files(sheet, {tmp_path / "a.yaml": result_with(continuation, 10.0)},
                        ("png", "pdf", "svg"), 100)
    check_pdf(files["pdf"])
    check_svg(files["svg"])
    box = re.search(rb"/MediaBox \[\s*0 0 ([\d.]+) ([\d.]+)\s*\]", files["pdf"])
    assert float(box.group(1)) == pytest.approx(72 * width)
    sizes = text_sizes(files["pdf"])
    assert sizes and 6 <= min(sizes) and max(sizes) <= 9, sorted(set(sizes))


def test_a_column_too_flat_for_its_size_is_refused(tmp_path):
    from whirl_cli.errors import StudyError
    from whirl_cli.figures.sheet import load_sheet

    (tmp_path / "a.yaml").write_text("name: s\nmodel: classical\n")
    (tmp_path / "f.yaml").write_text(
        'figure: "3.1"\ncaption: c\ncolumn: single\nsize: [40, 5]\n'
        "panels:\n  - {kind: bifurcation, study: a.yaml}\n")
    with pytest.raises(StudyError, match=r"f.yaml:3: column: 3.5 in wide, the figure would be "
                                         r"0.438 in high, outside 1 to 40; change `size`"):
        load_sheet(tmp_path / "f.yaml")
