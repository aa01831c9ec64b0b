"""The HDF5 layout is one mapping (issue 14, item 6): every field of every stored result
dataclass is declared once in ``output/store.py`` (or is a group name or a collection the file
layout holds), and the writer and the reader both go by those declarations."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from whirl_cli import results
from whirl_cli.output import store

#: Fields the layout holds as a group's name or as collections of their own, not as fields.
STRUCTURAL = {
    results.Branch: {"name", "orbits"},
    results.Orbit: {"label"},
    results.SpecialPoint: set(),
    results.CrossCheck: set(),
    results.LinearSweep: set(),
    results.LinearGrid: {"flutter", "divergence"},
    results.Boundary: {"name", "loci", "intervals", "polygons"},
    results.UnsafeInterval: set(),
    results.RunRecord: {"name"},
}
DECLARATIONS = {
    results.Branch: store.BRANCH, results.Orbit: store.ORBIT,
    results.SpecialPoint: store.SPECIAL_POINT, results.CrossCheck: store.CROSS_CHECK,
    results.LinearSweep: store.LINEAR_SWEEP, results.LinearGrid: store.LINEAR_GRID,
    results.Boundary: store.BOUNDARY, results.UnsafeInterval: store.UNSAFE_INTERVAL,
    results.RunRecord: store.RUN,
}


def declared(fields) -> set[str]:
    """Field names a declaration stores: its own and those its datasets carry as attributes."""
    names = {f.name for f in fields if not f.derived}
    for f in fields:
        if f.columns is not None:
            names |= {n for n in f.columns if n is not None}
        if f.unit_field is not None:
            names.add(f.unit_field)
    return names


@pytest.mark.parametrize("cls", list(DECLARATIONS), ids=lambda c: c.__name__)
def test_every_field_is_declared_exactly_once(cls):
    fields = {f.name for f in dataclasses.fields(cls)}
    mapped = declared(DECLARATIONS[cls])
    assert mapped | STRUCTURAL[cls] == fields
    assert not mapped & STRUCTURAL[cls]
    keys = [f.hdf5_key() for f in DECLARATIONS[cls]]
    assert len(keys) == len(set(keys))  # no two fields in one place


def branch(name: str, kind: str, n: int) -> results.Branch:
    rng = np.random.default_rng(1)
    return results.Branch(
        name=name, kind=kind, origin="o", parameter_names=("V",), parameter_units=("m/s",),
        state_names=("q1", "q2"), state_units=("m", "m/s"), parameters=rng.normal(size=(n, 1)),
        state_max=rng.normal(size=(n, 2)), state_min=rng.normal(size=(n, 2)),
        l2_norm=rng.normal(size=n), period=rng.normal(size=n), stable=rng.random(n) > 0.5,
        point_type=np.arange(n, dtype=np.int64), label=np.arange(n, dtype=np.int64),
        eigenvalues=rng.normal(size=(n, 2)) + 1j, end="range",
        orbits=(results.Orbit(3, 4, 1, np.array([0.5]), 0.2, np.linspace(0, 0.2, 5),
                              rng.normal(size=(5, 2))),) if n else (),
        stability_known=rng.random(n) > 0.5)


def test_a_result_with_every_kind_of_record_round_trips(tmp_path):
    point = results.SpecialPoint("b_periodic", 1, 5, ("V",), np.array([0.5]), np.zeros(2), 0.2,
                                 True, label=3, status="bracketed", criticality="sub",
                                 note="n", bracket=np.array([0.4, 0.6]), residual=0.1)
    result = results.StudyResult(
        "s", "m", (results.ContinuationResult(
            "c", "one-parameter", (branch("b_equilibrium", results.BranchKind.EQUILIBRIUM, 4),
                                   branch("b_periodic", results.BranchKind.PERIODIC, 3),
                                   branch("failed", results.BranchKind.PERIODIC, 0)), (point,),
            (results.CrossCheck("b_periodic", 1, "orbit", 0.5, 1.0, 1.001, True, "q1"),)),
                   results.ContinuationResult("empty", "one-parameter", (), ())),
        (results.LinearSweep("V", "m/s", np.arange(3.0), np.ones((3, 2)) * 1j,
                             np.zeros((3, 2)), np.ones((3, 2)),
                             np.array([["FW", "BW"]] * 3)),
         results.LinearSweep("K", "N m/rad", np.arange(3.0), np.ones((3, 2)) * 1j,
                             np.zeros((3, 2)), np.ones((3, 2)),
                             np.array([["FW", "BW"]] * 3),
                             np.array([["nacelle", "gimbal"]] * 3))),
        (results.RunRecord("c.run", "ok", "ok", "IPS = 1\n", 0, 0.5, 4),), {"a": "b"},
        (results.Boundary("bd", ("V", "K"), ("m/s", "N m/rad"), "loci",
                          {"l1": ("hopf", np.ones((4, 2)))},
                          (results.UnsafeInterval(0.1, 1.0, 2.0, "flutter"),),
                          (np.zeros((5, 2)),), (0.1, 0.2)),),
        results.LinearGrid("V", "K", "m/s", "N m/rad", np.arange(3.0), np.arange(2.0),
                           np.zeros((2, 3)), np.zeros((2, 3), dtype=bool),
                           (np.ones((3, 2)),), ()))
    back = store.read(store.write(result, tmp_path / "r.h5"))
    assert repr(back) == repr(result)  # every value, type and order
    with store.opened(tmp_path / "r.h5") as handle:  # Floquet multipliers stored as such
        periodic = handle["continuations/c/branches/b_periodic"]
        assert "floquet_multipliers" in periodic and "eigenvalues" not in periodic
        assert periodic["floquet_multipliers"].attrs["units"] == "1"
        assert handle["linear/sweeps/V/values"].attrs["units"] == "m/s"
