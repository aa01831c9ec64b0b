"""The equilibrium cross-check (``simulate.check_equilibrium``) on hand-made branches: a true
equilibrium passes, one stored a little wrong fails. The old acceptance (any deviation below a
tenth of the perturbation after ten decay times, where e^-10 is expected) let offsets of
1e-5..1e-4 rad through."""

from __future__ import annotations

import numpy as np
import pytest

from whirl_cli.analysis import simulate
from whirl_cli.models import get_model
from whirl_cli.results import Branch, BranchKind, Origin, PointType

HARDENING_CASE2 = {"K2_theta": 10.0, "K3_theta": 0.0, "K_psi": 0.3}


@pytest.fixture(scope="module")
def model():
    return get_model("classical")


def one_point_branch(model, k1: float, state: np.ndarray) -> Branch:
    """A stable equilibrium branch of one row at ``k1`` with the stored ``state``."""
    nan = np.full((1, model.n_states), np.nan + 0j)
    return Branch(
        name="hand", kind=BranchKind.EQUILIBRIUM, origin=Origin("by hand"),
        parameter_names=("K_theta",),
        parameter_units=("N m/rad",), state_names=model.state_names,
        state_units=tuple(s.unit for s in model.states), parameters=np.array([[k1]]),
        state_max=state[None, :].copy(), state_min=state[None, :].copy(),
        l2_norm=np.array([np.linalg.norm(state)]), period=np.array([np.nan]),
        stable=np.array([True]), point_type=np.array([PointType.REGULAR]),
        label=np.array([0]), eigenvalues=nan)


def equilibrium(model, k1: float, guess: np.ndarray) -> np.ndarray:
    """The equilibrium of hardening case 2 at ``k1`` nearest ``guess``, by Newton's method on
    the numpy right-hand side (to machine precision), checked stable."""
    params = model.parameter_vector({**HARDENING_CASE2, "K_theta": k1})
    state = np.asarray(guess, dtype=float)
    for _ in range(50):
        step = np.linalg.solve(model.jacobian_numpy(state, params), model.rhs_numpy(state, params))
        state = state - step
        if np.abs(step).max() < 1e-15:
            break
    assert np.abs(model.rhs_numpy(state, params)).max() < 1e-12
    assert np.linalg.eigvals(model.jacobian_numpy(state, params)).real.max() < 0
    return state


# (K1, Newton guess, offsets (rad) of the stored pitch and yaw that the old check accepted: below
# a tenth of its perturbation, which is 1e-3 of the deflection off the origin: 1.8e-5 rad at
# K1 = -0.298, 1.5e-5 rad at K1 = -0.2). An offset origin would count as a tiny deflection, its
# perturbation shrink with it, and any offset be refused, before as now: only the true origin.
CASES = [
    pytest.param(0.45, np.zeros(4), (), id="origin K1=0.45"),
    pytest.param(-0.298, np.array([0.18, 0.04, 0.0, 0.0]), (1e-5, 1.5e-5), id="K1=-0.298 (+)"),
    pytest.param(-0.298, np.array([-0.18, -0.04, 0.0, 0.0]), (1e-5,), id="K1=-0.298 (-)"),
    pytest.param(-0.2, np.array([0.15, 0.03, 0.0, 0.0]), (1e-5,), id="K1=-0.2 (+)"),
]


@pytest.mark.parametrize(("k1", "guess", "offsets"), CASES)
def test_equilibrium_check_accepts_the_true_state_and_refuses_a_slightly_wrong_one(
        model, k1, guess, offsets, capsys):
    state = equilibrium(model, k1, guess)
    true = simulate.check_equilibrium(model, HARDENING_CASE2, one_point_branch(model, k1, state), 0)
    assert true.passed, true
    refused = []
    for offset in offsets:
        for sign, angle in ((1.0, 0), (-1.0, 0), (1.0, 1), (-1.0, 1)):
            wrong = state.copy()
            wrong[angle] += sign * offset
            check = simulate.check_equilibrium(model, HARDENING_CASE2,
                                               one_point_branch(model, k1, wrong), 0)
            assert not check.passed, (offset, sign, angle, check)
            assert check.simulated == pytest.approx(offset, rel=0.05)  # what is left: the offset
            refused.append(check.simulated)
    with capsys.disabled():
        print(f"\nK1 = {k1}, state ({state[0]:+.4f}, {state[1]:+.4f}) rad: perturbation "
              f"{true.expected:.0e} rad -> {true.simulated:.1e} rad left, passed"
              + (f"; stored pitch or yaw off by +/-{', '.join(f'{o:.1e}' for o in offsets)} "
                 f"rad: {min(refused):.1e}..{max(refused):.1e} rad left, refused"
                 if offsets else ""))
