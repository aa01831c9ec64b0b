"""Special-point markers of the one-parameter plots: the folds of a snaking family drawn as
one cluster, markers at one place set apart so that none hides another, the crowd of
markers a diagram zooms on, and a band's label placed clear of the markers."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import TYPE_CHECKING

import numpy as np

from ..results import PointType
from .key import BLACK, MARKER_STYLE, PLOT_KEY, plot_styled

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.lines import Line2D

#: Fewest folds of one family, one after another along it, that make a snaking cluster.
SNAKE_FOLDS = 3
#: The folds of a cluster lie within this fraction of the plot's parameter span of its first.
SNAKE_WIDTH = 0.01
#: The key of :data:`~whirl_cli.plots.key.PLOT_KEY` a cluster's legend entry is filed under.
CLUSTER = "fold_cluster"
#: A cluster with another this fraction of the span to its right has its count on its left.
_LABEL_NEAR = 0.05


@dataclass(frozen=True)
class Mark:
    """A special point's marker: where it goes, and the family and row it belongs to."""

    x: float
    y: float
    family: str
    row: int


def fold_clusters(folds: list[Mark], span: float) -> tuple[list[Mark], list[list[Mark]]]:
    """(folds drawn one by one, clusters): runs of at least :data:`SNAKE_FOLDS` folds of one
    family, in row order, each within :data:`SNAKE_WIDTH` of ``span`` of the run's first
    (a family snaking towards a global bifurcation)."""
    singles: list[Mark] = []
    clusters: list[list[Mark]] = []
    families: dict[str, list[Mark]] = {}
    for mark in folds:
        families.setdefault(mark.family, []).append(mark)
    for marks in families.values():
        run: list[Mark] = []
        for mark in sorted(marks, key=lambda m: m.row):
            if run and abs(mark.x - run[0].x) > SNAKE_WIDTH * span:
                _close(run, singles, clusters)
                run = []
            run.append(mark)
        _close(run, singles, clusters)
    return singles, clusters


def _close(run: list[Mark], singles: list[Mark], clusters: list[list[Mark]]) -> None:
    """File a finished run as a cluster, or its folds as single ones."""
    if len(run) >= SNAKE_FOLDS:
        clusters.append(run)
    else:
        singles.extend(run)


def draw_marks(ax: Axes, marks: dict[str, list[Mark]], first: dict, span: float
               ) -> dict[str, list[Line2D]]:
    """Each style's marks as one artist (:func:`~whirl_cli.plots.key.plot_styled`), the folds
    of a snaking family as one cluster each (:func:`draw_cluster`); the marker lines drawn,
    by style (the clusters' under :data:`CLUSTER`)."""
    drawn: dict[str, list[Line2D]] = {}
    for style in PLOT_KEY:
        chosen = marks.get(style, [])
        if style == MARKER_STYLE[PointType.LPC] and chosen:
            chosen, clusters = fold_clusters(chosen, span)
            unique = {_cluster_key(c): c for c in reversed(clusters)}  # a mirror family's
            clusters = [c for c in clusters if unique.get(_cluster_key(c)) is c]  # once
            for cluster in clusters:
                left = any(0 < other[0].x - cluster[0].x <= _LABEL_NEAR * span
                           for other in clusters)
                drawn.setdefault(CLUSTER, []).append(draw_cluster(ax, cluster, first, left))
        if chosen:
            lines_before = len(ax.lines)
            plot_styled(ax, np.array([m.x for m in chosen]), np.array([m.y for m in chosen]),
                        style, first)
            drawn[style] = [ax.lines[lines_before]]
    return drawn


def _cluster_key(cluster: list[Mark]) -> tuple:
    ys = [m.y for m in cluster]
    return len(cluster), f"{cluster[0].x:.9g}", f"{min(ys):.9g}", f"{max(ys):.9g}"


#: The gap [points] between a cluster's outermost fold and its bar beside the curve.
BAR_GAP = 6.0


def draw_cluster(ax: Axes, cluster: list[Mark], first: dict, left: bool = False) -> Line2D:
    """One fold marker at the cluster's first fold, a capped bar over the values of all its
    folds beside the family's curve (:data:`BAR_GAP` points right of its rightmost fold, or
    left of its leftmost if ``left``: the curve snakes between its folds, so it stays in
    view), and their count beyond the bar; the marker's line."""
    from matplotlib.transforms import ScaledTranslation

    anchor = cluster[0]
    xs = np.array([m.x for m in cluster])
    ys = np.array([m.y for m in cluster])
    low, high = float(ys.min()), float(ys.max())
    side = -1.0 if left else 1.0
    edge = float(xs.min() if left else xs.max())
    style = PLOT_KEY["fold"]
    (marker,) = ax.plot([anchor.x], [anchor.y], marker="o", markersize=8.0, linestyle="none",
                        markerfacecolor=style["markerfacecolor"],
                        markeredgecolor=style["markeredgecolor"], zorder=3,
                        label="_fold cluster")
    beside = ax.transData + ScaledTranslation(side * BAR_GAP / 72.0, 0.0,
                                              ax.figure.dpi_scale_trans)
    ax.plot([edge, edge], [low, high], color=BLACK, linewidth=1.2, marker="_",
            markersize=8.0, markeredgewidth=1.2, zorder=3, transform=beside,
            label="_fold cluster span")
    ax.annotate(f"\u00d7{len(cluster)}", xy=(edge, (low + high) / 2),
                xytext=(side * (BAR_GAP + 4.0), 0), textcoords="offset points",
                ha="right" if left else "left", va="center", fontsize="x-small", zorder=6,
                bbox={"boxstyle": "round,pad=0.1", "facecolor": "white", "edgecolor": "none",
                      "alpha": 0.8})  # legible over a marker beside it
    first.setdefault(CLUSTER, _cluster_handle())
    return marker


def _cluster_handle():
    """The legend's picture of a cluster: a fold's dot with a capped bar beside it."""
    from matplotlib.lines import Line2D
    from matplotlib.path import Path

    circle = Path.circle((-0.45, 0.0), 0.42)
    bar = Path([(0.45, -1.0), (0.45, 1.0), (0.2, 1.0), (0.7, 1.0), (0.2, -1.0),
                (0.7, -1.0)], [Path.MOVETO, Path.LINETO] * 3)
    return Line2D([], [], marker=Path.make_compound_path(circle, bar), markersize=13,
                  markerfacecolor=BLACK, markeredgecolor=BLACK, markeredgewidth=1.2,
                  linestyle="none")


def unstack(ax: Axes, lines: list[Line2D]) -> None:
    """Set apart markers at one place: from the top down (by zorder, then drawing order),
    each marker whose centre lies within the half size of a marker drawn above it (a larger
    hollow ring around it excepted, and a marker of the same look) is drawn beside it
    instead, shifted sideways (right, else left) until its centre is a quarter of its size
    clear of the other's half size, in a copy of its line; one step at most, so that a crowd
    of markers does not spread far from its place. Positions are those of the axes as they
    are now (their limits autoscaled)."""
    ax.autoscale_view()
    order = sorted(lines, key=lambda line: line.get_zorder())
    per_point = ax.figure.dpi / 72.0
    placed: list[tuple[Line2D, np.ndarray]] = []  # lines above, with their final centres
    for line in reversed(order):
        centres = line.get_transform().transform(line.get_xydata())
        shifts = np.array([_shift(centre, line, placed, per_point) for centre in centres])
        placed.append((line, centres + np.column_stack([shifts, 0 * shifts]) * per_point))
        _split_by_shift(ax, line, shifts)


def _shift(centre: np.ndarray, line: Line2D, placed: list, per_point: float) -> float:
    """The sideways shift [points] that puts a marker of ``line`` at ``centre`` clear of
    every marker ``placed`` above it (0 if none covers it, or neither side is clear)."""
    above = [(other, xy) for other, xy in placed if not _both_seen(line, other)]
    if not above:
        return 0.0
    step = 0.25 * line.get_markersize() + 0.5 * max(o.get_markersize() for o, _ in above)
    for k in (0, 1, -1):
        at = centre + np.array([k * step * per_point, 0.0])
        if not any(_covers(other, xy, at, per_point) for other, xy in above):
            return k * step
    return 0.0


def _both_seen(below: Line2D, above: Line2D) -> bool:
    """Whether a marker of ``above`` leaves one of ``below`` at its place in view: the same
    mark, or a larger hollow ring around it."""
    same = (below.get_marker() == above.get_marker()
            and below.get_markerfacecolor() == above.get_markerfacecolor()
            and below.get_markersize() == above.get_markersize())
    ring = (above.get_markerfacecolor() == "none"
            and above.get_markersize() > below.get_markersize())
    return same or ring


def _covers(other: Line2D, centres: np.ndarray, at: np.ndarray, per_point: float) -> bool:
    """Whether a marker of ``other`` at one of ``centres`` [pixels] covers the point ``at``."""
    if not len(centres):
        return False
    reach = 0.5 * other.get_markersize() * per_point
    return bool((np.linalg.norm(centres - at, axis=1) < reach).any())


def _split_by_shift(ax: Axes, line: Line2D, shifts: np.ndarray) -> None:
    """Keep ``line``'s unshifted points in it and draw each group of shifted ones in a copy
    shifted by that many points (the line itself takes a group if none is unshifted)."""
    from matplotlib.lines import Line2D as Line
    from matplotlib.transforms import ScaledTranslation

    if not shifts.any():
        return
    xy = line.get_xydata()
    groups = sorted(set(shifts.tolist()), key=lambda s: (s != 0.0, abs(s), s))
    for n, shift in enumerate(groups):
        chosen = xy[shifts == shift]
        target = line
        if n:
            target = Line(chosen[:, 0], chosen[:, 1])
            target.update_from(line)
            target.set(label="_shifted", zorder=line.get_zorder(), transform=ax.transData)
            ax.add_line(target)
        target.set_data(chosen[:, 0], chosen[:, 1])
        if shift:
            target.set_transform(ax.transData + ScaledTranslation(
                shift / 72.0, 0.0, ax.figure.dpi_scale_trans))


#: The gap [points] between a band's label and the edge of the axes or of the band beside it.
_LABEL_GAP = 3.0


def band_label(ax: Axes, text: str, low: float, high: float, **style):
    """A label of the band ``low``-``high`` (the x data) inside ``ax``, placed when drawn
    (:func:`_place`): at the top in the band's middle, or, if its box would overlap a
    marker, another text or the legend of ``ax`` there (or a curve, if a place off the
    curves is clear), at the first clear place of: the top beside the band (right, left),
    the bottom (middle, right, left), rows between from the top down; the first if none
    is. Returns the annotation."""
    label = _band_label_class()(text, xy=((low + high) / 2, 1.0),
                                xycoords=("data", "axes fraction"), xytext=(0, -_LABEL_GAP),
                                textcoords="offset points", ha="center", va="top",
                                annotation_clip=True, **style)
    label.band = (low, high)
    ax._add_text(label)  # as Axes.annotate adds its annotations
    return label


@cache
def _band_label_class():
    """The class of :func:`band_label`'s annotations (made once, matplotlib imported then)."""
    from matplotlib.text import Annotation

    class BandLabel(Annotation):
        """An annotation that takes the first clear place of its band when drawn."""

        band = (0.0, 0.0)

        def draw(self, renderer) -> None:
            if self.get_visible() and self.axes is not None:
                _place(self, renderer)
            super().draw(renderer)

    return BandLabel


def _place(label, renderer) -> None:
    """Move ``label`` to the first of its places (:func:`band_label`) inside its axes and
    clear of their markers, texts and legend: of those, the first off every curve's
    vertices too, if one is. Its box is measured from its glyphs' outlines (:func:`_box`),
    so every renderer (PNG, PDF, SVG) puts it at the same place."""
    ax = label.axes
    inside = ax.get_window_extent(renderer)
    obstacles = _obstacles(ax, label, renderer)
    curves = _curve_points(ax)
    places = _places(label, inside)
    for strict in (True, False):
        for place in places:
            box = _box(label, place)
            within = (inside.x0 <= box.x0 and box.x1 <= inside.x1 and inside.y0 <= box.y0
                      and box.y1 <= inside.y1)
            if not within or any(box.overlaps(other) for other in obstacles):
                continue
            if not strict or not box.count_contains(curves):
                _put(label, place)
                return
    _put(label, places[0])


def _curve_points(ax: Axes) -> np.ndarray:
    """The vertices of ``ax``'s drawn lines without markers (curves), in display coordinates."""
    points = [line.get_transform().transform(line.get_xydata()) for line in ax.lines
              if line.get_visible() and not _has_marker(line) and len(line.get_xdata())]
    xy = np.concatenate(points) if points else np.zeros((0, 2))
    return xy[np.isfinite(xy).all(axis=1)]


def _has_marker(line) -> bool:
    """True if the matplotlib ``line`` draws a marker at its points."""
    return line.get_marker() not in ("None", "none", "", " ", None)


def _put(label, place: tuple) -> None:
    (x, y), offset, ha, va = place
    label.xy = (x, y)
    label.xyann = offset
    label.set_horizontalalignment(ha)
    label.set_verticalalignment(va)


def _size(label) -> tuple[float, float]:
    """(width, height) [points] of ``label``'s one line of text, from its glyphs' outlines
    (the height a line of its font takes, "lp")."""
    from matplotlib.textpath import TextToPath

    measure = TextToPath().get_text_width_height_descent
    font = label.get_fontproperties()
    width = measure(label.get_text(), font, ismath=False)[0]
    _, height, descent = measure("lp", font, ismath=False)
    return width, height + descent


def _box(label, place: tuple):
    """The display box ``label`` takes at ``place``, :data:`_LABEL_PAD` around its text."""
    from matplotlib.transforms import Bbox, blended_transform_factory

    (x, y), (dx, dy), ha, va = place
    per_point = label.figure.dpi / 72.0
    anchor = blended_transform_factory(label.axes.transData, label.axes.transAxes).transform(
        (x, y)) + np.array([dx, dy]) * per_point
    width, height = (np.array(_size(label)) + 2 * _LABEL_PAD) * per_point
    x0 = anchor[0] - {"left": 0.0, "center": 0.5, "right": 1.0}[ha] * width + \
        {"left": -1.0, "center": 0.0, "right": 1.0}[ha] * _LABEL_PAD * per_point
    y0 = anchor[1] - {"bottom": 0.0, "top": 1.0}[va] * height + \
        {"bottom": -1.0, "top": 1.0}[va] * _LABEL_PAD * per_point
    return Bbox.from_bounds(x0, y0, width, height)


#: The margin [points] kept around a band label's text.
_LABEL_PAD = 1.0


def _places(label, inside) -> list[tuple]:
    """(xy, offset [points], ha, va) of ``label``'s places in order: rows top, bottom, then
    between from the top down; in each the band's middle, right of it, left of it."""
    low, high = label.band
    height = _size(label)[1]
    rows = [(1.0, -_LABEL_GAP, "top"), (0.0, _LABEL_GAP, "bottom")]
    step = 1
    span = inside.height * 72.0 / label.figure.dpi
    while _LABEL_GAP + (step + 1) * height < span - _LABEL_GAP:
        rows.append((1.0, -_LABEL_GAP - step * height, "top"))
        step += 1
    return [((x, y), (dx, dy), ha, va) for y, dy, va in rows
            for x, dx, ha in (((low + high) / 2, 0.0, "center"), (high, _LABEL_GAP, "left"),
                              (low, -_LABEL_GAP, "right"))]


def _obstacles(ax: Axes, label, renderer) -> list:
    """The boxes (display) ``label`` must keep clear of: each marker of ``ax``'s lines (its
    size around its centre), its other visible texts, its legend."""
    from matplotlib.transforms import Bbox

    per_point = ax.figure.dpi / 72.0
    boxes = []
    for line in ax.lines:
        if not line.get_visible() or not _has_marker(line):
            continue
        half = 0.5 * (line.get_markersize() + line.get_markeredgewidth()) * per_point
        for x, y in line.get_transform().transform(line.get_xydata()):
            if np.isfinite(x) and np.isfinite(y):
                boxes.append(Bbox([[x - half, y - half], [x + half, y + half]]))
    boxes += [text.get_window_extent(renderer) for text in ax.texts
              if text is not label and text.get_visible() and text.get_text().strip()]
    if ax.get_legend() is not None:
        boxes.append(ax.get_legend().get_window_extent(renderer))
    return boxes


#: Fewest markers, each within a marker's size of another of them, that crowd a diagram.
CROWD = 5


def crowd(centres: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """Indices of the largest group of markers (``centres`` (N, 2) in display units, each
    reaching ``reach`` (N,) from its centre) linked by overlaps: two markers link if their
    centres are closer than the sum of their reaches. Empty if no group has :data:`CROWD`."""
    n = len(centres)
    if n < CROWD:
        return np.zeros(0, dtype=int)
    from scipy.sparse.csgraph import connected_components

    gaps = np.linalg.norm(centres[:, None, :] - centres[None, :, :], axis=2)
    _, group = connected_components(gaps < reach[:, None] + reach[None, :], directed=False)
    counts = np.bincount(group)
    if counts.max() < CROWD:
        return np.zeros(0, dtype=int)
    return np.flatnonzero(group == np.argmax(counts))


def crowded_box(ax: Axes) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """(x limits, y limits) in data of the largest crowd (:func:`crowd`) of ``ax``'s
    special-point markers as the axes are laid out now (their limits autoscaled), with a
    margin of half its span (at least 3 % of the axes' limits) on each side; None if the
    markers crowd nowhere."""
    ax.autoscale_view()
    per_point = ax.figure.dpi / 72.0
    data, centres, reach = [], [], []
    for line in ax.lines:
        if line.get_linestyle() not in ("None", "none", "") or not _has_marker(line) or \
                not line.get_visible():
            continue
        xy = line.get_xydata()
        xy = xy[np.isfinite(xy).all(axis=1)]
        data.append(xy)
        centres.append(line.get_transform().transform(xy))
        reach.append(np.full(len(xy), 0.5 * line.get_markersize() * per_point))
    if not data:
        return None
    chosen = crowd(np.concatenate(centres), np.concatenate(reach))
    if not len(chosen):
        return None
    points = np.concatenate(data)[chosen]
    limits = []
    for axis, view in ((0, ax.get_xlim()), (1, ax.get_ylim())):
        low, high = float(points[:, axis].min()), float(points[:, axis].max())
        margin = max(0.5 * (high - low), 0.03 * abs(view[1] - view[0]))
        limits.append((low - margin, high + margin))
    return limits[0], limits[1]
