"""Two-parameter stability maps (thesis figures 3.13, 3.15, 3.28, 3.29) with the unsafe
(overhang) region, and the bifurcation diagram of a slice with its unsafe intervals shaded.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from functools import partial
from typing import TYPE_CHECKING

import numpy as np

from ..errors import WhirlError
from ..results import (
    Boundary,
    ContinuationKind,
    ContinuationResult,
    LinearGrid,
    Spacing,
    on_slice,
)
from .diagrams import checked_branches, draw_bifurcation
from .key import (
    BLACK,
    BOUNDARY_KEY,
    UNSAFE_LABEL,
    axis_label,
    log_scale_if_decades,
    new_figure,
    patch_proxy,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

_LOCUS_KINDS = ("hopf", "branch_point", "fold", "fold_of_cycles", "torus")
_SLICE_TOLERANCE = 1e-12  # slice values equal within this are the same slice
_BAND_ALPHA = 0.25  # unsafe bands of overhang diagrams
_CASE_LABEL_LINES = 1.15  # least distance of case labels, in lines of their text
_LINEAR_FRACTION = 0.01  # of the surface's largest magnitude: its colour scale's linear part
_LIMIT_MARGIN = 0.02  # fraction of the data span added around loci-derived axis limits


def boundary_plot(boundary: Boundary | None, grid: LinearGrid | None,
                  cases: Sequence[float] = (), ax: Axes | None = None,
                  case_labels: Sequence[str] = (), title: str | None = None,
                  xlim: tuple[float, float] | None = None,
                  ylim: tuple[float, float] | None = None) -> Figure:
    """Stability map in two parameters (thesis figures 3.13, 3.15, 3.28, 3.29).

    x is the first parameter of ``boundary`` (or ``grid.x_parameter``), y the second, both in
    their own (SI) units. Drawn, styled after :data:`BOUNDARY_KEY`:

    * from ``grid``: the linearly unstable region (``max_real`` > 0) shaded light grey and the
      linear zero contour thin black, solid where the critical eigenvalue is complex (flutter),
      dashed where it is real (divergence); a grid drawn without a boundary shows the surface
      ``max_real`` itself (:data:`SURFACE_MAP`, a colour bar in 1/s), the unstable region
      hatched over it (:func:`stability_surface`);
    * from ``boundary``: its loci (Hopf solid dark blue, branch point dashed black, fold
      dash-dot grey, fold of cycles solid orange, torus dotted green strung with the thesis
      key's hollow circles; other kinds are not drawn) and the unsafe (overhang) region, its
      polygons filled red;
    * a thin dotted horizontal line at each value of ``cases`` (e.g. ``boundary.slices``),
      labelled by ``case_labels`` (by default, and where a label is missing or empty, "case
      1", "case 2", ...) just right of the axes (labels only for lines within the y limits,
      nudged up where they would overlap).

    The legend lists only what is drawn. Axis limits are the grid's extent, else the extent of
    the loci (or, without loci, of the polygons) plus a 2 % margin, else matplotlib's;
    ``xlim`` and ``ylim`` replace them. A grid
    over the same two parameters in the other order is transposed; over other parameters it is
    a :class:`WhirlError`, as is passing neither. Title: ``boundary.name`` (else "linear
    stability"), unless ``title`` is given. Draws on ``ax`` if given, else on a new figure;
    returns the figure.
    """
    if boundary is None and grid is None:
        raise WhirlError("boundary_plot needs a boundary, a linear grid or both")
    if boundary is not None and grid is not None:
        oriented = oriented_grid(grid, boundary.parameter_names)
        if oriented is None:
            raise WhirlError(f"linear grid over ({grid.x_parameter}, {grid.y_parameter}) does "
                             f"not match boundary {boundary.name!r} over "
                             f"({', '.join(boundary.parameter_names)})")
        grid = oriented
    if ax is None:
        ax = new_figure().add_subplot()
    first: dict[str, object] = {}
    if grid is not None:
        _draw_grid(ax, grid, first, surface=boundary is None)
    if boundary is not None:
        _draw_loci(ax, boundary, first)
        for polygon in boundary.polygons:
            polygon = np.asarray(polygon, dtype=float)
            if len(polygon) >= 3:
                style = dict(BOUNDARY_KEY["unsafe"], label="_unsafe")
                (patch,) = ax.fill(polygon[:, 0], polygon[:, 1], **style, zorder=2)
                first.setdefault("unsafe", patch)
    _set_map_limits(ax, boundary, grid)
    if xlim is not None:
        ax.set_xlim(*xlim)
    if ylim is not None:
        ax.set_ylim(*ylim)
    _draw_cases(ax, cases, case_labels)
    if boundary is not None:
        names, units = boundary.parameter_names, boundary.parameter_units
    else:
        names, units = (grid.x_parameter, grid.y_parameter), (grid.x_unit, grid.y_unit)
    ax.set_xlabel(axis_label(names[0], units[0]))
    ax.set_ylabel(axis_label(names[1], units[1]))
    if first:
        ax.legend([first[key] for key in BOUNDARY_KEY if key in first],
                  [str(BOUNDARY_KEY[key]["label"]) for key in BOUNDARY_KEY if key in first],
                  fontsize="small")
    if title is None:
        title = boundary.name if boundary is not None else "linear stability"
    ax.set_title(title)
    return ax.figure


def oriented_grid(grid: LinearGrid, names: Sequence[str]) -> LinearGrid | None:
    """``grid`` with x = ``names[0]`` and y = ``names[1]`` (transposed if needed), else None."""
    if (grid.x_parameter, grid.y_parameter) == tuple(names):
        return grid
    if (grid.y_parameter, grid.x_parameter) == tuple(names):
        return LinearGrid(grid.y_parameter, grid.x_parameter, grid.y_unit, grid.x_unit,
                          grid.y, grid.x, np.asarray(grid.max_real).T,
                          np.asarray(grid.oscillatory).T,
                          tuple(np.asarray(line)[:, ::-1] for line in grid.flutter),
                          tuple(np.asarray(line)[:, ::-1] for line in grid.divergence),
                          x_spacing=grid.y_spacing, y_spacing=grid.x_spacing)
    return None


SURFACE_MAP = "cividis"
"""Colour map of the max Re lambda surface (its lightness rises monotonically: it reads in
greyscale)."""


def stability_surface(ax: Axes, grid: LinearGrid):
    """The surface ``grid.max_real`` [1/s] over (x, y) as a colour mesh with a colour bar,
    the region where it is > 0 hatched; returns the mesh (its array is ``max_real``). The
    colour scale is linear within 1 % of the largest magnitude of zero and logarithmic beyond,
    so that slow flutter growth shows beside fast divergence."""
    from matplotlib.colors import SymLogNorm

    max_real = np.ma.masked_invalid(np.asarray(grid.max_real, dtype=float))
    low, high = float(max_real.min()), float(max_real.max())
    norm = SymLogNorm(linthresh=_LINEAR_FRACTION * max(abs(low), abs(high), 1e-300),
                      vmin=low, vmax=high, base=10)
    mesh = ax.pcolormesh(grid.x, grid.y, max_real, cmap=SURFACE_MAP, norm=norm,
                         shading="nearest", zorder=0, rasterized=True)
    ax.figure.colorbar(mesh, ax=ax, label=axis_label("max Re $\\lambda$", "1/s"))
    if np.ma.any(max_real > 0):
        ax.contourf(grid.x, grid.y, max_real, levels=[0.0, np.inf], colors="none",
                    hatches=["//"], zorder=0.5)
    return mesh


def _draw_grid(ax: Axes, grid: LinearGrid, first: dict, surface: bool = False) -> None:
    """Shade max_real > 0 (contourf, levels [0, inf]), or draw the surface with that region
    hatched (``surface``); draw the zero contour by kind."""
    max_real = np.ma.masked_invalid(np.asarray(grid.max_real, dtype=float))
    if surface:
        stability_surface(ax, grid)
        if np.ma.any(max_real > 0):
            first["linearly_unstable"] = _hatch_proxy()
    elif np.ma.any(max_real > 0):
        style = BOUNDARY_KEY["linearly_unstable"]
        ax.contourf(grid.x, grid.y, max_real, levels=[0.0, np.inf], colors=[style["color"]],
                    zorder=0)
        first["linearly_unstable"] = patch_proxy(style)
    for key, lines in (("linear_flutter", grid.flutter), ("linear_divergence", grid.divergence)):
        for line in lines:
            _plot_polyline(ax, line, key, first, zorder=1)


def _hatch_proxy():
    """A legend handle for the hatched unstable region of a surface."""
    from matplotlib.patches import Patch

    return Patch(facecolor="none", edgecolor=BLACK, hatch="//",
                 label=BOUNDARY_KEY["linearly_unstable"]["label"])


def _plot_polyline(ax: Axes, line: np.ndarray, key: str, first: dict, zorder: float) -> None:
    """Draw a (K, 2) polyline with ``BOUNDARY_KEY[key]`` (nothing if it has < 2 points)."""
    line = np.asarray(line, dtype=float)
    if line.ndim != 2 or len(line) < 2:
        return
    kwargs = dict(BOUNDARY_KEY[key], label=f"_{key}")
    (artist,) = ax.plot(line[:, 0], line[:, 1], **kwargs, zorder=zorder)
    first.setdefault(key, artist)


def _draw_loci(ax: Axes, boundary: Boundary, first: dict) -> None:
    """The boundary's loci, kinds in the order of :data:`BOUNDARY_KEY`."""
    for kind in _LOCUS_KINDS:
        for locus_kind, curve in boundary.loci.values():
            if locus_kind == kind:
                _plot_polyline(ax, curve, kind, first, zorder=3)


def _set_map_limits(ax: Axes, boundary: Boundary | None, grid: LinearGrid | None) -> None:
    """Grid extent; else loci extent (polygons if no loci) with a margin; else leave as is.
    An axis whose extent spans decades, or the grid samples log, is logarithmic
    (:func:`log_scale_if_decades`), its margin then a factor."""
    extent = _map_extent(boundary, grid)
    if extent is None:
        return
    for axis, (low, high) in zip("xy", extent[:2], strict=True):
        margin = extent[2]
        spacing = Spacing.LINEAR if grid is None else getattr(grid, f"{axis}_spacing")
        if log_scale_if_decades(ax, axis, (low, high), spacing):
            factor = (high / low) ** margin
            low, high = low / factor, high * factor
        else:
            low, high = low - margin * (high - low), high + margin * (high - low)
        if high > low:
            getattr(ax, f"set_{axis}lim")(float(low), float(high))


def _map_extent(boundary: Boundary | None, grid: LinearGrid | None):
    """((x low, x high), (y low, y high), margin): the grid's extent (no margin), else the
    loci's (the polygons' if no loci; :data:`_LIMIT_MARGIN`); None: nothing to bound."""
    if grid is not None and len(grid.x) and len(grid.y):
        return ((float(np.min(grid.x)), float(np.max(grid.x))),
                (float(np.min(grid.y)), float(np.max(grid.y))), 0.0)
    if boundary is None:
        return None
    curves = [np.asarray(c, dtype=float) for kind, c in boundary.loci.values()
              if kind in _LOCUS_KINDS]
    if not any(c.ndim == 2 and len(c) >= 2 for c in curves):
        curves = [np.asarray(p, dtype=float) for p in boundary.polygons]
    points = [c for c in curves if c.ndim == 2 and c.shape[1] == 2 and len(c)]
    if not points:
        return None
    xy = np.concatenate(points)
    xy = xy[np.isfinite(xy).all(axis=1)]
    if not len(xy):
        return None
    return ((xy[:, 0].min(), xy[:, 0].max()), (xy[:, 1].min(), xy[:, 1].max()), _LIMIT_MARGIN)


def _draw_cases(ax: Axes, cases: Sequence[float], labels: Sequence[str] = ()) -> None:
    """Dotted horizontal lines at the case values, labelled right of the axes by ``labels``
    ("case k" where there is none)."""
    for k, value in enumerate(cases, 1):
        ax.axhline(float(value), color=BLACK, linestyle=":", linewidth=0.8, zorder=1,
                   label=f"_case {k}")
    bottom, top = ax.get_ylim()
    low, high = sorted((bottom, top))
    shown = sorted(((float(v) - bottom) / (top - bottom) if top != bottom else 0.5, k)
                   for k, v in enumerate(cases, 1) if low <= float(v) <= high)
    values = [float(cases[k - 1]) for _, k in shown]
    for n, (_, k) in enumerate(shown):
        label = labels[k - 1] if k <= len(labels) and labels[k - 1] else f"case {k}"
        ax.annotate(label, xy=(1.01, values[n]), ha="left", va="center", fontsize="small",
                    xycoords=partial(_case_label_place, ax, values, n),
                    annotation_clip=False)


def _case_label_place(ax: Axes, values: list[float], n: int, renderer):
    """The transform placing case label ``n`` (x in axes fractions, y in data): at its case
    ``values[n]`` (``values`` in the order drawn bottom to top), or pushed up to stay
    :data:`_CASE_LABEL_LINES` lines of its text above the label below it, measured on the
    axes as drawn (after the layout and any shared limits)."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.transforms import Affine2D, blended_transform_factory

    heights = ax.transData.transform([(0.0, v) for v in values])[:, 1]
    gap = (_CASE_LABEL_LINES * FontProperties(size="small").get_size_in_points()
           * ax.figure.dpi / 72.0)
    position = -np.inf
    for height in heights[:n + 1]:
        position = max(height, position + gap)
    place = blended_transform_factory(ax.transAxes, ax.transData)
    return place + Affine2D().translate(0.0, position - heights[n])


def slice_continuation(continuation: ContinuationResult, index: int) -> ContinuationResult:
    """The one-parameter continuation of slice ``index`` of a two-parameter continuation.

    Its branches are those of that slice (:func:`~whirl_cli.results.on_slice`), named as on
    the slice, and its special points those on them (branch renamed likewise). Named
    ``<continuation>.slice_<index>``, kind "one-parameter"."""
    branches = tuple(replace(b, name=on_slice(b.name, index)) for b in continuation.branches
                     if on_slice(b.name, index) is not None)
    points = tuple(replace(p, branch=on_slice(p.branch, index))
                   for p in continuation.special_points if on_slice(p.branch, index) is not None)
    return ContinuationResult(f"{continuation.name}.slice_{index}", ContinuationKind.ONE_PARAMETER,
                              branches,
                              points)


def slice_index(boundary: Boundary, slice_value: float) -> int:
    """Index of ``slice_value`` in ``boundary.slices`` (equal within 1e-12); WhirlError if
    absent."""
    for k, value in enumerate(boundary.slices):
        if abs(float(value) - float(slice_value)) <= _SLICE_TOLERANCE:
            return k
    raise WhirlError(f"{slice_value!r} is not a slice of boundary {boundary.name!r} "
                     f"(slices: {list(boundary.slices)})")


def overhang_diagram(continuation: ContinuationResult, boundary: Boundary | None,
                     slice_value: float, state: str | None = None,
                     which: Sequence[str] = ("max",), ax: Axes | None = None,
                     degrees: bool = True, title: str | None = None) -> Figure:
    """Bifurcation diagram of one slice with its unsafe (overhang) intervals shaded.

    For a two-parameter ``continuation`` the diagram is :func:`bifurcation_diagram` of
    :func:`slice_continuation` at the index of ``slice_value`` in ``boundary.slices`` (a
    ``boundary`` is then required); a one-parameter continuation is drawn as it is. Every
    interval of ``boundary.intervals`` on this slice (``slice_value`` equal within 1e-12) is a
    red vertical band (alpha 0.25) from ``lower`` to ``upper``, with one legend entry
    "unsafe (overhang)". ``state``, ``which``, ``degrees`` and ``ax`` as in
    :func:`bifurcation_diagram`. Title: ``"<continuation>: <second parameter> = <value>"``
    (just the continuation's name without a boundary), unless ``title`` is given. Returns the
    figure.
    """
    if continuation.kind == ContinuationKind.TWO_PARAMETER:
        if boundary is None:
            raise WhirlError(f"continuation {continuation.name!r} is two-parameter: an "
                             "overhang diagram needs its boundary to find the slice")
        diagram = slice_continuation(continuation, slice_index(boundary, slice_value))
    else:
        diagram = continuation
    which, branches, state = checked_branches(diagram, state, which)
    if ax is None:
        ax = new_figure().add_subplot()
    handles, labels = draw_bifurcation(ax, diagram, branches, state, which, degrees)
    band = None
    intervals = () if boundary is None else boundary.intervals
    for interval in intervals:
        if abs(float(interval.slice_value) - float(slice_value)) <= _SLICE_TOLERANCE:
            span = ax.axvspan(float(interval.lower), float(interval.upper), color="red",
                              alpha=_BAND_ALPHA, linewidth=0, zorder=0, label="_unsafe")
            band = band or span
    if band is not None:
        handles.append(band)
        labels.append(UNSAFE_LABEL)
    if handles:
        ax.legend(handles, labels, fontsize="small")
    if title is None:
        title = continuation.name
        if boundary is not None:
            title += f": {boundary.parameter_names[1]} = {float(slice_value):g}"
    ax.set_title(title)
    return ax.figure

