"""Gimballed-hub rotor-nacelle (8 states): PROVISIONAL, whirl's own derivation.

The papers' gimballed model (thesis chapters 4-5) is not recovered; this is the derivation of
``../shared/models.md`` section 8, built on the verified classical model
(:mod:`whirl_cli.models.classical`): a rigid rotor on a spring-restrained gimbal (a
constant-velocity hub) at the front of the classical nacelle, same quasi-steady strip theory,
the blade elements moving with the tilted disc and the hub with the nacelle.

Dofs q = [theta, psi, beta_y, beta_z] (rad) and their rates: nacelle pitch and yaw about the
pivot, and the disc tilt relative to the nacelle on the gimbal about the nacelle's y and z axes
(non-rotating frame); the disc's tilt in space is (theta + beta_y, psi + beta_z). New
parameters: the rotor's diametral inertia I_d (rigid blades in one plane: I_d = I_x / 2, the
datum 5.15e-5 kg m^2 is that of the datum I_x: set it with I_x), the isotropic gimbal spring
K_beta and damper C_beta. I_y keeps its classical meaning (nacelle + rotor about the pivot);
the nacelle alone has I_n = I_y - I_d, which must be > 0 (a constraint: M is invertible).

Equations, in the derivation frame (spin about +x, theta about +y, psi and beta_z about +z)::

    I_y th'' + I_d by'' + I_x Om (ps' + bz') + C_th th' + K_th th = Q_th
    I_y ps'' + I_d bz'' - I_x Om (th' + by') + C_ps ps' + K_ps ps = Q_ps
    I_d (th'' + by'') + I_x Om (ps' + bz') + C_b by' + K_b by    = Q_by
    I_d (ps'' + bz'') - I_x Om (th' + by') + C_b bz' + K_b bz    = Q_bz

    Q_th = Q [ a A'_1 (th+by) + A'_2 (ps+bz) - A_3 (th'+by')/Om - a^2 A_1 th'/Om + a A_2 bz'/Om ]
    Q_ps = Q [ a A'_1 (ps+bz) - A'_2 (th+by) - A_3 (ps'+bz')/Om - a^2 A_1 ps'/Om - a A_2 by'/Om ]
    Q_by = Q [ A'_2 (ps+bz) - A_3 (th'+by')/Om - a A_2 ps'/Om ]
    Q_bz = Q [ -A'_2 (th+by) - A_3 (ps'+bz')/Om + a A_2 th'/Om ]

with Q, mu, A_1, A_2, A_3, A'_1 = mu A_1, A'_2 = mu A_2 the classical model's (models.md 2.2).

The classical aerodynamic-coupling switch ``aero_coupling`` (a parameter of this model too,
datum 1) multiplies every A'_2 term, the cross aerodynamic stiffness (k_c in the nacelle rows),
as in the classical model; the a A_2 rate terms (cross damping between nacelle and gimbal rows,
which cancel in the nacelle rows when beta = 0) are not scaled. With beta = 0 the nacelle rows
are the classical model's for every value of the switch.

Sign conventions: whirl uses the thesis frame of the classical model, psi -> -psi and
beta_z -> -beta_z (psi and beta_z measured about -z), which leaves every eigenvalue unchanged;
with beta = 0 the nacelle rows are the classical model's exactly. In the code the
derivation-frame equations are written once and mapped with T = diag(1, -1, 1, -1): M = T M_d T,
G(q, v) = T G_d(T q, T v). The hub (the gimbal centre, moving with the nacelle) is at
(y, z) = (-a R psi, -a R theta) as in the classical model; the disc normal's tip at
(y, z) = (-(psi + beta_z), -(theta + beta_y)). Nacelle modes (energy mostly in theta, psi) are
labelled FW/BW by the hub path, gimbal modes (energy mostly in beta_y, beta_z) by the disc's.

Checks: ``tests/unit/test_gimballed.py`` (the nacelle rows' aerodynamic terms are the classical
k_d, k_c, c_a; stiff-gimbal limit; free-gimbal disc modes at 2 Omega and 0) and
``tests/auto/test_gimballed_auto.py`` (the stiff-gimbal Hopf points by AUTO).
"""

from __future__ import annotations

from . import classical
from .declaration import NON_NEGATIVE, POSITIVE, Constraint, Dof, Family, ModeGroup, Parameter

DOFS = (
    *classical.DOFS,
    Dof("beta_y", "dbeta_y", "rad", "disc tilt on the gimbal about the nacelle's y axis",
        amplitude=1.0, stiffness="K_beta"),
    Dof("beta_z", "dbeta_z", "rad", "disc tilt on the gimbal about the nacelle's z axis "
        "(thesis frame: about -z, like psi)", amplitude=1.0, stiffness="K_beta"),
)

PARAMETERS = (
    *classical.PARAMETERS,
    Parameter("I_d", 0.0000515, "kg m^2", "rotor diametral inertia (rigid blades in one plane: "
              "I_x / 2); the nacelle alone has I_n = I_y - I_d > 0", bounds=POSITIVE),
    Parameter("K_beta", 10.0, "N m/rad", "gimbal spring stiffness (isotropic; no published datum: "
              "10 is whirl's soft gimbal, 1e6 effectively rigid)", bounds=NON_NEGATIVE),
    Parameter("C_beta", 0.0, "N m s/rad", "gimbal viscous damping (isotropic)",
              bounds=NON_NEGATIVE),
)

CONSTRAINTS = (
    Constraint(("I_d", "I_y"), lambda v: v["I_y"] - v["I_d"] > 0.0,
               "the nacelle-only inertia I_n = I_y - I_d must be > 0 (I_d < I_y)"),
)

#: Mode groups: nacelle modes by the hub path, gimbal modes by the disc normal's path.
MODE_GROUPS = (
    ModeGroup("nacelle", ("theta", "psi"), (((1, -1.0),), ((0, -1.0),))),
    ModeGroup("gimbal", ("beta_y", "beta_z"), (((1, -1.0), (3, -1.0)), ((0, -1.0), (2, -1.0)))),
)

#: theta, psi, beta_y, beta_z in the derivation frame = FRAME * (the same in whirl's frame).
FRAME = (1, -1, 1, -1)

NOTES = (
    "PROVISIONAL: whirl's own derivation (../shared/models.md section 8), not the papers' "
    "equations. Classical nacelle + rotor on an isotropic gimbal; I_n = I_y - I_d > 0; hub "
    "offset (y, z) = (-a R psi, -a R theta); K_beta -> 1e6 gives the classical model."
)


def derivation_frame(q: tuple, v: tuple, p: dict):
    """(M_d, G_d): mass matrix and forces other than K q of models.md section 8 in its
    derivation frame, for dofs ``q`` = (theta, psi, beta_y, beta_z) and rates ``v``."""
    import sympy as sp

    th, ps, by, bz = q
    dth, dps, dby, dbz = v
    Q, mu, a1, a2, a3 = classical.aerodynamic_integrals(p)
    a, Om = p["a"], p["Omega"]
    a1p, a2p = mu * a1, p["aero_coupling"] * mu * a2  # the switch on the cross stiffness
    gyro = p["I_x"] * Om
    aero = sp.Matrix([
        a * a1p * (th + by) + a2p * (ps + bz) - a3 * (dth + dby) / Om - a**2 * a1 * dth / Om
        + a * a2 * dbz / Om,
        a * a1p * (ps + bz) - a2p * (th + by) - a3 * (dps + dbz) / Om - a**2 * a1 * dps / Om
        - a * a2 * dby / Om,
        a2p * (ps + bz) - a3 * (dth + dby) / Om - a * a2 * dps / Om,
        -a2p * (th + by) - a3 * (dps + dbz) / Om + a * a2 * dth / Om,
    ])
    gyroscopic = sp.Matrix([gyro * (dps + dbz), -gyro * (dth + dby),
                            gyro * (dps + dbz), -gyro * (dth + dby)])
    damping = sp.Matrix([p["C_theta"] * dth, p["C_psi"] * dps, p["C_beta"] * dby,
                         p["C_beta"] * dbz])
    I_y, I_d = p["I_y"], p["I_d"]
    mass = sp.Matrix([[I_y, 0, I_d, 0], [0, I_y, 0, I_d], [I_d, 0, I_d, 0], [0, I_d, 0, I_d]])
    return mass, Q * aero - gyroscopic - damping


def equations(q: dict, v: dict, p: dict):
    """(M, G) in whirl's (thesis) frame: the derivation frame mapped by :data:`FRAME`."""
    import sympy as sp

    names = [d.name for d in DOFS]
    frame = sp.diag(*FRAME)
    mass, forces = derivation_frame(tuple(s * q[n] for s, n in zip(FRAME, names, strict=True)),
                                    tuple(s * v[n] for s, n in zip(FRAME, names, strict=True)),
                                    p)
    return frame * mass * frame, frame * forces


FAMILY = Family(
    name="gimballed",
    description="gimballed-hub rotor-nacelle: the classical nacelle with its rotor on a gimbal "
                "(models.md section 8)",
    dofs=DOFS,
    parameters=PARAMETERS,
    equations=equations,
    time_scale=classical.TIME_SCALE,
    hub=classical.FAMILY.hub,
    mode_groups=MODE_GROUPS,
    constraints=CONSTRAINTS,
    symmetric=True,
    linear=True,
    provisional=True,
    notes=NOTES,
)
