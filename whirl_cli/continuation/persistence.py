"""Persistence of special points as a smoothed law sharpens.

A smoothing (freeplay's epsilon) can create bifurcations of its own that vanish as it shrinks,
so a special point of such a model counts as physical only if it persists: it is recomputed
with every smoothing width halved and quartered, by short runs near it where they succeed
(:mod:`whirl_cli.continuation.shrinking`), else by repeating the continuation at those widths
and looking for it there (the same type, the nearest in the principal parameter).
:func:`annotate` stores the two values (``SpecialPoint.refined``, and how they were found in
``refined_by``) and flags a point that is not found again, or moves by more than ``tolerance``
of the range, as a smoothing artefact (``artefact``, and why in its ``note``). A point the
short runs located again at the study's smoothing on a finer mesh (a period doubling) is
moved there first, its note saying from where.

A global bifurcation bracketed by a snaking approach (its family's folds of cycles alternate
around it) is recomputed from those folds (:func:`snaking_recomputed`): its estimate is a
function of its family's last three folds, which the short runs recompute, so it is not left
to the repetition, whose family may take another path at a reduced width and never reach it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..analysis.global_bifurcations import snaking_estimate
from ..kinds import LocateStatus
from ..results import ContinuationResult, PointType, SpecialPoint
from .branches import joined_notes

#: The smoothing widths the continuation is repeated at, as fractions of the study's.
FACTORS = (0.5, 0.25)
#: A point persists if it moves by at most this fraction of the range at each refinement.
TOLERANCE = 2e-3
#: Types checked (global bifurcations are bracketed estimates, checked as they are).
CHECKED = frozenset({PointType.BP, PointType.LP, PointType.HB, PointType.LPC, PointType.BPC,
                     PointType.PD, PointType.TR, PointType.HOMOCLINIC, PointType.HETEROCLINIC})

#: How a snaking global point is recomputed (``SpecialPoint.refined_by``).
FOLDS = "bracketing folds"
#: A snaking global point's bracket ends are its family's last two folds if within this
#: fraction of the bracket's width of them (the bracket holds the turns of the stored rows,
#: the folds are located by AUTO).
FOLD_MATCH = 1e-2


@dataclass(frozen=True)
class Recomputed:
    """A special point's principal parameter at each reduced smoothing (in the order of the
    factors) and how it was found (``SpecialPoint.refined_by``); ``located``: the point found
    again at the study's smoothing on a finer mesh (its values then judged from there)."""

    values: np.ndarray
    method: str
    located: SpecialPoint | None = None


def refined_parameters(parameters: dict[str, float], smoothing: tuple[str, ...],
                       factor: float) -> dict[str, float]:
    """``parameters`` with every smoothing width (by name, ``smoothing``) times ``factor``."""
    return {**parameters, **{name: parameters[name] * factor for name in smoothing}}


def annotate(base: ContinuationResult, refined: list[ContinuationResult],
             width: float, tolerance: float = TOLERANCE,
             recomputed: dict | None = None) -> ContinuationResult:
    """``base`` with each special point's values at :data:`FACTORS` and its artefact flag:
    those of ``recomputed`` (index of the point -> its :class:`Recomputed`) as they are, the
    others' looked for in ``refined`` (the continuation repeated at :data:`FACTORS`; empty if
    every point was recomputed)."""
    recomputed = recomputed or {}
    points = tuple(_annotated(point, refined, width, tolerance, recomputed.get(k))
                   for k, point in enumerate(base.special_points))
    return replace(base, special_points=points)


def needs_repetition(base: ContinuationResult, recomputed: dict) -> bool:
    """True if a checked special point of ``base`` is not among ``recomputed`` (by index)."""
    return any(p.point_type in CHECKED and k not in recomputed
               for k, p in enumerate(base.special_points))


def snaking_recomputed(base: ContinuationResult, recomputed: dict) -> dict[int, Recomputed]:
    """The bracketed global points of ``base`` (by index) of a snaking approach recomputed
    from the folds that bracket them: where the last two folds of cycles before the point on
    its branch are its bracket's ends and the last three were recomputed (``recomputed``: by
    index, as :func:`annotate` takes it), the same estimate from their values at each
    factor."""
    points = base.special_points
    found = {}
    for k, point in enumerate(points):
        if not _snaking(point):
            continue
        folds = sorted((p.index, j) for j, p in enumerate(points)
                       if p.branch == point.branch and p.point_type == PointType.LPC
                       and p.index < point.index)[-3:]
        rows = [j for _, j in folds]
        if len(rows) < 3 or any(j not in recomputed for j in rows):
            continue
        ends = sorted(points[j].parameters[0] for j in rows[-2:])
        if not np.allclose(ends, point.bracket, rtol=0,
                           atol=FOLD_MATCH * np.ptp(point.bracket)):
            continue
        values = np.array([recomputed[j].values for j in rows])  # fold x factor
        found[k] = Recomputed(np.array([snaking_estimate(column)[0] for column in values.T]),
                              FOLDS)
    return found


def _snaking(point: SpecialPoint) -> bool:
    """True for a bracketed global point of a snaking approach (no fit residual)."""
    return point.point_type in (PointType.HOMOCLINIC, PointType.HETEROCLINIC) and \
        point.status == LocateStatus.BRACKETED and np.isnan(point.residual) and \
        bool(np.all(np.isfinite(point.bracket)))


def _annotated(point: SpecialPoint, refined: list[ContinuationResult], width: float,
               tolerance: float, recomputed=None) -> SpecialPoint:
    if point.point_type not in CHECKED:
        return point
    if recomputed is not None:
        values, method = np.asarray(recomputed.values, dtype=float), recomputed.method
        if recomputed.located is not None:
            point = relocated(point, recomputed.located)
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


def relocated(point: SpecialPoint, found: SpecialPoint) -> SpecialPoint:
    """``point`` at the parameters and period of ``found`` (the same point on a finer mesh),
    saying where it was."""
    if np.allclose(found.parameters, point.parameters, rtol=0, atol=0):
        return point
    note = (f"located on a finer mesh, where AUTO's Floquet multipliers are more accurate "
            f"(on the study's: {point.parameter_names[0]} = {point.parameters[0]:.6g})")
    return replace(point, parameters=found.parameters.copy(), period=found.period,
                   note=joined_notes(point.note, note))


def _nearest(point: SpecialPoint, run: ContinuationResult) -> float:
    """The principal parameter of the point of ``point``'s type in ``run`` nearest to it."""
    same = [p.parameters[0] for p in run.special_points if p.point_type == point.point_type]
    if not same:
        return float("nan")
    return float(min(same, key=lambda value: abs(value - point.parameters[0])))
