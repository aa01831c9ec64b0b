"""Families of cycles branching off at branch points of cycles (real AUTO-07p).

The classical model with the softening pitch law (K2 = -10) at K_psi = 0.285 is odd
(y -> -y); its symmetric cycles (x(t + T/2) = -x(t)) lose their symmetry at a pitchfork where
a Floquet multiplier leaves through +1 (K1 near 0.386), and a pair of asymmetric cycle
families, each the other's mirror image, leaves there: stable cycles just below it that no
family from a Hopf point holds. Checked against the model written out in the test
(tests/classical_exact.py): the pitchfork's K1 where the symmetric cycle's half-period map
-M(T/2) has an eigenvalue -1 (monodromy by scipy's variational equations), and a scipy
simulation started on the branched family's cycle stays on it.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from whirl_cli.pipeline import run_study
from whirl_cli.results import PointType
from whirl_cli.study import validate_text

from ..classical_exact import DATUM, field, linear_matrix, polynomial

pytestmark = pytest.mark.auto

K_PSI, K2 = 0.285, -10.0
ON_CYCLE = 0.375  # K1 where the branched family's cycles are stable

STUDY = f"""\
name: softening-pitchfork
description: softening slice at K_psi = {K_PSI}
model: classical
parameters: {{K_psi: {K_PSI}}}
nonlinearity: {{type: polynomial, dof: theta, K2: {K2}}}
continuations:
  - name: k1
    type: one-parameter
    parameter: K1
    start: 0.5
    range: [-0.3, 0.9]
    periodic: true
    orbits_at: [{ON_CYCLE}]
"""


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    study = validate_text(STUDY, "softening_pitchfork.yaml")
    (continuation,) = run_study(study, tmp_path_factory.mktemp("pitchfork"),
                                jobs=2).continuations
    return continuation


def _variational(k1: float):
    """The model's field with its variational equations: z = [y, P (4x4, row-major)]."""
    values = {"K_psi": K_PSI, "K_theta": k1}
    f, a = field(values, polynomial(k1, K2)), linear_matrix(values)

    def g(t, z):
        jacobian = a.copy()
        jacobian[2, 0] -= 3 * K2 * z[0] ** 2 / DATUM["I_y"]
        return np.concatenate([f(t, z[:4]), (jacobian @ z[4:].reshape(4, 4)).ravel()])
    return f, g


def _half_map(k1: float, y0: np.ndarray, period: float):
    """(y(T/2), M(T/2), field) from ``y0``."""
    f, g = _variational(k1)
    z = solve_ivp(g, (0, period / 2), np.concatenate([y0, np.eye(4).ravel()]),
                  method="DOP853", rtol=1e-11, atol=1e-13).y[:, -1]
    return z[:4], z[4:].reshape(4, 4), f


def symmetric_cycle(k1: float, y0, period: float) -> tuple[np.ndarray, float, np.ndarray]:
    """The symmetric cycle near (``y0``, ``period``) by Newton's method on y(T/2) = -y0
    (the pitch rate at t = 0 held): its start, period and half-period map M(T/2)."""
    y0 = np.array(y0, dtype=float)
    for _ in range(40):
        half, m, f = _half_map(k1, y0, period)
        step = np.linalg.lstsq(np.column_stack([(m + np.eye(4))[:, [0, 1, 3]],
                                                0.5 * f(0.0, half)]), -(half + y0),
                               rcond=None)[0]
        y0[[0, 1, 3]] += step[:3]
        period += step[3]
        if np.abs(step).max() < 1e-12:
            break
    half, m, _ = _half_map(k1, y0, period)
    assert np.abs(half + y0).max() < 1e-9
    return y0, period, m


def test_the_branched_family_starts_where_the_monodromy_says(result):
    by_name = {b.name: b for b in result.branches}
    family, switched = by_name["periodic_1"], by_name["periodic_1_bp1"]
    point = next(p for p in result.special_points if p.branch == "periodic_1"
                 and p.point_type == PointType.BPC and 0.37 < p.parameters[0] < 0.40)
    # a start near the symmetric cycle there: theta at its maximum (Newton does the rest)
    row = point.index
    guess = np.array([family.state_max[row, 0], 0.0, 0.0, 0.0])
    guess[1], guess[3] = 0.5 * family.state_max[row, 1], family.state_max[row, 3]
    start, period = guess, float(family.period[row])

    def crossing(k1: float) -> float:
        """det(I - M(T/2)): zero where -M(T/2) has the eigenvalue -1 (a multiplier of
        the cycle through +1 that breaks its symmetry)."""
        nonlocal start, period
        start, period, m = symmetric_cycle(k1, start, period)
        return float(np.linalg.det(np.eye(4) - m))

    low, high = 0.38, 0.389
    assert crossing(low) * crossing(high) < 0
    pitchfork = brentq(crossing, low, high, xtol=1e-7)
    assert point.parameters[0] == pytest.approx(pitchfork, abs=1e-4)
    assert switched.origin.value == pytest.approx(pitchfork, abs=1e-4)
    assert switched.parameters[0, 0] == pytest.approx(pitchfork, abs=1e-4)


def test_the_branched_familys_stable_cycle_is_what_scipy_settles_on(result):
    by_name = {b.name: b for b in result.branches}
    switched = by_name["periodic_1_bp1"]
    assert switched.origin.point == PointType.BPC
    orbit = next(o for o in switched.orbits if abs(o.parameters[0] - ON_CYCLE) < 1e-6)
    row = orbit.index
    assert switched.stable[row]
    theta_max, theta_min = switched.state_max[row, 0], switched.state_min[row, 0]
    assert abs(theta_max + theta_min) > 0.02 * theta_max  # not symmetric
    image = by_name["periodic_1_bp1m"]  # its mirror image, the other side of the pitchfork
    assert image.state_max[row, 0] == pytest.approx(-theta_min)

    f = field({"K_psi": K_PSI, "K_theta": ON_CYCLE}, polynomial(ON_CYCLE, K2))
    periods = 60
    t_end = periods * orbit.period
    done = solve_ivp(f, (0, t_end), orbit.states[0], method="DOP853", rtol=1e-11, atol=1e-13,
                     dense_output=True)
    late = np.linspace(t_end - 10 * orbit.period, t_end, 20001)
    theta = done.sol(late)[0]
    assert theta.max() == pytest.approx(theta_max, rel=1e-3)
    assert theta.min() == pytest.approx(theta_min, rel=1e-3)
    rate = done.sol(late)[2]
    ups = late[1:][(rate[:-1] < 0) & (rate[1:] >= 0) & (theta[1:] < 0.5 * theta_min)]
    assert np.diff(ups).mean() == pytest.approx(switched.period[row], rel=1e-3)
