"""The index's table of the thesis's numbers beside whirl's: a sheet's `thesis:` entries
checked like the rest of it, whirl's point picked from a result by type, branch and
nearness, the relative difference to a value or a range, the table's cells, and the redraw
command the page prints."""

from __future__ import annotations

import numpy as np
import pytest

from whirl_cli.cli import invoked_as
from whirl_cli.errors import StudyError
from whirl_cli.figures.build import redraw_command
from whirl_cli.figures.index import Comparison, index_html, numbers_table
from whirl_cli.figures.numbers import comparisons, relative_difference
from whirl_cli.figures.sheet import load_sheet
from whirl_cli.results import (
    ContinuationResult,
    LocateStatus,
    PointType,
    SpecialPoint,
    StudyResult,
)

STUDY = "name: s\nmodel: classical\n"
HEAD = 'figure: "3.14"\ncaption: c\npanels:\n  - {kind: bifurcation, study: a.yaml}\n'


def point(kind: PointType, value: float, branch: str = "main", unit: str = "N m/rad",
          **extra) -> SpecialPoint:
    return SpecialPoint(branch, 0, int(kind), ("K_theta",), np.array([value]), np.zeros(4),
                        float("nan"), False, parameter_units=(unit,), **extra)


def result(*points: SpecialPoint) -> StudyResult:
    return StudyResult("case", "classical",
                       (ContinuationResult("k1", "one-parameter", (), points),), (), ())


def sheet_with(tmp_path, thesis: str):
    (tmp_path / "a.yaml").write_text(STUDY)
    (tmp_path / "b.yaml").write_text(STUDY)
    path = tmp_path / "f.yaml"
    path.write_text(HEAD + "thesis:\n" + thesis)
    return load_sheet(path)


def rows(tmp_path, thesis: str, stored: StudyResult) -> list[Comparison]:
    sheet = sheet_with(tmp_path, thesis)
    return comparisons(sheet, {tmp_path / "a.yaml": stored}.__getitem__)


def test_relative_difference_to_a_value_or_the_nearer_end_of_a_range():
    assert relative_difference(0.0808, 0.08, None) == pytest.approx(0.01)
    assert relative_difference(-0.0808, -0.08, None) == pytest.approx(-0.01)
    assert relative_difference(0.036, None, (0.03, 0.04)) == 0.0
    assert relative_difference(0.044, None, (0.03, 0.04)) == pytest.approx(0.1)
    assert relative_difference(0.027, None, (0.03, 0.04)) == pytest.approx(-0.1)
    assert relative_difference(0.1, None, None) is None
    assert relative_difference(0.1, 0.0, None) is None


def test_whirl_point_is_the_nearest_of_its_type_on_its_branch(tmp_path):
    stored = result(point(PointType.HB, 0.2888), point(PointType.HB, 0.0807),
                    point(PointType.HB, 0.0846, "secondary"), point(PointType.BP, 0.0360),
                    point(PointType.HB, 0.0801, status=LocateStatus.REJECTED),
                    point(PointType.HB, 0.0802, artefact=True))
    found = rows(tmp_path, "  - {name: HB1, value: 0.08, unit: N m/rad, point: HB}\n"
                           "  - {name: HB2, value: 0.28, unit: N m/rad, point: HB}\n"
                           "  - {name: sec, near: 0.0, unit: N m/rad, point: HB, "
                           "branch: secondary}\n"
                           "  - {name: BP, between: [0.03, 0.04], unit: N m/rad, point: BP}\n",
                 stored)
    assert [(r.name, r.whirl) for r in found] == [("HB1", 0.0807), ("HB2", 0.2888),
                                                  ("sec", 0.0846), ("BP", 0.0360)]
    assert found[0].difference == pytest.approx(0.0807 / 0.08 - 1)
    assert found[2].difference is None and found[3].difference == 0.0
    assert found[0].where == "case: main"


def test_missing_point_or_other_unit_is_the_rows_problem(tmp_path):
    found = rows(tmp_path, "  - {name: onset, value: 7.8, unit: m/s, point: HB}\n"
                           "  - {name: fold, value: 0.4, unit: N m/rad, point: LPC}\n",
                 result(point(PointType.HB, 0.29)))
    assert [r.whirl for r in found] == [None, None]
    assert found[0].problem == "whirl stores K_theta in N m/rad, not m/s"
    assert found[1].problem == "no LPC point"


@pytest.mark.parametrize("thesis, expected", [
    ("  - {name: x, value: 1, between: [0, 2], unit: u, point: HB}\n",
     "f.yaml:6: thesis[0]: give at most one of `value` and `between`"),
    ("  - {name: x, unit: u, point: HB}\n",
     "f.yaml:6: thesis[0]: give `near` (where whirl's point lies)"),
    ("  - {name: x, value: 1, unit: u, point: XX}\n",
     "f.yaml:6: thesis[0].point: expected one of BP, LP, HB"),
    ("  - {name: x, value: 1, unit: u, point: HB, study: b.yaml}\n",
     "f.yaml:6: thesis[0].study: expected a study a panel of the sheet draws, got b.yaml"),
])
def test_bad_thesis_entries_name_file_line_key_and_reason(tmp_path, thesis, expected):
    with pytest.raises(StudyError) as caught:
        sheet_with(tmp_path, thesis)
    assert expected in str(caught.value)


def test_table_cells_hold_the_thesis_value_and_whirls_exactly():
    table = numbers_table((
        Comparison("3.14", "HB <1>", 0.08, None, "N m/rad", "HB", 0.08068720150912345,
                   0.0085899, "case: main"),
        Comparison("3.5", "onset", 7.8, None, "m/s", "HB", problem="no HB point"),
        Comparison("3.14", "BP", None, (0.03, 0.04), "N m/rad", "BP", 0.036, 0.0),
        Comparison("3.25", "homoclinic", None, None, "N m/rad", "HOMOCLINIC", -0.0815)))
    assert table.index(">3.5<") < table.index(">3.14<")  # in figure order
    assert 'data-value="0.08068720150912345">0.08069<' in table
    assert "HB &lt;1&gt;" in table and "+0.9 %" in table
    assert '<td class="problem">no HB point</td>' in table
    assert ">0.03 to 0.04<" in table and ">within<" in table
    assert ">not recovered<" in table
    assert numbers_table(()) == ""
    page = index_html([], "t", {"whirl": "1"}, (), redraw=".venv/bin/whirl figures s")
    assert "<li>redraw: <code>.venv/bin/whirl figures s</code></li>" in page


def test_redraw_command_repeats_the_call():
    from pathlib import Path

    assert redraw_command(".venv/bin/whirl", ["sheets/thesis ch3"], Path("figures"),
                          Path("results"), ("png", "pdf")) == (
        ".venv/bin/whirl figures 'sheets/thesis ch3' -o figures --results results")
    assert redraw_command("/usr/bin/python3 -m whirl_cli", ["s"], Path("o"), Path("r"),
                          ("png", "svg")).endswith("--results r --format png,svg")


@pytest.mark.parametrize("argv0, expected", [
    (".venv/bin/whirl", ".venv/bin/whirl"),
    ("/opt/my env/bin/whirl", "'/opt/my env/bin/whirl'"),
    ("/src/whirl_cli/__main__.py", "/usr/bin/python3 -m whirl_cli"),
    ("pytest", "whirl"),
])
def test_invoked_as_is_how_whirl_was_called(argv0, expected):
    assert invoked_as(argv0, "/usr/bin/python3") == expected


def test_a_study_without_result_is_the_rows_problem(tmp_path):
    from whirl_cli.errors import WhirlError

    def failed(path):
        raise WhirlError(f"{path.name}: AUTO failed")

    sheet = sheet_with(tmp_path, "  - {name: HB1, value: 0.08, unit: N m/rad, point: HB}\n")
    (row,) = comparisons(sheet, failed)
    assert (row.whirl, row.problem, row.value) == (None, "a.yaml: AUTO failed", 0.08)
