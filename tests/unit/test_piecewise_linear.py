"""The closed-form freeplay motion of tests/piecewise_linear.py, which the exact-law checks use,
against scipy's DOP853 restarted at each gap edge (a step-size-controlled integration of the
same law), and on a grazing the sampled edge test alone would miss."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from tests.piecewise_linear import Piece, affine_pieces, motion

DELTA = math.radians(1.0)
#: a lightly damped oscillator (x, y) driven by a stiff one: a slow and a fast mode
STIFFNESS = np.array([[0.4, -0.15], [0.1, 30.0]])
DAMPING = np.array([[0.01, 0.0], [0.0, 0.05]])


def pieces(k_out: float, k_in: float) -> dict[int, Piece]:
    """Freeplay on x: slope k_in in the gap, k_out beyond it."""
    def a_of(piece: int) -> np.ndarray:
        spring = STIFFNESS.copy()
        spring[0, 0] = k_in if piece == 0 else k_out
        return np.block([[np.zeros((2, 2)), np.eye(2)], [-spring, -DAMPING]])

    def b_of(piece: int) -> np.ndarray:
        return np.array([0.0, 0.0, -piece * DELTA * (k_in - k_out), 0.0])
    return affine_pieces(a_of, b_of)


def stepped(k_out: float, k_in: float, y0, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """The same law by DOP853 (rtol 1e-12), restarted at each edge crossing."""
    def f(_t, y):
        x = y[0]
        law = k_in * x + (k_out - k_in) * (x - DELTA * max(-1.0, min(1.0, x / DELTA)))
        force = STIFFNESS @ y[:2] + DAMPING @ y[2:]
        force[0] += law - STIFFNESS[0, 0] * x
        return np.concatenate([y[2:], -force])

    def edge(level: float):
        def event(_t, y):
            return y[0] - level
        event.terminal = True
        return event

    grid = np.arange(0.0, duration, 1e-3)
    t0, y, times, states = 0.0, np.asarray(y0, dtype=float), [], []
    while True:
        done = solve_ivp(f, (t0, duration), y, method="DOP853", rtol=1e-12, atol=1e-15,
                         t_eval=grid[grid >= t0], events=[edge(DELTA), edge(-DELTA)])
        times.append(done.t)
        states.append(done.y.T)
        if done.status != 1:
            return np.concatenate(times), np.vstack(states)
        t0 = min(e[0] for e in done.t_events if len(e))
        y = next(e[0] for e in done.y_events if len(e))
        t0, y = t0 + 1e-12, y + 1e-12 * f(t0, y)
        grid = grid[grid > t0]


@pytest.mark.parametrize("k_in", [0.0, 0.1])
def test_the_closed_form_is_the_stepped_integration(k_in):
    y0 = np.array([3 * DELTA, 0.5 * DELTA, 0.0, 0.0])
    t, y = motion(pieces(0.8, k_in), 0, 2, DELTA, y0, np.arange(0.0, 20.0, 1e-3))
    t_ref, y_ref = stepped(0.8, k_in, y0, 20.0)
    assert len(t) == len(t_ref) == 20000
    np.testing.assert_allclose(t, t_ref, rtol=0, atol=1e-12)
    assert np.abs(y - y_ref).max() < 1e-9 * np.abs(y_ref).max()
    assert (np.abs(y[:, 0]) > DELTA).any() and (np.abs(y[:, 0]) < DELTA).any()  # both pieces


def test_a_grazing_between_two_edge_tests_changes_piece():
    """x = A sin t in the gap reaches 1e-8 delta past the edge for 3e-4 s, between two points
    of the edge test (0.3 s apart); beyond the edge the motion runs away from it, x - delta =
    v sinh(t - t_edge) with v its speed at the edge: found there, the run-away is the motion
    in closed form."""
    amplitude = (1 + 1e-8) * DELTA
    gap = np.array([[0.0, 1.0], [-1.0, 0.0]])
    away = np.array([[0.0, 1.0], [1.0, 0.0]])  # x'' = x - delta beyond +delta: rest at the edge
    found = affine_pieces(lambda piece: gap if piece == 0 else away,
                          lambda piece: np.array([0.0, -piece * DELTA]))
    t, y = motion(found, 0, 1, DELTA, np.array([0.0, amplitude]), np.linspace(0.0, 20.0, 201))
    t_edge = math.asin(DELTA / amplitude)
    v = amplitude * math.cos(t_edge)
    expected = DELTA + v * np.sinh(t[-1] - t_edge)
    assert y[-1, 0] > 1e3 * DELTA
    assert y[-1, 0] == pytest.approx(expected, rel=1e-6)


def test_the_visits_give_the_flow_map_derivative():
    """The pieces a motion passes through and the time in each (``visits``): with a law
    continuous at the edges, the product of each piece's exp(A s) is the derivative of the
    final state by the initial one, as central differences of the closed-form map give it."""
    law = pieces(0.4, 0.0)
    y0, duration = np.array([4.0 * DELTA, 0.0, 0.0, 0.0]), 12.0

    def final(y):
        return motion(law, 0, 2, DELTA, y, np.array([duration / 2, duration]))[1][-1]

    visits = []
    motion(law, 0, 2, DELTA, y0, np.array([duration / 2, duration]), visits=visits)
    assert {piece for piece, _ in visits} == {-1, 0, 1}  # crosses the gap both ways
    assert sum(s for _, s in visits) == pytest.approx(duration, abs=1e-12)
    product = np.eye(4)
    for piece, s in visits:
        p = law[piece]
        product = (p.modes @ np.diag(np.exp(p.rates * s)) @ p.inverse).real @ product
    h = 1e-7 * DELTA
    differences = np.column_stack([(final(y0 + h * e) - final(y0 - h * e)) / (2 * h)
                                   for e in np.eye(4)])
    np.testing.assert_allclose(product, differences, rtol=1e-5, atol=1e-6 * np.abs(product).max())
