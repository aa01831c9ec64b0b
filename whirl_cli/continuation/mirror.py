"""Mirror images of a symmetric model (equations invariant under y -> -y): Hopf points in +/-
pairs, and a periodic family of one mapped onto the other's instead of computed again, so the
two carry the same special points by construction; so too the families doubled at their
period-doubling points (:mod:`.doubling`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ..models import Model
from ..results import Branch, Origin, PointType, SpecialPoint
from .branches import joined_notes, typical_amplitudes

#: Mirror Hopf points agree to this fraction of the range in the parameter, this many typical
#: amplitudes (or relatively) in the state and relatively in the period.
MIRROR_TOLERANCE = 1e-6


def is_odd(model: Model, parameters: np.ndarray, states: list[np.ndarray]) -> bool:
    """True if the model's right-hand side is odd, f(-y) = -f(y), at ``states`` and at each
    dof displaced by a typical amplitude (the premise of mapping mirror images)."""
    amplitudes = typical_amplitudes(model)
    probes = list(states) + [np.where(np.arange(model.n_states) == k, amplitudes, 0.0)
                             for k in range(model.n_states)]
    for y in probes:
        forward = model.rhs_numpy(np.asarray(y, dtype=float), parameters)
        backward = model.rhs_numpy(-np.asarray(y, dtype=float), parameters)
        if not np.allclose(backward, -forward, rtol=1e-9, atol=1e-12 * (1 + abs(forward).max())):
            return False
    return True


def mirror_sources(model: Model, hopfs: list[SpecialPoint], width: float,
                   parameters: dict[str, float]) -> dict[int, int]:
    """{k: j} for every Hopf point k that is the mirror image of an earlier one j (same
    parameter and period, opposite state off y = 0), where the model is symmetric and its
    right-hand side odd there; Hopf points on y = 0 are their own images and map to none."""
    if not model.symmetric:
        return {}
    amplitudes = typical_amplitudes(model)
    return _images(model, hopfs, parameters,
                   lambda a, b: _mirrors(a, b, width, amplitudes))


def mirror_points(model: Model, points: list[SpecialPoint], branches: dict[str, Branch],
                  width: float, parameters: dict[str, float]) -> dict[int, int]:
    """{k: j} for every point k on a periodic family that is the mirror image of an earlier
    one j on another family (same type, parameter and period; the orbit at k the negated
    orbit at j: its maxima the negated minima), where the model is symmetric and its
    right-hand side odd there."""
    if not model.symmetric:
        return {}
    amplitudes = typical_amplitudes(model)

    def orbit(point: SpecialPoint) -> tuple[np.ndarray, np.ndarray]:
        branch = branches[point.branch]
        return (branch.state_max[point.index] / amplitudes,
                branch.state_min[point.index] / amplitudes)

    return _images(model, points, parameters,
                   lambda a, b: _mirror_pair(a, b, orbit(a), orbit(b), width))


def _images(model: Model, points: list[SpecialPoint], parameters: dict[str, float],
            pair: Callable[[SpecialPoint, SpecialPoint], bool]) -> dict[int, int]:
    """{k: j} for every point k whose first earlier ``pair``-ed point j (not itself an
    image) it mirrors, where the model's right-hand side is odd at k's parameter value."""
    images: dict[int, int] = {}
    for k, point in enumerate(points):
        for j, other in enumerate(points[:k]):
            if j in images or not pair(point, other):
                continue
            name = point.parameter_names[0]
            params = model.parameter_vector({**parameters, name: float(point.parameters[0])})
            if is_odd(model, params, [point.state]):
                images[k] = j
            break
    return images


def _mirror_pair(a: SpecialPoint, b: SpecialPoint, orbit_a: tuple[np.ndarray, np.ndarray],
                 orbit_b: tuple[np.ndarray, np.ndarray], width: float) -> bool:
    """True if ``a`` and ``b``, on different families, are of one type at one parameter and
    period, and their orbits (maxima, minima) each other's negatives."""
    return (a.branch != b.branch and a.point_type == b.point_type
            and abs(a.parameters[0] - b.parameters[0]) <= MIRROR_TOLERANCE * width
            and abs(a.period - b.period) <= MIRROR_TOLERANCE * abs(b.period)
            and _negated(orbit_a, orbit_b))


def _negated(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]) -> bool:
    """True if the orbit with (maxima, minima) ``a`` is the negated ``b``: its maxima ``b``'s
    negated minima and the other way round, to MIRROR_TOLERANCE."""
    return all(np.allclose(x, y, rtol=MIRROR_TOLERANCE, atol=MIRROR_TOLERANCE)
               for x, y in zip(a, (-b[1], -b[0]), strict=True))


def _mirrors(a: SpecialPoint, b: SpecialPoint, width: float, amplitudes: np.ndarray) -> bool:
    """True if ``a`` and ``b`` are each other's mirror images, off y = 0."""
    sa, sb = a.state / amplitudes, b.state / amplitudes
    return (np.abs(sa).max() > 1e-3
            and abs(a.parameters[0] - b.parameters[0]) <= MIRROR_TOLERANCE * width
            and abs(a.period - b.period) <= MIRROR_TOLERANCE * abs(b.period)
            and np.allclose(sa, -sb, rtol=MIRROR_TOLERANCE, atol=MIRROR_TOLERANCE))


def mirrored_branch(branch: Branch, name: str, origin: Origin, end: str) -> Branch:
    """The mirror image of a periodic ``branch``: states negated (the maxima are the negated
    minima), everything else the same; named ``name``, from ``origin``, ending as ``end``
    says."""
    return replace(branch, name=name, origin=origin, end=end,
                   state_max=-branch.state_min, state_min=-branch.state_max,
                   message=joined_notes(branch.message, f"mirror image (y -> -y) of {branch.name}"),
                   orbits=tuple(replace(o, states=-o.states) for o in branch.orbits))


def mirrored_point(point: SpecialPoint, branch: Branch) -> SpecialPoint:
    """The mirror image of ``point`` on the mirrored ``branch``: a global bifurcation's state
    (its saddle) negated, a point of the family its maximum there."""
    state = -point.state if point.point_type in (PointType.HOMOCLINIC, PointType.HETEROCLINIC) \
        else branch.state_max[point.index]
    note = f"mirror image of the point on {point.branch} ({point.note})" if point.note else ""
    return replace(point, branch=branch.name, state=np.array(state, dtype=float), note=note)
