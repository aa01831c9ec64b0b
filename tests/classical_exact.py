"""The classical model written out for tests apart from whirl's model file (../shared/models.md
sections 2.3 and 7, thesis convention): y = [theta, psi, theta', psi'],

    I_y theta'' = -M(theta) + k_d theta - k_c psi - (C_theta + c_a) theta' + I_x Omega psi'
    I_z psi''   = k_c theta - (K_psi - k_d) psi - I_x Omega theta' - (C_psi + c_a) psi'

with k_d, k_c, c_a from :mod:`tests.strip_theory` and the pitch law M given as a function;
simulated with scipy's solve_ivp (an event at each breakpoint of a piecewise law), or, for the
exact freeplay law, each piece of it in closed form (:func:`freeplay_motion`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from tests.piecewise_linear import affine_pieces, motion
from tests.strip_theory import coefficients

#: Reed's tabletop model (models.md section 3).
DATUM = {"R": 0.152, "Omega": 40.0, "N": 4, "c": 0.026, "C_l_alpha": 2 * math.pi, "a": 0.25,
         "I_x": 0.000103, "I_y": 0.000178, "I_z": 0.000178, "C_theta": 0.001,
         "C_psi": 0.001, "rho": 1.225, "K_theta": 0.4, "K_psi": 0.4, "V": 6.7,
         "aero_coupling": 1.0}


def aero(values: dict) -> tuple[float, float, float]:
    """(k_d, k_c, c_a) at ``values`` (over DATUM)."""
    return tuple(float(x) for x in coefficients({**DATUM, **values}))


def field(values: dict, law):
    """f(t, y) of the model at ``values`` with the pitch restoring moment ``law(theta)``."""
    v = {**DATUM, **values}
    k_d, k_c, c_a = aero(v)
    gyro = v["I_x"] * v["Omega"]
    c_theta, c_psi, k_psi = v["C_theta"] + c_a, v["C_psi"] + c_a, v["K_psi"] - k_d
    i_y, i_z = v["I_y"], v["I_z"]

    def f(_t, y):
        theta, psi, dtheta, dpsi = y.tolist()  # Python floats: the same doubles, less overhead
        return np.array([
            dtheta, dpsi,
            (-law(theta) + k_d * theta - k_c * psi - c_theta * dtheta + gyro * dpsi) / i_y,
            (k_c * theta - k_psi * psi - gyro * dtheta - c_psi * dpsi) / i_z])
    return f


def linear_matrix(values: dict) -> np.ndarray:
    """The 4x4 Jacobian of the linear model (M = K_theta theta) at ``values``."""
    v = {**DATUM, **values}
    f = field(v, lambda theta: v["K_theta"] * theta)
    return np.column_stack([f(0.0, e) for e in np.eye(4)])


def polynomial(k1: float, k2: float = 0.0, k3: float = 0.0):
    """The thesis's pitch law K1 theta + K2 theta^3 + K3 theta^5."""
    return lambda theta: k1 * theta + k2 * theta**3 + k3 * theta**5


def freeplay(delta: float, k_out: float, k_in: float = 0.0):
    """The exact freeplay law K_in x + (K_out - K_in) (x - delta sat(x / delta))."""
    return lambda x: k_in * x + (k_out - k_in) * (x - delta * max(-1.0, min(1.0, x / delta)))


def simulate(values: dict, law, y0, duration: float, breakpoints: tuple[float, ...] = (),
             samples_per_second: int = 2000, limit: float = 1.5):
    """(t, y): the motion from ``y0`` for ``duration`` s, restarted at each crossing of
    theta = each of ``breakpoints`` (where the law changes piece); stops early where |theta|
    or |psi| exceeds ``limit`` rad (diverged)."""
    f = field(values, law)

    def crossing(level):
        def event(_t, y):
            return y[0] - level
        event.terminal = True
        return event

    def away(_t, y):
        return limit - max(abs(y[0]), abs(y[1]))
    away.terminal = True

    events = [crossing(b) for b in breakpoints] + [away]
    t0, y, times, states = 0.0, np.asarray(y0, dtype=float), [], []
    while t0 < duration:
        grid = np.arange(math.ceil(t0 * samples_per_second),
                         math.floor(duration * samples_per_second) + 1) / samples_per_second
        grid = grid[(grid > t0) & (grid <= duration)]
        done = solve_ivp(f, (t0, duration), y, method="DOP853", rtol=1e-10, atol=1e-12,
                         t_eval=grid, events=events)
        times.append(done.t)
        states.append(done.y.T)
        if done.status != 1:
            break
        hit = [k for k, e in enumerate(done.t_events) if len(e)]
        if hit and hit[0] == len(events) - 1:
            break  # diverged
        t_hit = min(e[0] for e in done.t_events if len(e))
        y = next(e[0] for e in done.y_events if len(e))
        # step a hair past the breakpoint so the event does not fire again at once
        t0 = t_hit + 1e-12
        y = y + 1e-12 * f(t_hit, y)
    return np.concatenate(times), np.concatenate(states)


def _freeplay_pieces(values: dict, delta: float, k_out: float, k_in: float):
    v = {**DATUM, **values}

    def a_of(piece: int) -> np.ndarray:
        return linear_matrix({**v, "K_theta": k_in if piece == 0 else k_out})

    def b_of(piece: int) -> np.ndarray:  # beyond the gap: k_out x - piece delta (k_out - k_in)
        return np.array([0.0, 0.0, piece * delta * (k_out - k_in) / v["I_y"], 0.0])

    return affine_pieces(a_of, b_of)


def freeplay_map(values: dict, delta: float, k_out: float, y0, duration: float,
                 k_in: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The exact freeplay law's state after ``duration`` s from ``y0`` and the derivative of
    that state by ``y0`` (over a period: the monodromy matrix): the product of each piece's
    exp(A s). The law is continuous at the gap's edges, so the field is too and no jump
    (saltation) term enters at a crossing."""
    pieces, visits = _freeplay_pieces(values, delta, k_out, k_in), []
    _, y = motion(pieces, 0, 2, delta, y0, np.array([duration / 2, duration]), visits=visits)
    derivative = np.eye(4)
    for piece, s in visits:
        p = pieces[piece]
        derivative = (p.modes @ np.diag(np.exp(p.rates * s)) @ p.inverse).real @ derivative
    return y[-1], derivative


def freeplay_motion(values: dict, delta: float, k_out: float, y0, duration: float,
                    k_in: float = 0.0, samples_per_second: int = 2000, limit: float = 1.5):
    """:func:`simulate` with the law ``freeplay(delta, k_out, k_in)``, each piece of it (where
    the model is linear) in closed form (:mod:`tests.piecewise_linear`): (t, y) sampled from 0
    to ``duration`` s; the samples end where |theta| or |psi| exceeds ``limit`` rad."""
    grid = np.arange(1, math.floor(duration * samples_per_second) + 1) / samples_per_second
    return motion(_freeplay_pieces(values, delta, k_out, k_in), 0, 2, delta, y0, grid,
                  limit=((0, 1), limit))
