"""The classical model's datum (models.md table 3, thesis Table 3.1) and its aerodynamic
coefficients from the closed-form radial integrals of models.md 2.2, in numpy, written apart
from whirl's model."""

from __future__ import annotations

import numpy as np

# datum of models.md table 3 (thesis Table 3.1), SI units
R, OMEGA, BLADES, CHORD, LIFT_SLOPE, V = 0.152, 40.0, 4, 0.026, 2 * np.pi, 6.7
A, I_X, I_Y, DAMPING, RHO = 0.25, 0.000103, 0.000178, 0.001, 1.225


def aerodynamic_coefficients(v: float = V) -> tuple[float, float, float]:
    """(k_d, k_c, c_a) from the closed-form radial integrals of models.md 2.2."""
    mu = v / (OMEGA * R)
    ratio, arsinh, root = CHORD / R, np.arcsinh(1 / mu), np.sqrt(1 + mu * mu)
    a1 = ratio * mu * mu * arsinh
    a2 = ratio * mu / 2 * (root - mu * mu * arsinh)
    a3 = ratio * ((2 - 3 * mu * mu) * root + 3 * mu ** 4 * arsinh) / 8
    q = BLADES * RHO * LIFT_SLOPE * R ** 5 * OMEGA ** 2 / 4
    return q * A * mu * a1, q * mu * a2, q * (a3 + A * A * a1) / OMEGA
