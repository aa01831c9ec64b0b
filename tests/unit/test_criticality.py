"""Hopf criticality from the periodic family when AUTO printed no eigenvalues beside the Hopf
point (issue 13, item 10): unknown stays unknown, and the first Lyapunov coefficient's
verdict stands."""

from __future__ import annotations

import numpy as np
import pytest

from whirl_cli.continuation.criticality import with_criticality
from whirl_cli.results import Branch, BranchKind, Origin, PointType, SpecialPoint

OMEGA = 30.0  # rad/s, the Hopf pair

#: The origin of a branch these tests do not start anywhere in particular.
ANYWHERE = Origin("")


def branch(name: str, kind: str, k1: np.ndarray, eigenvalues: np.ndarray, size: np.ndarray,
           origin: Origin = ANYWHERE) -> Branch:
    n = len(k1)
    state = np.zeros((n, 4))
    state[:, 0] = size
    return Branch(name=name, kind=kind, origin=origin, parameter_names=("K1",),
                  parameter_units=("N m/rad",), state_names=("theta", "psi", "dtheta", "dpsi"),
                  state_units=("rad", "rad", "rad/s", "rad/s"), parameters=k1[:, None],
                  state_max=state, state_min=-state, l2_norm=size, period=np.full(n, np.nan),
                  stable=np.zeros(n, dtype=bool), point_type=np.zeros(n, dtype=np.int64),
                  label=np.zeros(n, dtype=np.int64), eigenvalues=eigenvalues)


def hopf_and_family(printed: bool, lyapunov_says: str):
    """An equilibrium branch in K1 with a Hopf point at 0.2 (the pair stable above, unstable
    below, when AUTO printed eigenvalues) and a family growing towards K1 < 0.2 (so:
    supercritical), and the Hopf point as whirl found it, labelled by l1."""
    k1 = np.array([0.3, 0.25, 0.2, 0.15, 0.1])
    growth = -(k1 - 0.2)  # Re(lambda) of the pair grows as K1 falls
    values = np.column_stack([growth + 1j * OMEGA, growth - 1j * OMEGA,
                              np.full(5, -5.0 + 0j), np.full(5, -6.0 + 0j)])
    if not printed:
        values[:] = np.nan
    equilibria = branch("main_down", BranchKind.EQUILIBRIUM, k1, values, np.zeros(5))
    hopf = SpecialPoint(branch="main_down", index=2, point_type=int(PointType.HB),
                        parameter_names=("K1",), parameters=np.array([0.2]),
                        state=np.zeros(4), period=2 * np.pi / OMEGA, stable=False,
                        criticality=lyapunov_says, lyapunov=-1.0 if lyapunov_says ==
                        "supercritical" else 1.0)
    family = branch("periodic_1", BranchKind.PERIODIC, np.array([0.2, 0.19, 0.18, 0.17]),
                    np.full((4, 4), np.nan + 0j), np.array([0.0, 0.01, 0.02, 0.03]),
                    origin=Origin.at(hopf))
    return equilibria, hopf, family


@pytest.mark.parametrize("lyapunov_says", ["supercritical", "subcritical"])
def test_no_eigenvalues_beside_the_hopf_point_leaves_the_lyapunov_verdict(lyapunov_says):
    equilibria, hopf, family = hopf_and_family(printed=False, lyapunov_says=lyapunov_says)
    (labelled,) = with_criticality([hopf], [family], [equilibria], 0.8, np.ones(4))
    assert labelled.criticality == lyapunov_says
    assert labelled.note == ""


def test_with_eigenvalues_the_family_decides_and_a_disagreement_is_noted():
    equilibria, hopf, family = hopf_and_family(printed=True, lyapunov_says="subcritical")
    (labelled,) = with_criticality([hopf], [family], [equilibria], 0.8, np.ones(4))
    assert labelled.criticality == "supercritical"  # unstable below 0.2, the family there
    assert "first Lyapunov coefficient says subcritical" in labelled.note


def test_a_family_that_grows_at_the_hopf_value_first_lies_where_it_then_turns():
    """A family growing at a fixed parameter value (a Hopf point where the right-hand side is
    locally linear, e.g. just outside a freeplay gap), a hair above it in K1, then turning to
    K1 < 0.2 where the pair is unstable: supercritical (the hair's side said subcritical)."""
    equilibria, hopf, _ = hopf_and_family(printed=True, lyapunov_says="")
    family = branch("periodic_1", BranchKind.PERIODIC,
                    np.array([0.2, 0.2 + 1e-9, 0.2 + 2e-9, 0.2, 0.19, 0.17]),
                    np.full((6, 4), np.nan + 0j), np.array([0.0, 0.01, 0.02, 0.03, 0.04, 0.05]),
                    origin=Origin.at(hopf))
    (labelled,) = with_criticality([hopf], [family], [equilibria], 0.8, np.ones(4))
    assert labelled.criticality == "supercritical"
