"""The first Lyapunov coefficient of a Hopf point: its criticality from the equations alone.

At an equilibrium y0 with Jacobian A having the simple pair +-i omega (omega > 0) and no other
eigenvalue on the imaginary axis, the flow on the centre manifold is, in Kuznetsov's normal
form, dz/dt = (i omega) z + c1 z |z|^2 + ..., and the first Lyapunov coefficient is
l1 = Re(c1) / omega. With B(x, y) and C(x, y, z) the second and third derivatives of the
right-hand side at y0 (Kuznetsov, *Elements of Applied Bifurcation Theory*, 3rd ed., eq. 3.20):

    l1 = Re[ <p, C(q, q, conj q)> - 2 <p, B(q, A^-1 B(q, conj q))>
             + <p, B(conj q, (2 i omega I - A)^-1 B(q, q))> ] / (2 omega),

with A q = i omega q, A^T p = -i omega p, <q, q> = 1, <p, q> = 1 and <p, x> = conj(p) . x.

Sign convention: l1 < 0 is a supercritical Hopf (stable limit cycles on the side where the
equilibrium is unstable), l1 > 0 subcritical (unstable cycles on the stable side, the
overhang). Units: 1 / (s * state unit^2) in SI (whirl's states are rad and rad/s, so the value
depends on that scaling; only its sign is invariant). Zero for a linear model.
"""

from __future__ import annotations

import numpy as np

from ..kinds import Criticality
from ..models import Model


def first_lyapunov_coefficient(jacobian: np.ndarray, second: np.ndarray,
                               third: np.ndarray) -> float:
    """l1 of the Hopf pair of ``jacobian`` (n, n), given the derivative tensors ``second``
    (n, n, n) and ``third`` (n, n, n, n) of the right-hand side (see the module doc).

    The Hopf pair is the eigenvalue pair nearest the imaginary axis with non-zero imaginary
    part; ValueError if there is none."""
    eigenvalues, right = np.linalg.eig(jacobian)
    oscillatory = np.flatnonzero(eigenvalues.imag > 1e-12 * max(1.0, np.abs(eigenvalues).max()))
    if not len(oscillatory):
        raise ValueError("no complex eigenvalue pair: not a Hopf point")
    k = oscillatory[np.argmin(np.abs(eigenvalues.real[oscillatory]))]
    omega = float(eigenvalues[k].imag)
    q = right[:, k] / np.linalg.norm(right[:, k])
    left_values, left = np.linalg.eig(jacobian.T)
    p = left[:, np.argmin(np.abs(left_values - np.conj(eigenvalues[k])))]
    p = p / np.conj(np.vdot(p, q))  # <p, q> = vdot(p, q) = 1

    def bilinear(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return np.einsum("ijk,j,k->i", second, x, y)

    n = len(q)
    identity = np.eye(n)
    # A is used with its critical pair on the imaginary axis: solve with the exact omega
    a_inverse_b = np.linalg.solve(jacobian, bilinear(q, np.conj(q)))
    shifted = np.linalg.solve(2j * omega * identity - jacobian, bilinear(q, q))
    cubic = np.einsum("ijkm,j,k,m->i", third, q, q, np.conj(q))
    value = (np.vdot(p, cubic) - 2 * np.vdot(p, bilinear(q, a_inverse_b))
             + np.vdot(p, bilinear(np.conj(q), shifted)))
    return float(value.real / (2 * omega))


def hopf_lyapunov_coefficient(model: Model, state: np.ndarray, params: np.ndarray) -> float:
    """l1 [1/(s unit^2)] of ``model`` at the Hopf equilibrium ``state`` (SI) for the parameter
    vector ``params`` (declaration order)."""
    jacobian = model.jacobian_numpy(np.asarray(state, float), np.asarray(params, float))
    second, third = model.derivative_tensors(state, params)
    return first_lyapunov_coefficient(jacobian, second, third)


def criticality_of(l1: float, scale: float) -> Criticality:
    """Supercritical (l1 < 0), subcritical (l1 > 0), or unknown when |l1| <= 1e-9 ``scale``
    (degenerate to round-off, e.g. a linear model; ``scale``: a typical magnitude of l1)."""
    if not np.isfinite(l1) or abs(l1) <= 1e-9 * scale:
        return Criticality.UNKNOWN
    return Criticality.SUPERCRITICAL if l1 < 0 else Criticality.SUBCRITICAL
