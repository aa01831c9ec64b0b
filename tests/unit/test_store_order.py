"""A round trip through the HDF5 file keeps the order of every collection: continuations,
branches (``periodic_10`` after ``periodic_2``), orbits, linear sweeps, runs, boundaries and
their loci and polygons, grid contour lines. Files written before whirl tracked the order
still read, in name order."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from whirl_cli.output import store
from whirl_cli.results import Boundary, LinearGrid, Orbit, RunRecord, UnsafeInterval

from ..conftest import ROOT
from .compare_data import equilibrium_branch, make_result, periodic_branch

REFERENCE = ROOT / "tests" / "data" / "legacy_hardening_case2.h5"  # written 2026-11-25


def orbit(label: int, index: int) -> Orbit:
    time = np.linspace(0.0, 0.4, 5)
    return Orbit(label, 4, index, np.array([0.25]), 0.4, time, np.zeros((5, 4)) + label)


def unordered_result():
    """A result whose collections are all out of name order."""
    base = make_result()
    main = equilibrium_branch(np.linspace(0.5, -0.3, 21))
    family = periodic_branch(np.linspace(0.0, 1.6, 17))
    names = ["main_down", "main_up", "secondary_1b", "secondary_1a", "periodic_2",
             "periodic_10", "periodic_1"]
    branches = tuple(replace(family if name.startswith("periodic") else main, name=name)
                     for name in names)
    branches = branches[:4] + (replace(branches[4], orbits=(orbit(12, 3), orbit(3, 9),
                                                             orbit(7, 5))),) + branches[5:]
    first = base.continuations[0]
    continuations = (replace(first, name="k1", branches=branches, special_points=()),
                     replace(first, name="airspeed", branches=branches[:2], special_points=()),
                     replace(first, name="K_psi", branches=branches[4:], special_points=()))
    sweep = base.linear_sweeps[0]
    sweeps = tuple(replace(sweep, parameter=p) for p in ("V", "K1", "K_psi"))
    runs = tuple(RunRecord(name, "ok", "ok", "", 0, 0.1, 3) for name in (
        "k1.main_down", "k1.periodic_2.0", "k1.periodic_10.0", "airspeed.main_down",
        "k1.periodic_2.1"))
    curve = np.array([[0.0, 0.1], [0.2, 0.3], [0.4, 0.5]])
    loci = {name: (name.rsplit("_", 1)[0], curve + k) for k, name in enumerate(
        ["hopf_2a", "fold_of_cycles_10", "hopf_10a", "branch_point_1", "fold_2"])}
    polygons = tuple(curve + k for k in range(12))
    boundaries = tuple(Boundary(name, ("K1", "K_psi"), ("N m/rad", "N m/rad"), "loci", loci,
                                (UnsafeInterval(0.3, 0.1, 0.2, "flutter"),), polygons,
                                (0.3,)) for name in ("k1-kpsi-2", "k1-kpsi-10", "a"))
    lines = tuple(curve * k for k in range(1, 13))
    grid = LinearGrid("K1", "K_psi", "N m/rad", "N m/rad", np.arange(3.0), np.arange(2.0),
                      np.zeros((2, 3)), np.zeros((2, 3), dtype=bool), lines, lines[:3])
    return replace(base, continuations=continuations, linear_sweeps=sweeps, runs=runs,
                   boundaries=boundaries, linear_grid=grid)


def test_a_round_trip_keeps_the_order_of_every_collection(tmp_path):
    written = unordered_result()
    read = store.read(store.write(written, tmp_path / "r.h5"))
    assert [c.name for c in read.continuations] == ["k1", "airspeed", "K_psi"]
    for ours, theirs in zip(written.continuations, read.continuations, strict=True):
        assert [b.name for b in theirs.branches] == [b.name for b in ours.branches]
    assert [b.name for b in read.continuations[0].branches] == [
        "main_down", "main_up", "secondary_1b", "secondary_1a", "periodic_2", "periodic_10",
        "periodic_1"]
    assert [o.label for o in read.continuations[0].branches[4].orbits] == [12, 3, 7]
    assert [o.index for o in read.continuations[0].branches[4].orbits] == [3, 9, 5]
    assert [s.parameter for s in read.linear_sweeps] == ["V", "K1", "K_psi"]
    assert [r.name for r in read.runs] == [r.name for r in written.runs]
    assert [b.name for b in read.boundaries] == ["k1-kpsi-2", "k1-kpsi-10", "a"]
    for boundary in read.boundaries:
        assert list(boundary.loci) == ["hopf_2a", "fold_of_cycles_10", "hopf_10a",
                                       "branch_point_1", "fold_2"]
        assert [float(p[0, 0]) for p in boundary.polygons] == [float(k) for k in range(12)]
        assert [(kind, float(c[0, 0])) for kind, c in boundary.loci.values()] == [
            ("hopf", 0.0), ("fold_of_cycles", 1.0), ("hopf", 2.0), ("branch_point", 3.0),
            ("fold", 4.0)]
    assert [float(line[1, 0]) for line in read.linear_grid.flutter] == [
        0.2 * k for k in range(1, 13)]
    # and a second round trip writes the same order again
    again = store.read(store.write(read, tmp_path / "again.h5"))
    assert [b.name for b in again.continuations[0].branches] == \
        [b.name for b in read.continuations[0].branches]


def test_files_from_before_read_in_name_order():
    """The committed references predate order tracking: their groups list by name."""
    old = store.read(REFERENCE)
    names = [b.name for b in old.continuations[0].branches]
    assert names == sorted(names) == ["main_down", "periodic_1", "periodic_3", "periodic_5",
                                      "secondary_1a", "secondary_1b"]
    runs = [r.name for r in old.runs]
    assert runs == sorted(runs)
    for branch in old.continuations[0].branches:
        labels = [o.label for o in branch.orbits]
        assert labels == sorted(labels)  # by number, as before (not "12" before "3")

