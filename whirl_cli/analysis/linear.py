"""Linear stability analysis with numpy: eigenvalues, damping, frequency and whirl direction.

Everything is vectorised over points: Jacobians are stacked into an (M, n, n) array and handed to
``numpy.linalg.eig`` in one call; there is no Python loop per point.

Conventions: eigenvalues lambda = sigma + i omega in 1/s (physical time). Damping ratio
zeta = -sigma / |lambda| (positive = damped), frequency omega = |Im lambda| in rad/s. Modes are
ordered per point by frequency, then by real part.

Mode identification is generic, from what the model declares (``Model.mode_groups``): a mode
belongs to the group of dofs (e.g. nacelle or gimbal) holding most of its energy, the share of
dof i being Re(conj(q_i) (M q)_i) / (q^H M q) for the displacement part q of the eigenvector
(the kinetic-energy split, |lambda|^2 (q^H M q) / 2 in total; defined for lambda = 0 too).
Whirl direction is read from the eigenvector: the path of the mode's group (for a nacelle the
hub, for a disc its tilt) in the plane normal to the spin axis (+x) turns with the spin (FW) or
against it (BW).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ..kinds import LocusKind, Spacing
from ..models import Model
from ..results import LinearGrid, LinearSweep
from ..runtime import thread_map

FORWARD, BACKWARD, NON_OSCILLATORY = "FW", "BW", "--"


@dataclass(frozen=True)
class CriticalPoint:
    """A loss of stability of the equilibrium found from eigenvalues.

    ``kind``: "hopf" (a complex pair crosses the imaginary axis; ``frequency`` its omega in rad/s)
    or "branch_point" (a real eigenvalue crosses zero: det J = 0; ``frequency`` 0).
    """

    kind: LocusKind
    parameter: str
    value: float
    frequency: float


def parameter_matrix(model: Model, overrides: dict[str, float], parameter: str,
                     values: np.ndarray) -> np.ndarray:
    """(P, M) parameter array: ``overrides`` on the defaults, ``parameter`` set to ``values``."""
    base = model.parameter_vector(overrides)
    params = np.repeat(base[:, None], len(values), axis=1)
    params[model.parameter_names.index(model.canonical(parameter))] = values
    return params


def plane_matrix(model: Model, overrides: dict[str, float], x_parameter: str,
                 x_values: np.ndarray, y_parameter: str, y_values: np.ndarray) -> np.ndarray:
    """(P, M) parameter array: ``overrides`` on the defaults, the two parameters set to the
    points (``x_values``, ``y_values``), each (M,)."""
    params = np.repeat(model.parameter_vector(overrides)[:, None], len(x_values), axis=1)
    params[model.parameter_names.index(model.canonical(x_parameter))] = x_values
    params[model.parameter_names.index(model.canonical(y_parameter))] = y_values
    return params


def jacobians(model: Model, params: np.ndarray, equilibrium: np.ndarray | None = None
              ) -> np.ndarray:
    """Stacked Jacobians (M, n, n) at ``equilibrium`` (default: y = 0) for params (P, M)."""
    y = np.zeros(model.n_states) if equilibrium is None else np.asarray(equilibrium, float)
    if y.ndim == 1:
        y = y[:, None]
    jac = model.jacobian_numpy(y, params)
    return np.broadcast_to(jac, (params.shape[1], model.n_states, model.n_states))


def energy_shares(model: Model, params: np.ndarray, eigenvectors: np.ndarray) -> np.ndarray:
    """(M, n_dof, n): each dof's share of each mode's energy (see the module doc; the shares
    of a mode sum to 1). ``params`` (P, M), ``eigenvectors`` (M, n, n) with modes as columns."""
    n_dof = model.n_states // 2
    q = eigenvectors[..., :n_dof, :]
    mass = np.broadcast_to(model.mass_numpy(params), (len(eigenvectors), n_dof, n_dof))
    split = np.real(np.conj(q) * np.einsum("mij,mjk->mik", mass, q))
    total = split.sum(axis=-2, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, split / total, 1.0 / n_dof)


def mode_groups(model: Model, params: np.ndarray, eigenvectors: np.ndarray) -> np.ndarray:
    """(M, n) index into ``model.mode_groups`` of the group holding most of each mode's
    energy (0 everywhere for a model with one group)."""
    groups = model.mode_groups
    if len(groups) == 1:
        return np.zeros(eigenvectors.shape[::2], dtype=int)
    shares = energy_shares(model, params, eigenvectors)
    per_group = np.stack([shares[:, list(dofs), :].sum(axis=1) for _, dofs, _ in groups],
                         axis=1)
    return np.argmax(per_group, axis=1)


def whirl_direction(model: Model, eigenvalues: np.ndarray, eigenvectors: np.ndarray,
                    groups: np.ndarray | None = None) -> np.ndarray:
    """"FW"/"BW"/"--" per eigenvalue: sense of the mode's group path relative to the spin (+x).

    For a mode y = Re(v e^{i omega t}), the path components Y, Z (the group's path matrix @ v;
    ``groups`` (M, n) their indices into ``model.mode_groups``, default the first group) trace
    a curve that turns about +x (with the spin, FW) when Im(conj(Y) Z) * omega < 0.
    """
    groups = np.zeros(eigenvalues.shape, dtype=int) if groups is None else groups
    sense = np.zeros(eigenvalues.shape)
    for k, (_, _, path) in enumerate(model.mode_groups):
        hub = np.einsum("hi,...ik->...hk", path, eigenvectors)
        hub_y, hub_z = hub[..., 0, :], hub[..., 1, :]
        sense = np.where(groups == k, np.imag(np.conj(hub_y) * hub_z), sense)
    sense = sense * np.sign(eigenvalues.imag)
    oscillatory = np.abs(eigenvalues.imag) > 1e-9 * np.maximum(np.abs(eigenvalues), 1.0)
    return np.where(~oscillatory, NON_OSCILLATORY, np.where(sense < 0, FORWARD, BACKWARD))


def analyse(model: Model, params: np.ndarray, equilibrium: np.ndarray | None = None
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Eigenvalues (M, n) sorted per point (by |omega|, then sigma), their whirl labels and
    their mode groups (indices into ``model.mode_groups``)."""
    eigenvalues, eigenvectors = np.linalg.eig(jacobians(model, params, equilibrium))
    order = np.lexsort((eigenvalues.real, -eigenvalues.imag, np.abs(eigenvalues.imag)), axis=-1)
    eigenvalues = np.take_along_axis(eigenvalues, order, axis=-1)
    eigenvectors = np.take_along_axis(eigenvectors, order[:, None, :], axis=-1)
    groups = mode_groups(model, params, eigenvectors)
    return eigenvalues, whirl_direction(model, eigenvalues, eigenvectors, groups), groups


def samples(lower: float, upper: float, points: int, spacing: Spacing = Spacing.LINEAR
            ) -> np.ndarray:
    """``points`` values from ``lower`` to ``upper``: evenly spaced, or (log, both > 0)
    ``lower * (upper / lower) ** (k / (points - 1))``, a constant ratio between neighbours."""
    if spacing == Spacing.LOG:
        return np.geomspace(lower, upper, points)
    return np.linspace(lower, upper, points)


def sweep(model: Model, overrides: dict[str, float], parameter: str, values: np.ndarray,
          equilibrium: np.ndarray | None = None) -> LinearSweep:
    """Linear analysis at every value of ``parameter`` (others at datum + ``overrides``);
    the sweep records the parameter's datum."""
    values = np.asarray(values, dtype=float)
    params = parameter_matrix(model, overrides, parameter, values)
    eigenvalues, whirl, groups = analyse(model, params, equilibrium)
    modulus = np.abs(eigenvalues)
    with np.errstate(invalid="ignore", divide="ignore"):
        damping = np.where(modulus > 0, -eigenvalues.real / modulus, 0.0)
    name = model.canonical(parameter)
    names = np.array([g[0] for g in model.mode_groups], dtype=object)
    return LinearSweep(name, model.parameter(name).unit, values, eigenvalues, damping,
                       np.abs(eigenvalues.imag), whirl,
                       names[groups] if len(names) > 1 else None,
                       datum=float(model.parameter(name).default))


def _oscillatory_growth(model: Model, params: np.ndarray) -> np.ndarray:
    """Max real part over the complex eigenvalues, per point (-inf where none)."""
    eigenvalues = np.linalg.eigvals(jacobians(model, params))
    oscillatory = np.abs(eigenvalues.imag) > 1e-6 * np.maximum(np.abs(eigenvalues), 1.0)
    return np.where(oscillatory, eigenvalues.real, -np.inf).max(axis=-1)


def _determinant(model: Model, params: np.ndarray) -> np.ndarray:
    return np.linalg.det(jacobians(model, params))


def critical_points(model: Model, overrides: dict[str, float], parameter: str,
                    lower: float, upper: float, points: int = 2001, xtol: float = 1e-12
                    ) -> list[CriticalPoint]:
    """Hopf and branch points of the equilibrium y = 0 in [lower, upper] from eigenvalues.

    A vectorised scan brackets every sign change of the oscillatory growth rate (Hopf) and of
    det J (a real eigenvalue through zero); each is refined with Brent's method to ``xtol``.
    """
    from scipy.optimize import brentq  # imported here: scipy.optimize is slow to import

    name = model.canonical(parameter)
    grid = np.linspace(lower, upper, points)

    def at(value: float) -> np.ndarray:
        return parameter_matrix(model, overrides, name, np.array([value]))

    found: list[CriticalPoint] = []
    scans = ((LocusKind.HOPF, _oscillatory_growth), (LocusKind.BRANCH_POINT, _determinant))
    for kind, function in scans:
        samples = function(model, parameter_matrix(model, overrides, name, grid))
        finite = np.isfinite(samples)
        for k in np.flatnonzero(finite[:-1] & finite[1:] & (np.sign(samples[:-1])
                                                             != np.sign(samples[1:]))):
            value = brentq(lambda v, f=function: float(f(model, at(v))[0]), grid[k], grid[k + 1],
                           xtol=xtol)
            frequency = 0.0
            if kind == LocusKind.HOPF:
                eigenvalues = np.linalg.eigvals(jacobians(model, at(value)))[0]
                critical = eigenvalues[np.argmin(np.abs(eigenvalues.real))]
                frequency = float(abs(critical.imag))
                # a real pair colliding into a complex pair off the axis is no Hopf point
                if abs(critical.real) > 1e-6 * abs(critical) or frequency < 1e-6 * abs(
                        eigenvalues).max():
                    continue
            found.append(CriticalPoint(kind, name, float(value), frequency))
    return sorted(found, key=lambda c: c.value)


# ------------------------------------------------------------------------------------ grid
def batched_eigenvalues(matrices: np.ndarray) -> np.ndarray:
    """``numpy.linalg.eigvals`` of a stack (M, n, n), split over the CPU cores (the batched
    LAPACK call releases the GIL, so threads run it in parallel)."""
    workers = min(os.cpu_count() or 1, max(1, len(matrices) // 4096))
    if workers == 1:
        return np.linalg.eigvals(matrices)
    return np.concatenate(thread_map(np.linalg.eigvals, np.array_split(matrices, workers),
                                     workers))


def _critical(model: Model, params: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(max real part, is the critical eigenvalue complex) per column of ``params`` (P, M)."""
    eigenvalues = batched_eigenvalues(np.ascontiguousarray(jacobians(model, params)))
    k = np.argmax(eigenvalues.real, axis=1)
    critical = np.take_along_axis(eigenvalues, k[:, None], axis=1)[:, 0]
    oscillatory = np.abs(critical.imag) > 1e-6 * np.maximum(np.abs(critical), 1e-12)
    return critical.real, oscillatory


def grid(model: Model, overrides: dict[str, float], x_parameter: str, x_values: np.ndarray,
         y_parameter: str, y_values: np.ndarray) -> LinearGrid:
    """Max real part of the eigenvalues of y = 0 over a grid, and its zero contour split into
    flutter (complex critical eigenvalue) and divergence (real) parts. Vectorised: one batched
    eigenvalue computation for the whole grid."""
    import contourpy

    x_name, y_name = model.canonical(x_parameter), model.canonical(y_parameter)
    x_values, y_values = np.asarray(x_values, float), np.asarray(y_values, float)
    xx, yy = np.meshgrid(x_values, y_values)
    real, oscillatory = _critical(model, plane_matrix(model, overrides, x_name, xx.ravel(),
                                                      y_name, yy.ravel()))
    max_real = real.reshape(xx.shape)
    lines = contourpy.contour_generator(x_values, y_values, max_real).lines(0.0)
    flutter, divergence = _split_by_kind(model, overrides, x_name, y_name, lines)
    return LinearGrid(x_name, y_name, model.parameter(x_name).unit,
                      model.parameter(y_name).unit, x_values, y_values, max_real,
                      oscillatory.reshape(xx.shape), flutter, divergence)


def _split_by_kind(model: Model, overrides: dict[str, float], x_name: str, y_name: str,
                   lines: list[np.ndarray]) -> tuple[tuple[np.ndarray, ...], ...]:
    """Cut each contour polyline where the critical eigenvalue changes between complex and
    real; returns (flutter pieces, divergence pieces)."""
    pieces: dict[bool, list[np.ndarray]] = {True: [], False: []}
    for line in lines:
        if len(line) < 2:
            continue
        _, kind = _critical(model, plane_matrix(model, overrides, x_name, line[:, 0],
                                                y_name, line[:, 1]))
        cuts = np.flatnonzero(kind[1:] != kind[:-1]) + 1
        for part, flag in zip(np.split(np.arange(len(line)), cuts),
                              kind[np.r_[0, cuts]], strict=True):
            if len(part) >= 2:
                pieces[bool(flag)].append(line[part])
    return tuple(pieces[True]), tuple(pieces[False])
