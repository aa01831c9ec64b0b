"""The gimballed model with whirl's exact freeplay law, written out for tests apart from whirl's
model file (../shared/models.md sections 2.2, 7 and 8, in the derivation frame: psi and beta_z
of the thesis frame negated, which leaves |theta|, |beta_y|, periods and stability as they
are), and its exact freeplay law's motion, each piece of the law (where the model is linear) in
closed form, a root-finder at each breakpoint |x| = delta where the law changes piece.

q = [theta, psi, beta_y, beta_z]; M q'' + (C + G - C_a) q' + (K - K_a) q + freeplay = 0, the
freeplay dof's spring replaced by K_in x + (K_out - K_in) (x - delta sat(x / delta)).
"""

from __future__ import annotations

import numpy as np

from .piecewise_linear import affine_pieces, motion

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
    """(t, y): the exact-law motion from ``y0`` (8 states, derivation frame) for ``duration``
    s, sampled ``samples_per_second``; freeplay on ``dof`` with ``k_out`` outside the gap (the
    dof's linear spring in ``values`` is replaced), each piece of the law in closed form
    (:mod:`tests.piecewise_linear`)."""
    j = DOFS.index(dof)
    mass, damping, stiffness = matrices({**values, ("K_beta" if j > 1 else f"K_{dof}"): k_out})
    minv = np.linalg.inv(mass)

    def a_of(piece: int) -> np.ndarray:
        spring = stiffness.copy()
        spring[j, j] += (k_in if piece == 0 else k_out) - k_out  # the law's slope there
        return np.block([[np.zeros((4, 4)), np.eye(4)], [-minv @ spring, -minv @ damping]])

    def b_of(piece: int) -> np.ndarray:
        force = np.zeros(4)
        force[j] = piece * delta * (k_in - k_out)  # K_in x + (K_out - K_in)(x - delta sat)
        return np.concatenate([np.zeros(4), -minv @ force])

    return motion(affine_pieces(a_of, b_of), j, j + 4, delta, y0,
                  np.arange(0.0, duration, 1.0 / samples_per_second))


def maxima(t: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(times, values) of the local maxima of the sampled ``x``, each on the parabola
    through its three samples."""
    i = np.flatnonzero((x[1:-1] > x[:-2]) & (x[1:-1] >= x[2:])) + 1
    left, mid, right = x[i - 1], x[i], x[i + 1]
    curvature = left - 2 * mid + right
    shift = 0.5 * (left - right) / np.where(curvature == 0, -1.0, curvature)
    step = t[1] - t[0]
    return t[i] + shift * step, mid - 0.25 * (left - right) * shift
