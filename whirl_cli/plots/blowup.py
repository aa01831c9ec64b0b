"""The period of a periodic family approaching its global (homoclinic or heteroclinic)
bifurcation, and where a fitted 1/x curve puts that bifurcation: the curve
T = c + a / (p - p*) fitted to the family's approach, its asymptote p = p* (thesis figs.
3.25, 3.27).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import WhirlError
from ..results import Branch, ContinuationResult, PointType
from .key import (
    MARKER_STYLE,
    PLOT_KEY,
    axis_label,
    branch_style,
    log_scale_if_decades,
    new_figure,
    plot_styled,
    stability_curves,
    symbol,
)
from .markers import Mark, draw_marks, unstack

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

_GLOBAL = (PointType.HOMOCLINIC, PointType.HETEROCLINIC)
_FAMILY_POINTS = (PointType.HB, PointType.LPC, PointType.BPC, PointType.PD, PointType.TR)
_MIN_ROWS = 5  # fewest rows a fit is made from
_ZOOM_WORTH = 0.2  # an approach narrower than this fraction of the x-axis gets a zoom
_GRID = 600  # trial asymptotes, spaced logarithmically in their distance from the approach

#: Styles of the fitted curve and of its asymptote.
FIT_STYLE = {"color": "black", "linestyle": "-.", "linewidth": 1.2}
ASYMPTOTE_STYLE = {"color": "dimgrey", "linestyle": "--", "linewidth": 1.0}


@dataclass(frozen=True)
class BlowupFit:
    """T = ``offset`` + ``scale`` / (p - ``asymptote``), fitted to the rows ``rows`` of a
    family (``start`` to ``stop``, in branch order)."""

    asymptote: float
    scale: float
    offset: float
    start: int
    stop: int

    def period(self, parameter: np.ndarray) -> np.ndarray:
        """The fitted period at ``parameter``."""
        return self.offset + self.scale / (np.asarray(parameter, dtype=float) - self.asymptote)


def growth_run(parameter: np.ndarray, period: np.ndarray) -> tuple[int, int]:
    """(first, last) row of the run of rows between turns of the parameter (folds), of at
    least :data:`_MIN_ROWS` rows, over which the period grows by the largest factor.
    ValueError if there is none."""
    parameter = np.asarray(parameter, dtype=float)
    period = np.asarray(period, dtype=float)
    step = np.sign(np.diff(parameter))
    moving = np.flatnonzero(step)  # a repeated parameter value is no turn
    turns = [0, *(moving[1:][step[moving[1:]] != step[moving[:-1]]]), len(parameter) - 1]
    best, found = 1.0, None
    for first, last in zip(turns[:-1], turns[1:], strict=True):
        if last - first + 1 < _MIN_ROWS:
            continue
        growth = period[last] / period[first]
        if np.isfinite(growth) and growth > best:
            best, found = growth, (first, last)
    if found is None:
        raise ValueError("no run of the family over which the period grows")
    return found


def approach(parameter: np.ndarray, period: np.ndarray) -> tuple[int, int]:
    """(first, last) row of the approach: the :func:`growth_run` from its row where the
    period has made half its growth (the last :data:`_MIN_ROWS` rows at least), the curve
    of 1/x form near its asymptote rather than the fold it leaves. ValueError if there is
    none."""
    first, last = growth_run(parameter, period)
    period = np.asarray(period, dtype=float)
    half = (period[first] + period[last]) / 2.0
    upper = first + int(np.argmax(period[first:last + 1] >= half))
    return min(upper, last - _MIN_ROWS + 1), last


def fit_blowup(parameter: np.ndarray, period: np.ndarray) -> BlowupFit:
    """The 1/x curve through the family's :func:`approach`, least squares in the period: for
    each trial asymptote beyond the approach's end (at 1e-6 to 100 times the approach's
    span from it) the best scale and offset; the asymptote of least residual, refined
    between its grid neighbours. ValueError if the family has no approach."""
    from scipy.optimize import minimize_scalar

    first, last = approach(parameter, period)
    p = np.asarray(parameter, dtype=float)[first:last + 1]
    t = np.asarray(period, dtype=float)[first:last + 1]
    direction = np.sign(p[-1] - p[0])
    span = abs(p[-1] - p[0])

    def residual(log_distance: float) -> float:
        return _solve(p, t, p[-1] + direction * 10.0 ** log_distance)[2]

    grid = np.linspace(np.log10(span) - 6.0, np.log10(span) + 2.0, _GRID)
    k = int(np.argmin([residual(g) for g in grid]))
    low, high = grid[max(k - 1, 0)], grid[min(k + 1, _GRID - 1)]
    best = minimize_scalar(residual, bounds=(low, high), method="bounded",
                           options={"xatol": 1e-9}).x
    asymptote = p[-1] + direction * 10.0 ** best
    scale, offset, _ = _solve(p, t, asymptote)
    return BlowupFit(float(asymptote), scale, offset, first, last)


def _solve(p: np.ndarray, t: np.ndarray, asymptote: float) -> tuple[float, float, float]:
    """(scale, offset, residual sum of squares) of the least-squares 1/x curve with the
    given asymptote."""
    matrix = np.column_stack([1.0 / (p - asymptote), np.ones_like(p)])
    (scale, offset), *_ = np.linalg.lstsq(matrix, t, rcond=None)
    return float(scale), float(offset), float(np.sum((matrix @ (scale, offset) - t) ** 2))


def blowup_family(continuation: ContinuationResult, name: str | None = None
                  ) -> tuple[Branch, object | None]:
    """The periodic branch named ``name`` (None: the first one whirl found a global
    bifurcation on) and its global point (None if it has none). WhirlError if there is
    none."""
    points = {p.branch: p for p in continuation.special_points
              if int(p.point_type) in {int(t) for t in _GLOBAL}}
    periodic = [b for b in continuation.branches if b.is_periodic]
    if name is not None:
        found = [b for b in periodic if b.name == name]
        if not found:
            raise WhirlError(f"no periodic branch {name!r} in {continuation.name!r} "
                             f"(periodic: {', '.join(b.name for b in periodic) or 'none'})")
    else:
        found = [b for b in periodic if b.name in points]
        if not found:
            raise WhirlError(f"{continuation.name!r}: no periodic family ending in a global "
                             "bifurcation")
    return found[0], points.get(found[0].name)


def blowup_plot(continuation: ContinuationResult, branch: str | None = None,
                ax: Axes | None = None, title: str | None = None) -> Figure:
    """Period [s] of one periodic family (``branch``; None: the first ending in a global
    bifurcation) against its principal parameter near that bifurcation: the family in the
    styles of :data:`PLOT_KEY` with its Hopf, fold (LPC), branch and torus points, the
    global point whirl located (at the family's last period), the 1/x curve of
    :func:`fit_blowup` (dash-dot) and its asymptote (dashed, its value in the legend). The
    x-axis spans the approach and the asymptote; an inset zooms on the rows the fit was made
    from and the asymptote (:func:`approach_box`). Draws on ``ax`` if given, else on a new
    figure; returns the figure. Title: ``title`` (None: the family's name)."""
    family, global_point = blowup_family(continuation, branch)
    if ax is None:
        ax = new_figure().add_subplot()
    x, period = family.parameters[:, 0], family.period
    try:
        fit = fit_blowup(x, period)
    except ValueError:
        fit = None
    xlim = None
    if fit is not None:
        run = x[growth_run(x, period)[0]]
        margin = 0.06 * abs(run - fit.asymptote)
        xlim = sorted((run + np.sign(run - fit.asymptote) * margin,
                       fit.asymptote - np.sign(run - fit.asymptote) * margin))
    first: dict[str, object] = {}
    shown_span = float(np.ptp(x)) if xlim is None else xlim[1] - xlim[0]
    markers = _draw_family(ax, continuation, family, global_point, first, shown_span)
    name, unit = family.parameter_names[0], family.parameter_units[0]
    handles = [first[key] for key in PLOT_KEY if key in first]
    labels = [str(PLOT_KEY[key]["label"]) for key in PLOT_KEY if key in first]
    if global_point is not None:  # whirl's own estimate beside the fitted one
        style = MARKER_STYLE[PointType(int(global_point.point_type))]
        if style in first:
            labels[[k for k in PLOT_KEY if k in first].index(style)] = (
                f"{PLOT_KEY[style]['label']} (whirl: {symbol(name)} = "
                f"{float(global_point.parameters[0]):.5g})")
    if fit is not None:
        top = 1.15 * float(np.nanmax(period))
        line, asymptote = _draw_fit(ax, fit, x[fit.start], top)
        handles += [line, asymptote]
        labels += ["fitted 1/x curve",
                   f"fitted asymptote {symbol(name)} = {fit.asymptote:.5g}"
                   + (f" {unit}" if unit else "")]
        ax.set_xlim(*xlim)
        shown = (x >= min(ax.get_xlim())) & (x <= max(ax.get_xlim()))
        ax.set_ylim(0.95 * float(np.nanmin(period[shown])), top)
        _zoom_approach(ax, continuation, family, global_point, fit, top)
    log_scale_if_decades(ax, "y", ax.get_ylim() if fit is not None else period)
    unstack(ax, markers)
    ax.set_xlabel(axis_label(name, unit))
    ax.set_ylabel(axis_label("period", "s"))
    ax.legend(handles, labels, fontsize="small")
    ax.set_title(family.name if title is None else title)
    return ax.figure


def _draw_family(ax: Axes, continuation: ContinuationResult, family: Branch, global_point,
                 first: dict, span: float) -> list:
    """The family's period by stability and its points (:func:`_family_points`, on an axis
    spanning ``span`` of the parameter); the marker lines."""
    for xs, ys, stable in stability_curves(family.parameters[:, 0], family.period,
                                           family.stable, family.stability_known):
        plot_styled(ax, xs, ys, branch_style(family.kind, stable), first)
    return _family_points(ax, continuation, family, global_point, first, span)


def _draw_fit(ax: Axes, fit: BlowupFit, start: float, top: float) -> tuple:
    """The fitted curve from ``start`` up to the period ``top``, and its asymptote."""
    near = fit.asymptote + fit.scale / (top - fit.offset) if fit.scale else fit.asymptote
    curve_x = np.linspace(start, near, 400)
    (line,) = ax.plot(curve_x, fit.period(curve_x), label="_fit", **FIT_STYLE)
    return line, ax.axvline(fit.asymptote, label="_asymptote", **ASYMPTOTE_STYLE)


def approach_box(parameter: np.ndarray, period: np.ndarray, fit: BlowupFit, global_at=None
                 ) -> tuple[tuple[float, float], tuple[float, float]]:
    """(x limits, y limits) of the approach the fit was made from, its asymptote and the
    global point's parameter ``global_at`` (if given), with margins."""
    ends = [float(parameter[fit.start]), float(parameter[fit.stop]), fit.asymptote]
    if global_at is not None:
        ends.append(float(global_at))
    low, high = min(ends), max(ends)
    pad = 0.08 * (high - low)
    inside = (parameter >= low - pad) & (parameter <= high + pad)
    shown = period[inside & np.isfinite(period)]
    bottom, peak = float(np.min(shown)), float(np.max(shown))
    return (low - pad, high + pad), (bottom - 0.05 * (peak - bottom),
                                     peak + 0.15 * (peak - bottom))


def _zoom_approach(ax: Axes, continuation: ContinuationResult, family: Branch, global_point,
                   fit: BlowupFit, top: float) -> Axes | None:
    """An inset of ``ax`` in its emptiest corner zooming on :func:`approach_box`: the family,
    its points, the fit and its asymptote again; the region outlined on ``ax``. None
    (nothing drawn) where the box spans more than :data:`_ZOOM_WORTH` of the x-axis."""
    from matplotlib.ticker import MaxNLocator

    from .argand import ZOOM_SIZE, emptiest_corner

    x, period = family.parameters[:, 0], family.period
    at = None if global_point is None else global_point.parameters[0]
    xlim, ylim = approach_box(x, period, fit, at)
    left, right = ax.get_xlim()
    if xlim[1] - xlim[0] > _ZOOM_WORTH * abs(right - left):
        return None
    ax.autoscale_view()
    finite = np.isfinite(period)
    points = ax.transLimits.transform(np.column_stack([x[finite], period[finite]]))
    x0, y0 = emptiest_corner(points)
    inset = ax.inset_axes([x0, y0, ZOOM_SIZE, ZOOM_SIZE])
    markers = _draw_family(inset, continuation, family, global_point, {}, xlim[1] - xlim[0])
    _draw_fit(inset, fit, x[fit.start], top)
    inset.set_xlim(*xlim)
    inset.set_ylim(*ylim)
    unstack(inset, markers)
    inset.tick_params(labelsize="x-small")
    inset.xaxis.set_major_locator(MaxNLocator(3))
    ax.indicate_inset_zoom(inset, edgecolor="black", alpha=0.6)
    return inset


def _family_points(ax: Axes, continuation: ContinuationResult, family: Branch, global_point,
                   first: dict, span: float) -> list:
    """The family's own special points at their periods (a snaking run of folds as one
    cluster), and its global point at the family's last finite period; the marker lines."""
    points: dict[str, list[Mark]] = {}
    for point in continuation.special_points:
        if point.branch != family.name or int(point.point_type) not in {
                int(t) for t in _FAMILY_POINTS}:
            continue
        period = float(point.period)
        if not np.isfinite(period) and 0 <= point.index < len(family):
            period = float(family.period[point.index])
        style = MARKER_STYLE[PointType(int(point.point_type))]
        points.setdefault(style, []).append(Mark(float(point.parameters[0]), period,
                                                 family.name, point.index))
    if global_point is not None:
        finite = family.period[np.isfinite(family.period)]
        if finite.size:
            style = MARKER_STYLE[PointType(int(global_point.point_type))]
            points.setdefault(style, []).append(Mark(float(global_point.parameters[0]),
                                                     float(finite[-1]), family.name,
                                                     len(family) - 1))
    drawn = draw_marks(ax, points, first, span)
    for style in [MARKER_STYLE[kind] for kind in _GLOBAL if MARKER_STYLE[kind] in drawn]:
        hollow = PLOT_KEY[style].get("markerfacecolor") == "none"
        for line in drawn[style]:  # on top of the fold beside it
            line.set(zorder=5, markersize=11, markeredgewidth=1.4 if hollow else 0.8,
                     markeredgecolor="black" if hollow else "white")
    return [line for lines in drawn.values() for line in lines]
