"""``whirl summary`` (issue 17, item 4): what it prints equals what the HDF5 file holds, read
here with h5py alone; JSON round-trips; CSV parses; a bad file is one line, exit 1."""

from __future__ import annotations

import csv
import io
import json
import math
import subprocess
import sys
from dataclasses import replace

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

from whirl_cli.cli import cli
from whirl_cli.output import store
from whirl_cli.output.summary import Table
from whirl_cli.results import (
    Branch,
    BranchKind,
    ContinuationResult,
    LocateStatus,
    SpecialPoint,
    StudyResult,
)

from ..conftest import ROOT

REFERENCES = (ROOT / "tests" / "regression" / "references" / "hardening_case2.h5",
              ROOT / "tests" / "regression" / "references" / "linear_datum_airspeed.h5",
              ROOT / "tests" / "data" / "legacy_hardening_case2.h5")
CLASSICAL_DOFS = ("theta", "psi")  # the classical model's dofs, in these files' states
#: The thesis's parameter names the legacy file stores, and their canonical names (whirl
#: reads older files with canonical names).
ALIASES = {"K1": "K_theta"}
PLAIN = {0, 4, -4, 9, -9}  # regular, RG, UZ, EP, MX: not listed


def text(value) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def expected_rows(path, dofs) -> list[dict]:
    """The summary's rows, built from the file with h5py (no whirl code)."""
    rows = []
    with h5py.File(path, "r") as handle:
        for name, group in handle["continuations"].items():
            points = group["special_points"]
            names = [ALIASES.get(text(n), text(n)) for n in points["parameters"].attrs["names"]]
            for k in range(len(points["index"])):
                if int(points["point_type"][k]) in PLAIN:
                    continue
                branch = group["branches"][text(points["branch"][k])]
                units = [text(u) for u in branch["parameters"].attrs["units"]]
                row = {"continuation": name, "branch": text(points["branch"][k]),
                       "type": text(points["type_name"][k])}
                for j, parameter in enumerate(names):
                    row[f"{parameter} [{units[j]}]"] = float(points["parameters"][k, j])
                states = [text(n) for n in branch["state_max"].attrs["names"]]
                state_units = [text(u) for u in branch["state_max"].attrs["units"]]
                for dof in dofs:
                    j = states.index(dof)
                    value = float(points["state"][k, j])
                    if state_units[j] == "rad":
                        row[f"{dof} [deg]"] = value * 180.0 / math.pi
                    else:
                        row[f"{dof} [{state_units[j]}]"] = value
                period = float(points["period"][k])
                row["period [s]"] = period if math.isfinite(period) else None
                index = int(points["index"][k])
                row["stability"] = expected_stability(branch, index, bool(points["stable"][k]),
                                                      int(points["point_type"][k]))
                row["criticality"] = text(points["criticality"][k])
                row["status"] = text(points["status"][k])
                rows.append(row)
    return rows


def expected_stability(branch, index: int, stable: bool, point_type: int) -> str:
    """"unknown" where the branch has no verdict at the point; on a fold (LP 2, LPC 5) whose
    nearest known rows before and after it differ, "stable/unstable"; where they agree, their
    verdict; else the point's own."""
    flags = np.asarray(branch["stable"][()], dtype=bool)
    known = (np.asarray(branch["stability_known"][()], dtype=bool)
             if "stability_known" in branch else np.ones(len(flags), dtype=bool))
    if not known[index]:
        return "unknown"
    rows = np.flatnonzero(known)
    before, after = rows[rows < index], rows[rows > index]
    if point_type in (2, 5) and len(before) and len(after):
        sides = {bool(flags[before[-1]]), bool(flags[after[0]])}
        if len(sides) == 2:
            return "stable/unstable"
        stable = sides.pop()
    return "stable" if stable else "unstable"


def same_rows(got: list[dict], expected: list[dict]) -> None:
    """Every row equal (floats to 1e-12 relative), and no key beyond the expected ones holds a
    value (another continuation's parameter is None)."""
    assert len(got) == len(expected) > 0
    for row, want in zip(got, expected, strict=True):
        assert {k: v for k, v in row.items() if k not in want} == \
            dict.fromkeys(set(row) - set(want))
        for key, value in want.items():
            if isinstance(value, float):
                assert row[key] == pytest.approx(value, rel=1e-12, abs=1e-300), (key, row)
            else:
                assert row[key] == value, (key, row)


def summary(*args) -> str:
    result = CliRunner().invoke(cli, ["summary", *map(str, args)])
    assert result.exit_code == 0, result.output
    return result.stdout


@pytest.mark.parametrize("path", REFERENCES, ids=lambda p: p.name)
def test_json_rows_equal_the_file(path):
    rows = json.loads(summary(path, "--format", "json"))
    same_rows(rows, expected_rows(path, CLASSICAL_DOFS))


@pytest.mark.parametrize("path", REFERENCES, ids=lambda p: p.name)
def test_csv_parses_to_the_same_rows(path):
    parsed = list(csv.DictReader(io.StringIO(summary(path, "--format", "csv"))))
    expected = expected_rows(path, CLASSICAL_DOFS)
    numbers = {k for row in expected for k, v in row.items() if isinstance(v, float)} \
        | {"period [s]"}
    rows = [{k: (None if v == "" and k in numbers else float(v) if k in numbers else v)
             for k, v in row.items()} for row in parsed]
    same_rows(rows, expected)


def test_json_round_trips():
    path = REFERENCES[0]
    rows = json.loads(summary(path, "--format", "json"))
    assert json.loads(json.dumps(rows)) == rows
    assert json.loads(summary(path, "--format", "json")) == rows  # the same every time


def cells(value) -> list[str]:
    """What the table shows for a value: 6 significant digits, "-" for none, text as is."""
    if value is None:
        return ["-"]
    if isinstance(value, float):
        return [f"{value:.6g}"]
    return [value] if value else []


@pytest.mark.parametrize("path", REFERENCES[:2], ids=lambda p: p.name)
def test_table_shows_every_row_of_the_file(path):
    lines = summary(path).splitlines()  # default: the table
    expected = expected_rows(path, CLASSICAL_DOFS)
    by_continuation: dict[str, list[dict]] = {}
    for row in expected:
        by_continuation.setdefault(row["continuation"], []).append(row)
    for name, rows in by_continuation.items():
        title = next(k for k, line in enumerate(lines) if line.startswith(f"{name} ("))
        assert lines[title].endswith(f"{len(rows)} special point{'s' * (len(rows) > 1)}")
        header = lines[title + 1].split()
        assert header[:2] == ["branch", "type"] and "[deg]" in header
        for line, row in zip(lines[title + 2:], rows, strict=False):
            want = [c for key, value in row.items() if key != "continuation"
                    for c in cells(value)]
            assert line.split() == want


def oscillator_result() -> StudyResult:
    """Six states in m and m/s (no angle, not four states), two parameters, a Hopf point of
    unknown stability and a fold of cycles with a period."""
    states = ("q1", "q2", "q3", "dq1", "dq2", "dq3")
    units = ("m", "m", "m", "m/s", "m/s", "m/s")
    n = 3

    def branch(name, kind):
        return Branch(name, kind, "test", ("alpha", "k"), ("1/s", "N/m"), states, units,
                      np.array([[0.1, 2.0], [0.0, 2.0], [-0.1, 2.0]]),
                      np.zeros((n, 6)), np.zeros((n, 6)), np.zeros(n), np.full(n, np.nan),
                      np.array([True, False, False]), np.zeros(n, int), np.zeros(n, int),
                      np.full((n, 6), np.nan, complex),
                      stability_known=np.array([True, False, True]))

    points = (
        SpecialPoint("main", 1, 3, ("alpha", "k"), np.array([-0.0125, 2.0]),
                     np.array([0.5, -0.25, 0.125, 0.0, 0.0, 0.0]), 1.5, True,
                     criticality="supercritical"),
        SpecialPoint("main", 2, 9, ("alpha", "k"), np.array([-0.1, 2.0]), np.zeros(6),
                     np.nan, False),  # an end point: not listed
        SpecialPoint("periodic_1", 2, 5, ("alpha", "k"), np.array([-0.05, 2.0]),
                     np.array([0.01, 0.02, 0.03, 0.1, 0.2, 0.3]), 2.25, False),
    )
    continuation = ContinuationResult(
        "alpha", "one-parameter",
        (branch("main", BranchKind.EQUILIBRIUM), branch("periodic_1", BranchKind.PERIODIC)),
        points)
    return StudyResult("oscillators-test", "oscillators_poly", (continuation,), (), (),
                       {"study_yaml": "not a study"})


def test_any_model_states_in_their_own_units(tmp_path):
    path = tmp_path / "osc.h5"
    store.write(oscillator_result(), path)
    rows = json.loads(summary(path, "--format", "json"))
    # the stored study does not validate: the dofs are the first half of the states
    same_rows(rows, expected_rows(path, ("q1", "q2", "q3")))
    assert [r["type"] for r in rows] == ["HB", "LPC"]
    assert rows[0]["q1 [m]"] == 0.5 and rows[0]["stability"] == "unknown"
    assert rows[1]["period [s]"] == 2.25 and rows[1]["stability"] == "unstable"
    assert "dq1 [m/s]" not in rows[0]


def test_a_fold_row_shows_the_stability_of_both_sides():
    """A fold of cycles between a stable and an unstable side says so, whatever AUTO's flag at
    the fold itself; between two unstable sides it is unstable; a Hopf point keeps its own."""
    from whirl_cli.output.summary import summary_rows

    result = oscillator_result()
    (continuation,) = result.continuations
    family = replace(continuation.branches[1], stable=np.array([True, False, False]),
                     stability_known=np.ones(3, bool))
    fold = replace(continuation.special_points[2], index=1, stable=True)
    seen = []
    for first in (True, False):
        branch = replace(family, stable=np.array([first, False, False]))
        changed = replace(continuation, branches=(continuation.branches[0], branch),
                          special_points=(continuation.special_points[0], fold))
        rows = summary_rows(replace(result, continuations=(changed,)))
        seen.append([r.stability for r in rows])
    assert seen == [["unknown", "stable/unstable"], ["unknown", "unstable"]]


@pytest.mark.parametrize("content, reason", [
    (None, "no such file"),
    (b"name: x\n", "not an HDF5 file"),
])
def test_bad_file_is_one_line(tmp_path, content, reason):
    path = tmp_path / "bad.h5"
    if content is not None:
        path.write_bytes(content)
    result = CliRunner().invoke(cli, ["summary", str(path)])
    assert result.exit_code == 1
    assert result.stdout == ""
    assert result.stderr == f"{path}: {reason}\n"


def test_other_hdf5_file_is_one_line(tmp_path):
    path = tmp_path / "other.h5"
    with h5py.File(path, "w") as handle:
        handle["x"] = [1, 2]
    result = CliRunner().invoke(cli, ["summary", str(path)])
    assert result.exit_code == 1
    assert len(result.stderr.splitlines()) == 1 and "not a whirl result file" in result.stderr


def test_a_long_run_of_one_type_is_shortened_in_the_table_only(tmp_path):
    """Eight GH points in a row on one branch (as on a linear model's Hopf locus) are shown
    as the first, "... 6 more GH" and the last; CSV and JSON keep every one."""
    base = oscillator_result()
    (continuation,) = base.continuations
    hopf = continuation.special_points[0]
    ghs = tuple(replace(hopf, point_type=-32, parameters=np.array([-0.01 * k, 2.0]))
                for k in range(1, 9))
    two_hopf = (hopf, replace(hopf, parameters=np.array([0.05, 2.0])))
    points = two_hopf + ghs + (continuation.special_points[2],)
    result = replace(base, continuations=(replace(continuation, special_points=points),))
    path = tmp_path / "many.h5"
    store.write(result, path)
    assert len(json.loads(summary(path, "--format", "json"))) == 11
    lines = summary(path).splitlines()
    assert lines[0] == "alpha (one-parameter): 11 special points"
    body = [line.split()[:3] for line in lines[2:]]
    assert body == [["main", "HB", "-0.0125"], ["main", "HB", "0.05"],
                    ["main", "GH", "-0.01"], ["...", "6", "more"], ["main", "GH", "-0.08"],
                    ["periodic_1", "LPC", "-0.05"]]
    assert lines[5].split() == ["...", "6", "more", "GH"]


def test_a_table_aligns_its_columns_and_never_cuts_a_cell():
    """Columns two spaces apart, each as wide as its widest cell (header included), text
    left- and numbers right-aligned, trailing blanks dropped; "none" centred without rows."""
    table = Table("t (one-parameter): 2 special points", ("branch", "V [m/s]"), (False, True),
                  (("main", "1.5"), ("periodic_12", "-0.0125")))
    assert table.lines() == ["t (one-parameter): 2 special points",
                             "branch       V [m/s]",
                             "main             1.5",
                             "periodic_12  -0.0125"]
    empty = Table("t (one-parameter): 0 special points", ("branch", "type", "status"),
                  (False, False, False), ())
    assert empty.lines()[1:] == ["branch  type  status", "        none"]


def test_the_table_needs_no_rich():
    """The closing table of `whirl run` and `whirl summary` is plain text: rendering it
    imports no terminal library (rich takes about 0.03 s to import)."""
    code = ("import sys; from whirl_cli.output.store import read; "
            "from whirl_cli.output.summary import render; "
            f"text = render(read({str(REFERENCES[0])!r}), 'table'); "
            "print(len(text.splitlines()) > 2, 'rich' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60, check=True)
    assert done.stdout.split() == ["True", "False"]


def test_rejected_points_are_counted_apart_and_never_shortened_with_located_ones(tmp_path):
    """A run of GH points whirl's check rejected (a linear model's Hopf locus) is shortened
    apart from the located ones beside it, its "..." row says they are rejected, and the
    title says how many of the points are."""
    base = oscillator_result()
    (continuation,) = base.continuations
    hopf = continuation.special_points[0]
    gh = replace(hopf, point_type=-32)
    located = tuple(replace(gh, parameters=np.array([-0.01 * k, 2.0])) for k in range(1, 6))
    rejected = tuple(replace(gh, parameters=np.array([-0.1 - 0.01 * k, 2.0]),
                             status=LocateStatus.REJECTED) for k in range(1, 8))
    points = (hopf, *located, *rejected)
    result = replace(base, continuations=(replace(continuation, special_points=points),))
    path = tmp_path / "rejected.h5"
    store.write(result, path)
    lines = summary(path).splitlines()
    assert lines[0] == "alpha (one-parameter): 13 special points, 7 of them rejected by " \
        "whirl's checks"
    skipped = [line.split(maxsplit=1)[1] for line in lines if line.startswith("...")]
    assert skipped == ["3 more GH", "5 more GH, rejected"]
