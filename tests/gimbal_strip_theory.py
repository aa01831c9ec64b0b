"""The gimballed rotor's aerodynamic generalised forces derived for tests with sympy, apart from
whirl's model files: quasi-steady strip theory on the perturbation (../shared/models.md 2.3 and
8), blade elements on the tilted disc, the hub on the nacelle, for two ways of holding blade
pitch: relative to the tilted disc (each blade feathers by the tilt's component about its span)
or relative to the shaft (a swashplate's pitch links, delta3 = 0: no such feathering).

Derivation frame: spin about +x, theta about +y, psi and beta_z about +z; q = [theta, psi,
beta_y, beta_z]. ``aerodynamic(shaft)`` gives the 4 x 8 matrix of d Q_i / d(q, q') with the
radial integrals done in closed form; ``matrices`` the numeric (M, D, K) of the linear model.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import sympy as sp

from .gimballed_exact import DATUM

MU, ETA, AZIMUTH = sp.symbols("mu eta A", positive=True)
A_LEVER = sp.Symbol("a", positive=True)
Q = sp.symbols("theta psi beta_y beta_z", real=True)
DQ = sp.symbols("dtheta dpsi dbeta_y dbeta_z", real=True)


def _rotated(vector: sp.Matrix, angles: sp.Matrix) -> sp.Matrix:
    """``vector`` turned by the small rotation ``angles`` (first order)."""
    return vector + angles.cross(vector)


@cache
def _kernel(power: int) -> sp.Expr:
    """int_0^1 eta^power / sqrt(eta^2 + mu^2) d eta, in closed form."""
    return sp.simplify(sp.integrate(ETA**power / sp.sqrt(ETA**2 + MU**2), (ETA, 0, 1)))


@cache
def aerodynamic(shaft: bool) -> sp.Matrix:
    """d Q_i / d(q_j, q'_j) in units of Q (c/R) = N rho C_l_alpha R^5 Omega^2 c / (4 R), rates
    per Omega: a 4 x 8 matrix in mu and a."""
    x = sp.Matrix([1, 0, 0])
    radial = sp.Matrix([0, sp.cos(AZIMUTH), sp.sin(AZIMUTH)])
    tangential = sp.Matrix([0, -sp.sin(AZIMUTH), sp.cos(AZIMUTH)])
    theta, psi, beta_y, beta_z = Q
    nacelle = sp.Matrix([0, theta, psi])
    disc = sp.Matrix([0, theta + beta_y, psi + beta_z])
    # lengths in R, speeds in Omega R (so the rates DQ are q' / Omega): the element at eta on
    # the tilted disc, the hub at a R
    position = _rotated(A_LEVER * x, nacelle) + _rotated(ETA * radial, disc)
    velocity = position.jacobian(Q) * sp.Matrix(DQ) + position.diff(AZIMUTH) + MU * x
    u_t = (velocity.T * _rotated(tangential, disc))[0]
    u_p = (velocity.T * _rotated(x, disc))[0]
    origin = {s: 0 for s in Q + DQ}

    def first_order(expr):
        return sum(sp.diff(expr, s).subs(origin) * s for s in Q + DQ)

    feathering = beta_y * sp.cos(AZIMUTH) + beta_z * sp.sin(AZIMUTH)
    steady_t, steady_p = ETA, MU
    # U^2 times the angle of attack's perturbation: the inflow angle's, and with pitch held on
    # the shaft the pitch links' undoing of the tilt's feathering
    lift = -(steady_t * first_order(u_p) - steady_p * first_order(u_t))
    if shaft:
        lift -= (steady_t**2 + steady_p**2) * feathering
    direction = steady_t * x - steady_p * tangential  # U times the steady lift direction
    rows = []
    for j in range(4):
        lever = position.jacobian(Q)[:, j].subs(origin)
        per_blade = sp.expand(lift * (direction.T * lever)[0])
        average = sp.expand(sp.integrate(per_blade, (AZIMUTH, 0, 2 * sp.pi)) / (2 * sp.pi))
        # dL = 1/2 rho c C_l_alpha U^2 d alpha over N blades, / U for the unit direction:
        # N rho C_l_alpha c R^4 Omega^2 / 2 * int poly(eta) / sqrt(eta^2 + mu^2) d eta
        poly = sp.Poly(average, ETA)
        row = []
        for s in Q + DQ:
            coefficient = sum(c.coeff(s) * _kernel(k) for (k,), c in poly.terms())
            row.append(2 * coefficient)  # 1/2 / (1/4): in units of Q c/R
        rows.append(row)
    return sp.Matrix(rows)


@cache
def _compiled(shaft: bool):
    return sp.lambdify([MU, A_LEVER], aerodynamic(shaft), "numpy")


def matrices(values: dict, shaft: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(M, D, K) of the linear gimballed model (derivation frame) at ``values`` over DATUM, the
    aerodynamic terms from :func:`aerodynamic`."""
    v = {**DATUM, **values}
    omega = v["Omega"]
    scale = v["N"] * v["rho"] * v["C_l_alpha"] * v["R"] ** 5 * omega**2 / 4 * v["c"] / v["R"]
    mu = max(v["V"] / (omega * v["R"]), 1e-12)
    aero = np.array(_compiled(shaft)(mu, v["a"]), dtype=float)
    i_y, i_d = v["I_y"], v["I_d"]
    mass = np.array([[i_y, 0, i_d, 0], [0, i_y, 0, i_d], [i_d, 0, i_d, 0], [0, i_d, 0, i_d]])
    gyro = v["I_x"] * omega * np.array([[0, 1, 0, 1], [-1, 0, -1, 0], [0, 1, 0, 1],
                                        [-1, 0, -1, 0]])
    damping = np.diag([v["C_theta"], v["C_psi"], v["C_beta"], v["C_beta"]]) + gyro \
        - scale * aero[:, 4:] / omega
    stiffness = np.diag([v["K_theta"], v["K_psi"], v["K_beta"], v["K_beta"]]) \
        - scale * aero[:, :4]
    return mass, damping, stiffness
