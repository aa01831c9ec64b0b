"""Classical whirl flutter: the Reed/Bielawa 2-DOF pitch-yaw rotor-nacelle (thesis ch. 3).

Sources (see ``../shared/models.md``): Mair, Rezgui & Titurus, Nonlinear Dyn. 94 (2018) for the
model; C. Riso's public MATLAB implementation ``cristinariso/propeller-nacelle``
(``utilities/model/compute_A.m``), which states it follows Mair 2018 with no modifications, for
the equations; an independent quasi-steady strip-theory derivation for every coefficient.
Datum parameters: Reed's 1965 tabletop model (thesis Table 3.1), with C_l_alpha = 2 pi (the
table's "2" gives an onset of 14.9 m/s instead of 7.8) and rho = 1.225 kg/m^3 (not printed).

Equations (thesis/Riso sign convention), dofs q = [theta, psi], M = diag(I_y, I_y)::

    I_y theta'' = -S_theta + k_d theta - k_c psi - (C_theta + c_a) theta' + I_x Omega psi'
    I_y psi''   = -S_psi + k_c theta + k_d psi - I_x Omega theta' - (C_psi + c_a) psi'

    S_theta = K_theta theta, S_psi = K_psi psi, or the stiffness law's restoring moment;
    k_d = Q a A'_1 (direct aerodynamic stiffness), k_c = s_c Q A'_2 (cross aerodynamic stiffness),
    c_a = Q (A_3 + a^2 A_1) / Omega (aerodynamic damping), Q = N rho C_l_alpha R^5 Omega^2 / 4,
    mu = V / (Omega R) and, with c/R constant,
    A_1 = (c/R) mu^2 asinh(1/mu),  A_2 = (c/R) (mu/2) [sqrt(1+mu^2) - mu^2 asinh(1/mu)],
    A_3 = (c/R) [(2 - 3 mu^2) sqrt(1+mu^2) + 3 mu^4 asinh(1/mu)] / 8,  A'_1 = mu A_1, A'_2 = mu A_2.

The aerodynamic-coupling switch s_c = ``aero_coupling`` (dimensionless, in [0, 1], datum 1) is
a factor on the aerodynamic cross terms: the cross aerodynamic stiffness k_c, which couples
pitch and yaw (thesis figs. 3.9-3.11: "with and without the aerodynamic coupling"; science.md:
without it gyroscopics alone cannot destabilise). The quasi-steady theory has no aerodynamic
cross damping (the damping matrix is diagonal), so nothing else is scaled: the direct stiffness
k_d and the damping c_a stay. s_c = 1 is the model above; s_c = 0 decouples the aerodynamics,
leaving only the gyroscopic coupling I_x Omega. It is an ordinary parameter (PAR in AUTO).

Sign conventions: the rotor spins about +x (forward along the shaft); theta is pitch about +y.
Relative to the strip-theory derivation frame, psi is measured about -z (psi -> -psi), which
leaves every eigenvalue unchanged and gives deflected equilibria with theta and psi of the same
sign, as the thesis reports. The hub offset is (y, z) = (-a R psi, -a R theta); backward whirl
(BW, against the spin) has theta in phase with psi_dot.

Regularisation: mu enters as sqrt(mu^2 + 1e-16) so that V = 0 (mu -> 0, where A_1 = A_2 = 0) is
finite; the relative change is below 1e-12 for V > 1e-2 m/s.
"""

from __future__ import annotations

import math

from .declaration import NON_NEGATIVE, POSITIVE, Bounds, Dof, Family, Parameter

#: AUTO's time: tau = TIME_SCALE * t, with the datum rotor speed (the BW mode is ~34 rad/s).
TIME_SCALE = 40.0

DOFS = (
    Dof("theta", "dtheta", "rad", "nacelle pitch about the pivot", amplitude=1.0,
        stiffness="K_theta"),
    Dof("psi", "dpsi", "rad", "nacelle yaw about the pivot", amplitude=1.0, stiffness="K_psi"),
)

PARAMETERS = (
    Parameter("K_theta", 0.4, "N m/rad", "pitch spring stiffness"),
    Parameter("K_psi", 0.4, "N m/rad", "yaw spring stiffness"),
    Parameter("V", 6.7, "m/s", "free-stream airspeed", bounds=NON_NEGATIVE),
    Parameter("C_theta", 0.001, "N m s/rad", "pitch viscous damping", bounds=NON_NEGATIVE),
    Parameter("C_psi", 0.001, "N m s/rad", "yaw viscous damping", bounds=NON_NEGATIVE),
    Parameter("Omega", 40.0, "rad/s", "rotor speed", bounds=POSITIVE),
    Parameter("I_y", 0.000178, "kg m^2", "nacelle + rotor inertia about the pivot (I_y = I_z)",
              bounds=POSITIVE),
    Parameter("rho", 1.225, "kg/m^3", "air density", bounds=NON_NEGATIVE),
    Parameter("a", 0.25, "1", "pivot-to-hub distance / R", bounds=NON_NEGATIVE),
    Parameter("I_x", 0.000103, "kg m^2", "rotor polar inertia", bounds=NON_NEGATIVE),
    Parameter("R", 0.152, "m", "rotor radius", bounds=POSITIVE),
    Parameter("c", 0.026, "m", "blade chord (constant)", bounds=NON_NEGATIVE),
    Parameter("N", 4.0, "1", "number of blades (>= 3: the azimuth average of the blade "
              "forces is exact)", bounds=Bounds(lower=3.0, integer=True)),
    Parameter("C_l_alpha", 2.0 * math.pi, "1/rad", "blade section lift slope", bounds=POSITIVE),
    Parameter("aero_coupling", 1.0, "1", "factor on the aerodynamic cross terms (the cross "
              "stiffness k_c coupling pitch and yaw): 1 = on (the model), 0 = off",
              bounds=Bounds(lower=0.0, upper=1.0)),
)

NOTES = (
    "Recovered from Mair et al. 2018 via Riso's implementation and a strip-theory derivation "
    "(../shared/models.md). Onset 7.764 m/s at datum (thesis ~7.8). Angles in rad inside the "
    "model; hub offset (y, z) = (-a R psi, -a R theta); rotor spin about +x."
)


def aerodynamic_integrals(p: dict):
    """(Q, mu, A_1, A_2, A_3): the moment scale Q [N m], the regularised advance ratio mu and
    the radial integrals (models.md 2.2; A'_1 = mu A_1, A'_2 = mu A_2), as sympy expressions
    of the parameter symbols ``p`` (by name)."""
    import sympy as sp

    V, Omega, R, c = p["V"], p["Omega"], p["R"], p["c"]
    mu = sp.sqrt((V / (Omega * R)) ** 2 + sp.Float(1e-16))
    ash = sp.asinh(1 / mu)
    root = sp.sqrt(1 + mu**2)
    a1 = (c / R) * mu**2 * ash
    a2 = (c / R) * (mu / 2) * (root - mu**2 * ash)
    a3 = (c / R) * ((2 - 3 * mu**2) * root + 3 * mu**4 * ash) / 8
    q = p["N"] * p["rho"] * p["C_l_alpha"] * R**5 * Omega**2 / 4
    return q, mu, a1, a2, a3


def aerodynamic_coefficients(p: dict):
    """(k_d, k_c, c_a): direct and cross aerodynamic stiffness [N m/rad], damping [N m s/rad],
    as sympy expressions of the parameter symbols ``p`` (by name); k_c carries the switch
    ``aero_coupling`` (k_c = aero_coupling Q A'_2, the models.md value at its datum 1)."""
    q, mu, a1, a2, a3 = aerodynamic_integrals(p)
    Omega = p["Omega"]
    k_d = q * p["a"] * mu * a1
    k_c = p["aero_coupling"] * q * mu * a2
    c_a = q * (a3 + p["a"] ** 2 * a1) / Omega
    return k_d, k_c, c_a


def equations(q: dict, v: dict, p: dict):
    """(M, G) of the classical model (see the module doc)."""
    import sympy as sp

    k_d, k_c, c_a = aerodynamic_coefficients(p)
    theta, psi, dtheta, dpsi = q["theta"], q["psi"], v["theta"], v["psi"]
    gyro = p["I_x"] * p["Omega"]
    mass = sp.diag(p["I_y"], p["I_y"])
    forces = sp.Matrix([
        k_d * theta - k_c * psi - (p["C_theta"] + c_a) * dtheta + gyro * dpsi,
        k_c * theta + k_d * psi - gyro * dtheta - (p["C_psi"] + c_a) * dpsi,
    ])
    return mass, forces


FAMILY = Family(
    name="classical",
    description="Reed/Bielawa pitch-yaw rotor-nacelle (thesis chapter 3)",
    dofs=DOFS,
    parameters=PARAMETERS,
    equations=equations,
    time_scale=TIME_SCALE,
    hub=(((1, -1.0),), ((0, -1.0),)),  # (y, z) = (-a R psi, -a R theta), up to the factor a R
    symmetric=True,
    linear=True,
    notes=NOTES,
)
