"""Curve geometry of loci in two parameters (in axes scaled by the ranges): whether a locus has
closed, ended at the range's edge or used up its chunk of steps, and whether it passes a point.
"""

from __future__ import annotations

import numpy as np

from ..results import Branch, PointType, RunStatus
from .branches import head


def chunk_used(curve: Branch, width: np.ndarray, bounds: dict[str, tuple[float, float]]
                ) -> bool:
    """True if a locus run stopped only because its chunk of steps was used up: it ended
    with status ok on a plain end point, not closed, not at the range edge."""
    if curve.status != RunStatus.OK or len(curve) < 2 or curve.point_type[-1] != PointType.EP:
        return False
    return len(cut_closed(curve, width)) == len(curve) and not at_range_edge(curve, bounds, width)


def at_range_edge(curve: Branch, bounds: dict[str, tuple[float, float]], width: np.ndarray
                   ) -> bool:
    """True if the locus ends on the edge of the study's range (where UZSTOP stops it) or
    beyond it (AUTO locates no event in the first step after a restart, so a locus continued
    from a point just inside the edge can pass it)."""
    last = curve.parameters[-1, :2]
    edges = np.array([bounds[p] for p in curve.parameter_names[:2]])
    return bool(np.any((last < edges[:, 0] + 1e-6 * width) | (last > edges[:, 1] - 1e-6 * width)))


def near_polyline(point: np.ndarray, curve: np.ndarray, width: np.ndarray,
                   tolerance: float = 1e-3) -> bool:
    """True if ``point`` lies within ``tolerance`` of the polyline ``curve`` (K, >= 2), in
    axes scaled by the ranges ``width`` (Euclidean distance to the nearest segment)."""
    target = np.asarray(point[:2], dtype=float)[None] / width
    return bool(on_paths(target, [curve[:, :2] / width], tolerance)[0])


def locus_coordinates(curve: Branch, width: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """(K, 3 + 2n) a locus's points in the coordinates loci are compared in: the two
    parameters scaled by the ranges ``width``, the orbit extremes (state_max, state_min) by
    20 ``scale`` (their spread over the loci compared), so that 1e-3 there is 2 % of the
    spread, and the logarithm of the period by 10 (1e-3 there: 1 %; 0 on loci of equilibria
    without one). The parameter projections of two different loci may touch; their orbits
    differ (near a homoclinic orbit, mostly in period)."""
    extremes = np.hstack([curve.state_max, curve.state_min])
    period = np.asarray(curve.period, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        logarithm = np.where(np.isfinite(period) & (period > 0), np.log(period) / 10, 0.0)
    return np.hstack([curve.parameters[:, :2] / width, extremes / (20 * scale),
                      logarithm[:, None]])


def extreme_scale(curves: list[Branch]) -> np.ndarray:
    """(2n,) the spread of every orbit extreme over ``curves`` (1 where it does not vary: the
    loci of equilibria)."""
    return _spread(np.vstack([np.hstack([c.state_max, c.state_min]) for c in curves]))


def on_paths(points: np.ndarray, paths: list[np.ndarray], tolerance: float = 1e-3
              ) -> np.ndarray:
    """(K,) True where a row of ``points`` (K, D) lies within ``tolerance`` (Euclidean) of a
    segment of one of the polylines ``paths`` (each (M, D), in the same coordinates).

    Only the pairs that can be that near are measured: points not yet found near a path,
    inside its bounding box widened by twice the tolerance, against its segments whose boxes
    meet theirs so widened (a point that near a segment is within the tolerance of it in every
    coordinate)."""
    near = np.zeros(len(points), dtype=bool)
    margin = 2 * tolerance
    for path in paths:
        if len(path) == 0:
            continue
        inside = np.all((points >= path.min(axis=0) - margin)
                        & (points <= path.max(axis=0) + margin), axis=1)
        rows = np.flatnonzero(inside & ~near)
        if not len(rows):
            continue
        candidates = points[rows]
        if len(path) == 1:
            near[rows] |= np.linalg.norm(candidates - path[0], axis=1) < tolerance
            continue
        first, last = path[:-1], path[1:]
        meets = np.all((np.maximum(first, last) >= candidates.min(axis=0) - margin)
                       & (np.minimum(first, last) <= candidates.max(axis=0) + margin), axis=1)
        if not meets.any():
            continue
        start, step = first[meets], (last - first)[meets]
        length = np.einsum("md,md->m", step, step)
        offset = candidates[:, None, :] - start[None]
        along = np.clip(np.einsum("kmd,md->km", offset, step)
                        / np.where(length > 0, length, 1.0), 0.0, 1.0)
        gap = offset - along[..., None] * step[None]
        near[rows] |= np.einsum("kmd,kmd->km", gap, gap).min(axis=1) < tolerance ** 2
    return near


def has_merged(points: np.ndarray, others: list[np.ndarray], follow: int = 5) -> bool:
    """True if a locus (``points`` in :func:`locus_coordinates`) has run onto one of the
    ``others``: its last ``follow`` points lie on them, after it had left its start by more
    than 0.02 of the ranges (near its start a locus lies on its twin traced the other way).
    Continued, it would retrace them."""
    if len(points) < follow + 1:
        return False
    left = np.abs(points[:, :2] - points[0, :2]).max(axis=1) > 0.02
    return bool(left.any() and on_paths(points[-follow:], others).all())


def cut_closed(curve: Branch, width: np.ndarray, follow: int = 5) -> Branch:
    """A locus cut where it first comes back to its start, or back onto its own earlier path
    and follows it the same way for ``follow`` more points: AUTO goes round a closed locus
    until its step limit, also one it has run onto from elsewhere. Coming back means within
    0.005 of the ranges of a point it had since left by more than 0.02: for the start in the
    two parameters (a locus of the folds of cycles of a family snaking toward a homoclinic
    orbit goes from one of them to the next, at nearly the same parameters but another
    period: it is cut there too, the next one's own locus going on; :func:`whirl_cli.
    continuation.loci._locus_end` tells the two ends apart), elsewhere also in the orbit's
    extremes (scaled by their spread along the locus; the parameter projection of a locus
    may pass over itself) or, on a locus of cycles, in its period instead (scaled likewise)
    for a whole lap (the points since the earlier one, repeated): the extremes are maxima over
    AUTO's mesh, and round a closed locus the mesh points fall elsewhere on the orbit from lap
    to lap, so the extremes of a fast state (the gimballed hub's rates) differ by a few per
    cent at the same point of the locus, which then goes round until its step limit."""
    if len(curve) < 10:
        return curve
    scaled = curve.parameters[:, :2] / width
    extremes = np.hstack([curve.state_max, curve.state_min])
    # (coordinates, True if a whole lap must repeat): the extremes, and on a locus of cycles
    # the period, which must then retrace the whole stretch since the earlier point
    paths = [(np.hstack([scaled, extremes / _spread(extremes)]), False)]
    period = np.asarray(curve.period, dtype=float)[:, None]
    if np.isfinite(period).all():
        paths.append((np.hstack([scaled, period / _spread(period)]), True))
    from_start = np.abs(scaled - scaled[0]).max(axis=1)
    away = np.maximum.accumulate(from_start) > 0.02
    # how far the curve got from each point since it, in each path's coordinates
    farthest = [np.zeros(len(curve)) for _ in paths]
    for j in range(1, len(curve)):
        if away[j] and from_start[j] < 0.005:
            return head(curve, j + 1)
        for (full, lap), far in zip(paths, farthest, strict=True):
            distance = np.abs(full[:j] - full[j]).max(axis=1)
            far[:j] = np.maximum(far[:j], distance)
            for i in np.flatnonzero((distance < 0.005) & (far[:j] > 0.02)):
                if i > 0 and _follows(full, int(i), j, max(follow, j - i - 1) if lap else follow):
                    return head(curve, j + 1)
    return curve


def _spread(values: np.ndarray) -> np.ndarray:
    """The spread of each column of ``values`` (1 where it does not vary)."""
    spread = np.ptp(values, axis=0)
    return np.where(spread > 0, spread, 1.0)


def _follows(points: np.ndarray, i: int, j: int, follow: int) -> bool:
    """True if ``points`` (scaled coordinates of a curve) j+1 .. j+follow each stay within
    0.005 of the path near point i and move along it the same way (their nearest earlier
    points go forward from i)."""
    after = points[j + 1:j + 1 + follow]
    lower, upper = max(i - follow, 0), min(i + 4 * follow, j)
    if len(after) < follow or upper <= lower:
        return False
    distance = np.abs(after[:, None] - points[None, lower:upper]).max(axis=2)
    nearest = distance.argmin(axis=1)
    return bool(np.all(distance.min(axis=1) < 0.005) and np.all(np.diff(nearest) >= 0)
                and nearest[-1] > nearest[0])
