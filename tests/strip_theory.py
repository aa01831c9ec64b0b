"""The classical model's aerodynamic coefficients written out for tests (../shared/models.md
section 2.2), apart from whirl's model file: k_d = Q a mu A_1, k_c = s_c Q mu A_2,
c_a = Q (A_3 + a^2 A_1) / Omega with Q = N rho C_l_alpha R^5 Omega^2 / 4, mu = V / (Omega R)
and A_1 = (c/R) mu^2 asinh(1/mu), A_2 = (c/R) (mu/2) [sqrt(1+mu^2) - mu^2 asinh(1/mu)],
A_3 = (c/R) [(2 - 3 mu^2) sqrt(1+mu^2) + 3 mu^4 asinh(1/mu)] / 8. ``values`` by parameter
name; the arithmetic is that of the values' type (floats, or sympy symbols/Floats)."""

from __future__ import annotations

import sympy as sp


def coefficients(values: dict):
    """(k_d, k_c, c_a) for parameter ``values`` (sympy objects or numbers)."""
    v = {name: sp.sympify(value) for name, value in values.items()}
    mu = sp.sqrt((v["V"] / (v["Omega"] * v["R"])) ** 2 + sp.Float(1e-16))
    ash = sp.asinh(1 / mu)
    chord = v["c"] / v["R"]
    a1 = chord * mu**2 * ash
    a2 = chord * (mu / 2) * (sp.sqrt(1 + mu**2) - mu**2 * ash)
    a3 = chord * ((2 - 3 * mu**2) * sp.sqrt(1 + mu**2) + 3 * mu**4 * ash) / 8
    q = v["N"] * v["rho"] * v["C_l_alpha"] * v["R"] ** 5 * v["Omega"] ** 2 / 4
    return (q * v["a"] * mu * a1, v["aero_coupling"] * q * mu * a2,
            q * (a3 + v["a"] ** 2 * a1) / v["Omega"])
