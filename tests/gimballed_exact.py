"""The gimballed model with whirl's exact freeplay law, written out for tests apart from whirl's
model file (../shared/models.md sections 2.2, 7 and 8, in the derivation frame: psi and beta_z
of the thesis frame negated, which leaves |theta|, |beta_y|, periods and stability as they
are), and simulated with scipy's solve_ivp, an event at each breakpoint |x| = delta where the
law changes piece.

q = [theta, psi, beta_y, beta_z]; M q'' + (C + G - C_a) q' + (K - K_a) q + freeplay = 0, the
freeplay dof's spring replaced by K_in x + (K_out - K_in) (x - delta sat(x / delta)).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

#: Reed's tabletop model (models.md section 3) and the gimbal's data (section 8).
DATUM = {"R": 0.152, "Omega": 40.0, "N": 4, "c": 0.026, "C_l_alpha": 2 * np.pi, "a": 0.25,
         "I_x": 0.000103, "I_y": 0.000178, "C_theta": 0.001, "C_psi": 0.001, "rho": 1.225,
         "K_theta": 0.4, "K_psi": 0.4, "I_d": 0.0000515, "K_beta": 10.0, "C_beta": 0.0}
DOFS = ("theta", "psi", "beta_y", "beta_z")


def matrices(values: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(M, D, K): mass, damping (structural + gyroscopic - aerodynamic) and stiffness
    (structural - aerodynamic) of the linear gimballed model at ``values`` (over DATUM)."""
    v = {**DATUM, **values}
    omega, a = v["Omega"], v["a"]
    mu = v["V"] / (omega * v["R"])
    ash = np.arcsinh(1 / mu)
    chord = v["c"] / v["R"]
    a1 = chord * mu**2 * ash
    a2 = chord * (mu / 2) * (np.sqrt(1 + mu**2) - mu**2 * ash)
    a3 = chord * ((2 - 3 * mu**2) * np.sqrt(1 + mu**2) + 3 * mu**4 * ash) / 8
    p1, p2 = mu * a1, mu * a2
    q = v["N"] * v["rho"] * v["C_l_alpha"] * v["R"] ** 5 * omega**2 / 4
    i_y, i_d = v["I_y"], v["I_d"]
    mass = np.array([[i_y, 0, i_d, 0], [0, i_y, 0, i_d], [i_d, 0, i_d, 0], [0, i_d, 0, i_d]])
    gyro = v["I_x"] * omega * np.array([[0, 1, 0, 1], [-1, 0, -1, 0], [0, 1, 0, 1],
                                        [-1, 0, -1, 0]])
    aero_stiffness = q * np.array([[a * p1, p2, a * p1, p2], [-p2, a * p1, -p2, a * p1],
                                   [0, p2, 0, p2], [-p2, 0, -p2, 0]])
    aero_damping = q / omega * np.array([
        [-a3 - a**2 * a1, 0, -a3, a * a2], [0, -a3 - a**2 * a1, -a * a2, -a3],
        [-a3, -a * a2, -a3, 0], [a * a2, -a3, 0, -a3]])
    damping = np.diag([v["C_theta"], v["C_psi"], v["C_beta"], v["C_beta"]]) + gyro \
        - aero_damping
    stiffness = np.diag([v["K_theta"], v["K_psi"], v["K_beta"], v["K_beta"]]) - aero_stiffness
    return mass, damping, stiffness


def freeplay_simulation(values: dict, dof: str, delta: float, k_out: float, y0: np.ndarray,
                        duration: float, k_in: float = 0.0, samples_per_second: int = 2000):
    """(t, y): the exact-law simulation from ``y0`` (8 states, derivation frame) for
    ``duration`` s, sampled ``samples_per_second``; freeplay on ``dof`` with ``k_out``
    outside the gap (the dof's linear spring in ``values`` is replaced)."""
    j = DOFS.index(dof)
    mass, damping, stiffness = matrices({**values, ("K_beta" if j > 1 else f"K_{dof}"): k_out})
    stiffness = stiffness.copy()
    stiffness[j, j] -= k_out  # the dof's spring is the freeplay law's
    minv = np.linalg.inv(mass)

    def field(piece: int):
        def f(_t, y):
            x = y[j]
            spring = k_in * x if piece == 0 else k_in * piece * delta + k_out * (
                x - piece * delta)
            force = stiffness @ y[:4] + damping @ y[4:]
            force[j] += spring
            return np.concatenate([y[4:], -minv @ force])
        return f

    def crossing(level: float, direction: int):
        def event(_t, y):
            return y[j] - level
        event.terminal, event.direction = True, direction
        return event

    # the breakpoints a piece can leave by, each only in the direction that leaves it
    leaving = {0: [crossing(delta, 1), crossing(-delta, -1)], 1: [crossing(delta, -1)],
               -1: [crossing(-delta, 1)]}
    grid = np.arange(0.0, duration, 1.0 / samples_per_second)
    t0, y, out_t, out_y = 0.0, np.asarray(y0, dtype=float), [], []
    piece = 0 if abs(y[j]) < delta else int(np.sign(y[j]))
    while True:
        sol = solve_ivp(field(piece), (t0, duration), y, method="DOP853", rtol=1e-10,
                        atol=1e-13, t_eval=grid[grid >= t0], events=leaving[piece])
        out_t.append(sol.t)
        out_y.append(np.reshape(sol.y, (len(y), -1)).T)  # no samples left: sol.y is []
        if sol.status != 1:
            return np.concatenate(out_t), np.vstack(out_y)
        hit = next(k for k, times in enumerate(sol.t_events) if len(times))
        t0, y = float(sol.t_events[hit][0]), sol.y_events[hit][0].copy()
        y[j] = delta * np.sign(y[j])  # exactly on the breakpoint
        piece = int(np.sign(y[j])) if piece == 0 else 0
        grid = grid[grid > t0]


def maxima(t: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(times, values) of the local maxima of the sampled ``x``, each on the parabola
    through its three samples."""
    i = np.flatnonzero((x[1:-1] > x[:-2]) & (x[1:-1] >= x[2:])) + 1
    left, mid, right = x[i - 1], x[i], x[i + 1]
    curvature = left - 2 * mid + right
    shift = 0.5 * (left - right) / np.where(curvature == 0, -1.0, curvature)
    step = t[1] - t[0]
    return t[i] + shift * step, mid - 0.25 * (left - right) * shift
