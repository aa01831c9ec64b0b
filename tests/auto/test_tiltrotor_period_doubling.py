"""Branch switching at period doubling (``period_doubling: true``) on the real AUTO-07p, on the
Rossler system (tests/data/rossler.model.yaml, a = b = 0.2), whose cascade is published: the
period-1 cycle doubles at c = 2.83, the period-2 cycle at c = 3.84. Both points and the doubled
family are checked against a Poincare map written here (scipy), never against whirl's output.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from whirl_cli.pipeline import run_study
from whirl_cli.results import PointType
from whirl_cli.study import load_study

from ..conftest import ROOT

pytestmark = pytest.mark.auto

STUDY = ROOT / "tests" / "data" / "rossler_c.yaml"
A = B = 0.2


def _field(c: float):
    def f(_t, u):
        x, y, z = u
        return [-y - z, x + A * y, B + z * (x - c)]
    return f


def _crossing(_t, u):
    """The section y = 0, crossed upwards (x > 0 there: the outer side of the attractor)."""
    return u[1]


_crossing.direction = 1


def _returns(c: float, u: np.ndarray, count: int) -> tuple[np.ndarray, float]:
    """The state after ``count`` returns to the section from ``u`` on it, and the time taken."""
    t_total = 0.0
    for _ in range(count):
        sol = solve_ivp(_field(c), (0, 20), u, method="DOP853", rtol=1e-11, atol=1e-12,
                        events=_crossing, first_step=1e-3)
        times = [t for t, v in zip(sol.t_events[0], sol.y_events[0], strict=True) if t > 1e-2]
        states = [v for t, v in zip(sol.t_events[0], sol.y_events[0], strict=True) if t > 1e-2]
        if not times:
            raise AssertionError("no return to the section")
        u, t_total = states[0], t_total + times[0]
        u = np.array([u[0], 0.0, u[2]])
    return u, t_total


def _fixed_point(c: float, count: int, guess: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """(x, z) of the fixed point of the ``count``-th return map on the section y = 0 (Newton,
    finite differences), the map's Jacobian there and the orbit's period."""
    p = np.array(guess, dtype=float)
    for _ in range(20):
        image, period = _returns(c, np.array([p[0], 0.0, p[1]]), count)
        residual = image[[0, 2]] - p
        jac = np.empty((2, 2))
        for k in range(2):
            h = np.zeros(2)
            h[k] = 1e-6
            moved, _ = _returns(c, np.array([p[0] + h[0], 0.0, p[1] + h[1]]), count)
            jac[:, k] = (moved[[0, 2]] - image[[0, 2]]) / 1e-6
        step = np.linalg.solve(jac - np.eye(2), -residual)
        p = p + step
        if np.abs(step).max() < 1e-9:
            break
    return p, jac, period


def _settled(c: float, count: int) -> np.ndarray:
    """A point of the attracting cycle at ``c`` on the section (simulated from (1, 1, 0))."""
    sol = solve_ivp(_field(c), (0, 600), [1.0, 1.0, 0.0], method="DOP853", rtol=1e-10,
                    atol=1e-12, events=_crossing)
    u = sol.y_events[0][-count]
    return np.array([u[0], u[2]])


def _doubling(count: int, low: float, high: float) -> float:
    """c where the ``count``-th return map's multiplier crosses -1 (the cycle stable at
    ``low``, followed by Newton to ``high``)."""
    guess = _settled(low, count)

    def most_negative(c: float) -> float:
        nonlocal guess
        point, jac, _ = _fixed_point(c, count, guess)
        guess = point
        return float(np.linalg.eigvals(jac).real.min()) + 1.0
    return brentq(most_negative, low, high, xtol=1e-6)


@cache
def computed():
    import tempfile
    from pathlib import Path
    return run_study(load_study(STUDY), Path(tempfile.mkdtemp(prefix="whirl-test-")), jobs=2)


def _pd_points():
    (continuation,) = computed().continuations
    return sorted((p for p in continuation.special_points if p.point_type == PointType.PD),
                  key=lambda p: p.parameters[0])


def test_the_period_doubling_points_are_the_return_maps():
    """AUTO's first two PD points (on the period-1 family and on the family doubled from it)
    are where the scipy return map's (and its square's) multiplier crosses -1 (1e-3), at the
    published 2.83 and 3.84 (0.01)."""
    first, second = _pd_points()[:2]
    ours = _doubling(1, 2.6, 3.0), _doubling(2, 3.5, 3.95)
    print(f"\n  PD: AUTO {first.parameters[0]:.5f}, {second.parameters[0]:.5f}; "
          f"return map {ours[0]:.5f}, {ours[1]:.5f}")
    assert first.parameters[0] == pytest.approx(ours[0], abs=1e-3)
    assert second.parameters[0] == pytest.approx(ours[1], abs=1e-3)
    assert ours == pytest.approx((2.83, 3.84), abs=0.01)
    assert second.branch == f"{first.branch}_pd1"


def test_the_doubled_family_is_the_settled_period_two_cycle():
    """At c = 3.2 the family doubled at the first PD point holds the cycle a scipy simulation
    settles on: its period is that of two returns (1e-4) and its largest x the settled cycle's
    (1e-3); it is stable there, the period-1 family unstable, and it starts at twice the
    period-1 period."""
    first = _pd_points()[0]
    (continuation,) = computed().continuations
    doubled = next(b for b in continuation.branches if b.name == f"{first.branch}_pd1")
    assert doubled.period[0] == pytest.approx(2 * first.period, rel=1e-4)
    assert doubled.origin.point == PointType.PD and doubled.origin.parameter == "c"
    assert doubled.origin.value == pytest.approx(first.parameters[0])
    row = int(np.argmin(np.abs(doubled.parameters[:, 0] - 3.2)))
    c = float(doubled.parameters[row, 0])
    point, _, period = _fixed_point(c, 2, _settled(c, 2))
    sol = solve_ivp(_field(c), (0, period), [point[0], 0.0, point[1]], method="DOP853",
                    rtol=1e-11, atol=1e-12, max_step=0.01)
    print(f"\n  c = {c:.4f}: AUTO period {doubled.period[row]:.6f}, x max "
          f"{doubled.state_max[row, 0]:.6f}; scipy {period:.6f}, {sol.y[0].max():.6f}")
    assert doubled.period[row] == pytest.approx(period, rel=1e-4)
    assert doubled.state_max[row, 0] == pytest.approx(sol.y[0].max(), rel=1e-3)
    assert doubled.stable[row]
    single = next(b for b in continuation.branches if b.name == first.branch)
    assert not single.stable[int(np.argmin(np.abs(single.parameters[:, 0] - c)))]
