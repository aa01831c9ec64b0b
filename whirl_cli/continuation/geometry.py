"""Curve geometry of loci in two parameters (in axes scaled by the ranges): whether a locus has
closed, ended at the range's edge or used up its chunk of steps, and whether it passes a point.
"""

from __future__ import annotations

import numpy as np

from ..results import Branch, PointType
from .branches import head


def _chunk_used(curve: Branch, width: np.ndarray, bounds: dict[str, tuple[float, float]]
                ) -> bool:
    """True if a locus run stopped only because its chunk of steps was used up: it ended
    with status ok on a plain end point, not closed, not at the range edge."""
    if curve.status != "ok" or len(curve) < 2 or curve.point_type[-1] != PointType.EP:
        return False
    return len(_closed(curve, width)) == len(curve) and not _at_range_edge(curve, bounds, width)


def _at_range_edge(curve: Branch, bounds: dict[str, tuple[float, float]], width: np.ndarray
                   ) -> bool:
    """True if the locus ends on the edge of the study's range (where UZSTOP stops it)."""
    last = curve.parameters[-1, :2]
    edges = np.array([bounds[p] for p in curve.parameter_names[:2]])
    return bool(np.any(np.abs(last[:, None] - edges) < 1e-6 * width[:, None]))


def _near_polyline(point: np.ndarray, curve: np.ndarray, width: np.ndarray,
                   tolerance: float = 1e-3) -> bool:
    """True if ``point`` lies within ``tolerance`` of the polyline ``curve`` (K, >= 2), in
    axes scaled by the ranges ``width`` (Euclidean distance to the nearest segment)."""
    if len(curve) == 0:
        return False
    scaled = curve[:, :2] / width
    target = np.asarray(point[:2]) / width
    if len(scaled) == 1:
        return bool(np.linalg.norm(scaled[0] - target) < tolerance)
    start, step = scaled[:-1], np.diff(scaled, axis=0)
    length = np.einsum("ij,ij->i", step, step)
    along = np.clip(np.einsum("ij,ij->i", target - start, step) / np.where(length > 0, length, 1),
                    0.0, 1.0)
    nearest = start + along[:, None] * step
    return bool(np.linalg.norm(nearest - target, axis=1).min() < tolerance)


def _on_curve(point: np.ndarray, curve: np.ndarray, width: np.ndarray) -> bool:
    """True if ``point`` lies on the polyline ``curve`` (within 1e-3 of the ranges)."""
    return bool(len(curve)) and float(np.min(np.abs((curve - point) / width).max(axis=1))) < 1e-3


def _closed(curve: Branch, width: np.ndarray) -> Branch:
    """A locus cut where it first returns to its start (AUTO goes round a closed locus until
    its step limit)."""
    if len(curve) < 10:
        return curve
    distance = np.abs((curve.parameters - curve.parameters[0]) / width).max(axis=1)
    away = np.flatnonzero(distance > 0.02)
    if not len(away):
        return curve
    back = np.flatnonzero((distance < 0.005) & (np.arange(len(curve)) > away[0]))
    return head(curve, int(back[0]) + 1) if len(back) else curve

