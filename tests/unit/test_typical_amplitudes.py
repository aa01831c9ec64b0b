"""Amplitude thresholds and tolerances in units of each dof's typical amplitude (issue 14): a
model declared in small units behaves as one in large units (the end-to-end check on AUTO is
tests/auto/test_general_model.py)."""

from __future__ import annotations

import dataclasses

import numpy as np

from whirl_cli.analysis.global_bifurcations import equilibria_at
from whirl_cli.continuation.branches import same_point, typical_amplitudes
from whirl_cli.continuation.engine import Numerics
from whirl_cli.continuation.equilibria import equilibrium_constants
from whirl_cli.models import FAMILIES, Model
from whirl_cli.results import Branch, BranchKind, PointType, SpecialPoint


def scaled(family, factor: float, name: str):
    return Model(dataclasses.replace(family, name=name, dofs=tuple(
        dataclasses.replace(d, amplitude=d.amplitude * factor) for d in family.dofs)),
        ("polynomial",) * len(family.dofs))


def test_branches_stop_at_max_amplitude_typical_amplitudes():
    """AUTO's PVLS maxima are in typical amplitudes; so is the stop (was the dof's unit: a
    model in micrometres would only stop 1.5 m out)."""
    numerics = Numerics(max_amplitude=0.7)
    for model in (Model(FAMILIES["classical"], ("polynomial",) * 2),
                  scaled(FAMILIES["oscillators"], 1e-6, "tiny")):
        stops = equilibrium_constants(model, numerics, model.parameters[0].name, (0.0, 1.0),
                                      -1)["UZSTOP"]
        for dof in model.dofs:
            assert stops[f"max_{dof.name}"] == 0.7 and stops[f"min_{dof.name}"] == -0.7


def test_typical_amplitudes_per_state():
    classical = Model(FAMILIES["classical"], ("polynomial",) * 2)
    np.testing.assert_array_equal(typical_amplitudes(classical), np.ones(4))
    tiny = scaled(FAMILIES["oscillators"], 1e-6, "tiny")
    np.testing.assert_array_equal(typical_amplitudes(tiny), np.full(6, 1e-6))


def point(state) -> SpecialPoint:
    return SpecialPoint("main", 0, int(PointType.BP), ("p",), np.array([0.1]),
                        np.asarray(state, dtype=float), float("nan"), False)


def test_special_points_told_apart_in_typical_amplitudes():
    """Two branch points 5 typical amplitudes apart are two points in a model in micrometres
    (absolute 1e-5 called them one); 1e-6 apart in a model of amplitude 1 they are one."""
    tiny = typical_amplitudes(scaled(FAMILIES["oscillators"], 1e-6, "tiny"))
    a, b = point([5e-6, 0, 0, 0, 0, 0]), point([0, 0, 0, 0, 0, 0])
    assert not same_point(a, b, 1.0, tiny)
    assert same_point(point([1e-6, 0, 0, 0, 0, 0]), b, 1.0, np.ones(6))


def test_equilibria_at_counts_distinct_states_in_typical_amplitudes():
    """Two equilibrium branches 1e-7 m apart (0.1 typical amplitude of 1e-6 m) are two
    equilibria, not one."""
    def equilibrium(offset: float) -> Branch:
        n = 2
        states = np.zeros((n, 6))
        states[:, 0] = offset
        return Branch("e", BranchKind.EQUILIBRIUM, "", ("p",), ("1",), STATES, UNITS,
                      np.array([[0.0], [1.0]]), states, states, np.zeros(n),
                      np.full(n, np.nan), np.ones(n, bool), np.zeros(n, int), np.zeros(n, int),
                      np.zeros((n, 6), complex))

    branches = [equilibrium(0.0), equilibrium(1e-7)]
    assert len(equilibria_at(0.5, branches)) == 1  # absolute 1e-6: one
    assert len(equilibria_at(0.5, branches, np.full(6, 1e-6))) == 2


STATES = ("q1", "q2", "q3", "dq1", "dq2", "dq3")
UNITS = ("m",) * 3 + ("m/s",) * 3


def test_loci_of_asymmetric_cycles_cut_in_typical_amplitudes():
    """A Hopf locus of cycles centred half their size off y = 0 is not one of the undeflected
    equilibrium's, in micrometres as in radians (absolute 1e-6 kept it at that size)."""
    from whirl_cli.analysis.boundaries import loci_curves

    n, size, centre = 3, 1e-6, 5e-7
    state_max, state_min = np.full((n, 6), centre + size), np.full((n, 6), centre - size)
    locus = Branch("hopf_1a", BranchKind.HOPF_LOCUS, "", ("p", "r"), ("1", "1"), STATES, UNITS,
                   np.column_stack([np.arange(n), np.arange(n)]).astype(float), state_max,
                   state_min, np.zeros(n), np.full(n, np.nan), np.ones(n, bool),
                   np.zeros(n, int), np.zeros(n, int), np.zeros((n, 6), complex))
    assert loci_curves([locus]) != {}  # 1e-6 m of slack: kept
    assert loci_curves([locus], np.full(6, 1e-6)) == {}
    big = dataclasses.replace(locus, state_max=state_max * 1e6, state_min=state_min * 1e6)
    assert loci_curves([big]) == {}
