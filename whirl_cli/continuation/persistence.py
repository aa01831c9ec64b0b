"""Persistence of special points as a smoothed law sharpens.

A smoothing (freeplay's epsilon) can create bifurcations of its own that vanish as it shrinks,
so a special point of such a model counts as physical only if it persists: it is recomputed
with every smoothing width halved and quartered, by short runs near it where they succeed
(:mod:`whirl_cli.continuation.shrinking`), else by repeating the continuation at those widths
and looking for it there (the same type, the nearest in the principal parameter).
:func:`annotate` stores the two values (``SpecialPoint.refined``, and how they were found in
``refined_by``) and flags a point that is not found again, or moves by more than ``tolerance``
of the range, as a smoothing artefact (``artefact``, and why in its ``note``).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..results import ContinuationResult, PointType, SpecialPoint
from .branches import joined_notes

#: The smoothing widths the continuation is repeated at, as fractions of the study's.
FACTORS = (0.5, 0.25)
#: A point persists if it moves by at most this fraction of the range at each refinement.
TOLERANCE = 2e-3
#: Types checked (global bifurcations are bracketed estimates, checked as they are).
CHECKED = frozenset({PointType.BP, PointType.LP, PointType.HB, PointType.LPC, PointType.BPC,
                     PointType.PD, PointType.TR, PointType.HOMOCLINIC, PointType.HETEROCLINIC})


def refined_parameters(parameters: dict[str, float], smoothing: tuple[str, ...],
                       factor: float) -> dict[str, float]:
    """``parameters`` with every smoothing width (by name, ``smoothing``) times ``factor``."""
    return {**parameters, **{name: parameters[name] * factor for name in smoothing}}


def annotate(base: ContinuationResult, refined: list[ContinuationResult],
             width: float, tolerance: float = TOLERANCE,
             recomputed: dict | None = None) -> ContinuationResult:
    """``base`` with each special point's values at :data:`FACTORS` and its artefact flag:
    those of ``recomputed`` (index of the point -> its
    :class:`~whirl_cli.continuation.shrinking.Recomputed`) as they are, the others' looked for
    in ``refined`` (the continuation repeated at :data:`FACTORS`; empty if every point was
    recomputed)."""
    recomputed = recomputed or {}
    points = tuple(_annotated(point, refined, width, tolerance, recomputed.get(k))
                   for k, point in enumerate(base.special_points))
    return replace(base, special_points=points)


def needs_repetition(base: ContinuationResult, recomputed: dict) -> bool:
    """True if a checked special point of ``base`` is not among ``recomputed`` (by index)."""
    return any(p.point_type in CHECKED and k not in recomputed
               for k, p in enumerate(base.special_points))


def _annotated(point: SpecialPoint, refined: list[ContinuationResult], width: float,
               tolerance: float, recomputed=None) -> SpecialPoint:
    if point.point_type not in CHECKED:
        return point
    if recomputed is not None:
        values, method = np.asarray(recomputed.values, dtype=float), recomputed.method
    else:
        values, method = np.array([_nearest(point, run) for run in refined]), "repetition"
    steps = np.diff(np.concatenate([[point.parameters[0]], values]))
    missing = [f"epsilon x {f:g}" for f, v in zip(FACTORS, values, strict=True)
               if np.isnan(v)]
    moved = np.nanmax(np.abs(steps)) if np.isfinite(steps).any() else 0.0
    artefact = bool(missing) or moved > tolerance * width
    if missing:
        why = "smoothing artefact: not found at " + ", ".join(missing)
    elif artefact:
        why = f"smoothing artefact: moves by {moved:.3g} as epsilon shrinks"
    else:
        why = ""
    return replace(point, refined=values, artefact=artefact, note=joined_notes(point.note, why),
                   refined_by=method)


def _nearest(point: SpecialPoint, run: ContinuationResult) -> float:
    """The principal parameter of the point of ``point``'s type in ``run`` nearest to it."""
    same = [p.parameters[0] for p in run.special_points if p.point_type == point.point_type]
    if not same:
        return float("nan")
    return float(min(same, key=lambda value: abs(value - point.parameters[0])))
