"""What a root locus shows beyond its roots (thesis figure 3.12): where a complex pair crosses
the imaginary axis (a Hopf point) and where two real roots coalesce into a complex pair, an
arrow per oscillatory mode in the sense of the increasing parameter, and a zoom on the
crossings in the emptiest corner of the axes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..results import LinearSweep

if TYPE_CHECKING:
    from matplotlib.axes import Axes

CROSSING_STYLE = {"marker": "s", "markersize": 8, "markerfacecolor": "none",
                  "markeredgecolor": "black", "markeredgewidth": 1.4, "linestyle": "none",
                  "zorder": 4}
"""Marker of a pair crossing the imaginary axis (the Hopf point's square of the plot key)."""
COALESCENCE_STYLE = {"marker": "D", "markersize": 7, "markerfacecolor": "white",
                     "markeredgecolor": "black", "linestyle": "none", "zorder": 4}
"""Marker of two real roots coalescing into a complex pair (or a pair splitting)."""
ZOOM_SIZE = 0.4
"""Width and height of the zoom, in fractions of the axes."""
_CLEARANCE = 0.05  # axes fractions around a corner box counted as covered
_ZOOM_WORTH = 0.2  # a zoom box wider and taller than this fraction of the axes is no zoom
_HIDDEN = 0.01  # the largest fraction of the roots an inset may cover
_ZOOM_MARGIN = 0.15  # of the zoomed span, on each side
_CORNERS = ((1.0, 1.0), (0.0, 1.0), (1.0, 0.0), (0.0, 0.0))  # upper right first


@dataclass(frozen=True)
class LocusEvents:
    """``crossings``: (parameter, Im lambda) where a complex pair's real part changes sign;
    ``coalescences``: (parameter, Re lambda) where the number of real roots changes, at the
    complex pair's side; ``columns``: the eigenvalue columns that cross."""

    crossings: tuple[tuple[float, float], ...]
    coalescences: tuple[tuple[float, float], ...]
    columns: tuple[int, ...]


def locus_events(sweep: LinearSweep) -> LocusEvents:
    """The crossings of the imaginary axis (:func:`~whirl_cli.plots.linear.zero_crossings`)
    and the coalescences on the real axis of ``sweep``, in parameter order."""
    from .linear import zero_crossings

    found = zero_crossings(sweep)
    crossings = sorted((value, frequency) for points in found.values()
                       for value, frequency in points)
    roots = np.asarray(sweep.eigenvalues)
    values = np.asarray(sweep.values, dtype=float)
    real = np.abs(roots.imag) <= 1e-9 * np.maximum(np.abs(roots), 1.0)
    count = real.sum(axis=1)
    coalescences = []
    for k in np.flatnonzero(count[1:] != count[:-1]):
        side = k if count[k] < count[k + 1] else k + 1  # the point where the pair is complex
        upper = np.where(roots[side].imag > 0, roots[side].imag, np.inf)
        pair = roots[side, int(np.argmin(upper))]
        coalescences.append((float(0.5 * (values[k] + values[k + 1])), float(pair.real)))
    return LocusEvents(tuple(crossings), tuple(coalescences), tuple(sorted(found)))


def mark_events(ax: Axes, events: LocusEvents) -> None:
    """The crossings (at Re lambda = 0) and coalescences (at Im lambda = 0) on ``ax``, each
    kind labelled once."""
    if events.crossings:
        ax.plot([0.0] * len(events.crossings), [im for _, im in events.crossings],
                **CROSSING_STYLE, label="crossing Re $\\lambda$ = 0 (Hopf)")
    if events.coalescences:
        ax.plot([re for _, re in events.coalescences], [0.0] * len(events.coalescences),
                **COALESCENCE_STYLE, label="real roots coalesce")


def direction_arrows(ax: Axes, sweep: LinearSweep, label: str = "",
                     events: LocusEvents | None = None) -> list:
    """An arrow along the upper half of each oscillatory mode, in the sense of the increasing
    parameter, on its longest complex stretch: at its middle, or the row nearest it whose
    arrow keeps :data:`_ARROW_CLEARANCE` (on the axes as sized now) from every marked
    event of ``events`` and lies within the limits (:func:`_arrow_row`); ``label`` written
    beside the last (the highest mode's, usually clear of the axes). Returns the arrows'
    annotations."""
    roots = np.asarray(sweep.eigenvalues)
    marks = _event_points(events)
    arrows = []
    for column in range(roots.shape[1]):
        run = _longest_run(roots[:, column].imag > 0)
        if run is None or run[1] - run[0] < 4:
            continue
        step = max(1, (run[1] - run[0]) // 10)
        middle = _arrow_row(ax, roots[:, column], run, step, marks)
        start, end = roots[middle, column], roots[min(middle + step, run[1] - 1), column]
        if start == end:
            continue
        arrows.append(ax.annotate(
            "", xy=(end.real, end.imag), xytext=(start.real, start.imag), zorder=5,
            arrowprops={"arrowstyle": "-|>", "color": "black", "linewidth": 1.2,
                        "mutation_scale": 14, "shrinkA": 0, "shrinkB": 0}))
    if label and arrows:
        tail, head = np.asarray(arrows[-1].xyann), np.asarray(arrows[-1].xy)
        along = ax.transData.transform(head) - ax.transData.transform(tail)
        side = np.array([-along[1], along[0]]) / max(float(np.hypot(*along)), 1e-12)
        side = side if side[1] >= 0 else -side  # above the arrow
        ax.annotate(label, xy=(tail + head) / 2, xytext=tuple(14.0 * side),
                    textcoords="offset points", ha="center", va="bottom",
                    fontsize="small", zorder=5)
    return arrows


_ARROW_CLEARANCE = 12.0  # least distance of an arrow from an event marker's centre, points


def _event_points(events: LocusEvents | None) -> np.ndarray:
    """The marked events as (Re, Im) points: crossings at (0, Im), coalescences at (Re, 0)."""
    if events is None:
        return np.empty((0, 2))
    points = [(0.0, im) for _, im in events.crossings] + [(re, 0.0)
                                                          for _, re in events.coalescences]
    return np.array(points, dtype=float).reshape(-1, 2)


def _arrow_row(ax: Axes, roots: np.ndarray, run: tuple[int, int], step: int,
               marks: np.ndarray) -> int:
    """The row of ``run`` (a stretch of one mode's ``roots``) where its arrow (to ``step``
    rows on) starts: the middle, or the row nearest it whose arrow lies within ``ax``'s
    limits and :data:`_ARROW_CLEARANCE` clear of ``marks``; the middle if none is."""
    middle = (run[0] + run[1]) // 2
    if not len(marks):
        return middle
    rows = np.arange(run[0], run[1] - 1)
    ends = np.minimum(rows + step, run[1] - 1)
    limits = ax.transLimits
    starts = limits.transform(np.column_stack([roots[rows].real, roots[rows].imag]))
    heads = limits.transform(np.column_stack([roots[ends].real, roots[ends].imag]))
    inside = ((starts >= 0) & (starts <= 1) & (heads >= 0) & (heads <= 1)).all(axis=1)
    size = np.array([ax.bbox.width, ax.bbox.height]) * 72.0 / ax.figure.dpi  # points
    gaps = _segment_gaps(starts * size, heads * size, limits.transform(marks) * size)
    clear = inside & (gaps >= _ARROW_CLEARANCE)
    if not clear.any():
        return middle
    candidates = rows[clear]
    return int(candidates[np.argmin(np.abs(candidates - middle))])


def _segment_gaps(starts: np.ndarray, heads: np.ndarray, points: np.ndarray) -> np.ndarray:
    """For each segment (``starts[k]`` to ``heads[k]``), its least distance to ``points``."""
    along = heads - starts
    length2 = np.maximum((along ** 2).sum(axis=1), 1e-300)[:, None]
    offset = points[None, :, :] - starts[:, None, :]
    t = np.clip((offset * along[:, None, :]).sum(axis=2) / length2, 0.0, 1.0)
    nearest = starts[:, None, :] + t[:, :, None] * along[:, None, :]
    return np.hypot(*(points[None, :, :] - nearest).transpose(2, 0, 1)).min(axis=1)


def _longest_run(mask: np.ndarray) -> tuple[int, int] | None:
    """(start, stop) of the longest run of True in ``mask`` (the first of equal ones)."""
    best, start = None, None
    for k, flag in enumerate([*mask, False]):
        if flag and start is None:
            start = k
        elif not flag and start is not None:
            if best is None or k - start > best[1] - best[0]:
                best = (start, k)
            start = None
    return best


def zoom_box(sweep: LinearSweep, events: LocusEvents
             ) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """(x limits, y limits) around the crossing modes' upper roots between their first and
    last event (crossings and coalescences within that stretch of the sweep), a margin on
    each side; None without a crossing."""
    if not events.crossings:
        return None
    values = np.asarray(sweep.values, dtype=float)
    found = [v for v, _ in events.crossings]
    low, high = min(found), max(found)
    pad = 0.25 * max(high - low, np.ptp(values) * 0.05)
    near = (values >= low - pad) & (values <= high + pad)
    roots = np.asarray(sweep.eigenvalues)[near][:, list(events.columns)]
    roots = roots[roots.imag > 0]
    xs = [0.0, *roots.real]
    ys = [im for _, im in events.crossings] + list(roots.imag)
    for value, re in events.coalescences:
        if low - pad <= value <= high + pad:
            xs.append(re)
            ys.append(0.0)
    limits = []
    for data in (xs, ys):
        a, b = float(np.min(data)), float(np.max(data))
        margin = _ZOOM_MARGIN * max(b - a, 1e-9)
        limits.append((a - margin, b + margin))
    (x0, x1), ys_ = limits
    half = max(abs(x0), abs(x1))  # the imaginary axis in the middle
    return (-half, half), ys_


def emptiest_corner(points: np.ndarray, size: float = ZOOM_SIZE) -> tuple[float, float]:
    """(x0, y0) in axes fractions of the corner box of ``size`` holding the fewest of
    ``points`` (N, 2, in axes fractions); the upper right wins ties, then upper left, lower
    right, lower left."""
    counts = []
    for cx, cy in _CORNERS:
        x0, y0 = cx * (1.0 - size), cy * (1.0 - size)
        counts.append((int(np.count_nonzero(_inside(points, x0, y0, size))), (x0, y0)))
    return min(counts, key=lambda c: c[0])[1]


def _inside(points: np.ndarray, x0: float, y0: float, size: float) -> np.ndarray:
    """Which of ``points`` (axes fractions) lie in the box at (x0, y0) or near it."""
    return ((points[:, 0] >= x0 - _CLEARANCE) & (points[:, 0] <= x0 + size + _CLEARANCE)
            & (points[:, 1] >= y0 - _CLEARANCE) & (points[:, 1] <= y0 + size + _CLEARANCE))


def draw_zoom(ax: Axes, sweep: LinearSweep, events: LocusEvents, draw_roots
              ) -> tuple[float, float] | None:
    """An inset of ``ax`` in its emptiest corner (:func:`emptiest_corner` of the roots as
    drawn) showing :func:`zoom_box`: the roots again (``draw_roots(inset)``), the events,
    the arrows; the zoomed region outlined on ``ax``. Returns the corner (x0, y0) in axes
    fractions; None (nothing drawn) without a crossing, where the box is not much smaller
    than the axes or where the inset would hide more than :data:`_HIDDEN` of the roots."""
    box = zoom_box(sweep, events)
    if box is None:
        return None
    ax.autoscale_view()
    roots = np.asarray(sweep.eigenvalues).reshape(-1)
    points = ax.transLimits.transform(np.column_stack([roots.real, roots.imag]))
    corners = ax.transLimits.transform(np.array(box).T)
    if np.all(np.abs(np.diff(corners, axis=0)) > _ZOOM_WORTH):
        return None
    x0, y0 = emptiest_corner(points)
    if np.count_nonzero(_inside(points, x0, y0, ZOOM_SIZE)) > _HIDDEN * len(points):
        return None
    inset = ax.inset_axes([x0, y0, ZOOM_SIZE, ZOOM_SIZE])
    draw_roots(inset)
    mark_events(inset, events)
    inset.set_xlim(*box[0])
    inset.set_ylim(*box[1])
    direction_arrows(inset, sweep, events=events)
    inset.tick_params(labelsize="x-small")
    ax.indicate_inset_zoom(inset, edgecolor="black", alpha=0.6)
    return x0, y0
