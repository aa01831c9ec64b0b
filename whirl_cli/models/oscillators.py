"""A test model: three coupled oscillators with a full mass matrix (6 states).

Not a rotor: it exists to check the general core (a full mass matrix, any number of dofs,
laws on any dof) against a linear onset known in closed form. Dofs q1, q2, q3 (m) with

    M q'' + (alpha M + beta K) q' + K q + gamma (q_i^2 q_i')_i = 0,

M = m [[2, 1, 0], [1, 2, 1], [0, 1, 2]] (full, positive definite), K = diag(k1, k2, k3) (each
k_i q_i replaceable by a stiffness law) and a van der Pol-like damping gamma q_i^2 q_i' that
makes the Hopf points generic. With k1 = k2 = k3 = k the modes are those of M: the generalised
eigenvalues of (K, M) are omega_j^2 = k / (m mu_j), mu_j = 2 + 2 cos(j pi / 4), j = 1, 2, 3, and
mode j has modal damping alpha + beta omega_j^2, so mode j crosses the imaginary axis (a Hopf
point in alpha) at alpha_j = -beta omega_j^2: as alpha falls, first the softest mode j = 1
(mu_1 = 2 + sqrt 2), at -0.01464 for the datum values. Units are SI (m, kg, N/m).
"""

from __future__ import annotations

from .declaration import NON_NEGATIVE, POSITIVE, Dof, Family, Parameter

DOFS = tuple(Dof(f"q{i}", f"dq{i}", "m", f"displacement of oscillator {i}", amplitude=1.0,
                 stiffness=f"k{i}") for i in (1, 2, 3))

PARAMETERS = (
    Parameter("k1", 1.0, "N/m", "stiffness of oscillator 1"),
    Parameter("k2", 1.0, "N/m", "stiffness of oscillator 2"),
    Parameter("k3", 1.0, "N/m", "stiffness of oscillator 3"),
    Parameter("alpha", 0.1, "1/s", "mass-proportional damping (Rayleigh)"),
    Parameter("beta", 0.05, "s", "stiffness-proportional damping (Rayleigh)", bounds=NON_NEGATIVE),
    Parameter("gamma", 1.0, "N s/m^3", "nonlinear damping gamma q^2 q'", bounds=NON_NEGATIVE),
    Parameter("m", 1.0, "kg", "mass scale of the mass matrix", bounds=POSITIVE),
)


def equations(q: dict, v: dict, p: dict):
    """(M, G): M as in the module doc; G = -(alpha M + beta K) v - gamma q_i^2 v_i."""
    import sympy as sp

    names = ("q1", "q2", "q3")
    mass = p["m"] * sp.Matrix([[2, 1, 0], [1, 2, 1], [0, 1, 2]])
    stiffness = sp.diag(p["k1"], p["k2"], p["k3"])
    rates = sp.Matrix([v[n] for n in names])
    damping = (p["alpha"] * mass + p["beta"] * stiffness) * rates
    nonlinear = sp.Matrix([p["gamma"] * q[n] ** 2 * v[n] for n in names])
    return mass, -damping - nonlinear


FAMILY = Family(
    name="oscillators",
    description="three coupled oscillators with a full mass matrix (a test model, not a rotor)",
    dofs=DOFS,
    parameters=PARAMETERS,
    equations=equations,
    time_scale=1.0,
    hub=(((0, 1.0),), ((1, 1.0),)),
    symmetric=True,
    linear=False,
    notes="A test model of the general core: linear onset in closed form (module doc).",
)
