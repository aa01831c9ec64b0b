"""One-parameter figures: bifurcation diagrams, state projections, period plots and phase
planes of stored orbits.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..errors import WhirlError
from ..results import Branch, ContinuationResult, Criticality, LocateStatus, PointType
from .key import (
    BLACK,
    BOUNDARY_KEY,
    MARKER_STYLE,
    PLOT_KEY,
    PLOTTED_KINDS,
    axis_label,
    branch_style,
    display_unit,
    is_neutral_line,
    log_scale_if_decades,
    new_figure,
    next_colour,
    plot_styled,
    stability_curves,
)
from .markers import Mark, band_label, crowded_box, draw_marks, unstack

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.gridspec import SubplotSpec

_PERIOD_POINTS = (PointType.HB, PointType.LPC, PointType.PD, PointType.TR, PointType.BPC,
                  PointType.HOMOCLINIC, PointType.HETEROCLINIC)
_GLOBAL_POINTS = (PointType.HOMOCLINIC, PointType.HETEROCLINIC)


def bifurcation_diagram(continuation: ContinuationResult, state: str | None = None,
                        which: Sequence[str] = ("max",), ax: Axes | None = None,
                        degrees: bool = True, title: str | None = None) -> Figure:
    """One-parameter bifurcation diagram: ``state`` against each branch's principal parameter.

    ``state``: a state name of the branches; None: the first state of the first plotted branch
    (the model's first degree of freedom).

    Equilibrium and periodic branches are drawn (other kinds, e.g. loci, are skipped) with
    y = max of ``state`` over the orbit (the state itself for equilibria), and for periodic
    branches also the min when "min" is in ``which``; line styles follow :data:`PLOT_KEY` by kind
    and stability. Special points get markers at (principal parameter, ``state`` value). Angle
    states are shown in degrees (rad -> deg, rad/s -> deg/s) unless ``degrees`` is False; the
    parameter keeps its SI unit. Draws on ``ax`` if given, else on a new figure; returns the
    figure. The overhang of each subcritical Hopf point (:func:`overhangs`) is shaded and
    its width written at its top. The legend lists only styles present; the title is
    ``title`` (None: the continuation's name).
    """
    which, branches, state = checked_branches(continuation, state, which)
    if ax is None:
        ax = new_figure().add_subplot()
    handles, labels = draw_bifurcation(ax, continuation, branches, state, which, degrees)
    bands = overhangs(continuation)
    if bands:
        unit = branches[0].parameter_units[0] if branches else ""
        handles.append(_shade_overhangs(ax, bands, unit))
        labels.append(OVERHANG_LABEL)
    if handles:
        ax.legend(handles, labels, fontsize="small")
    ax.set_title(continuation.name if title is None else title)
    return ax.figure


def bifurcation_figure(continuation: ContinuationResult, state: str | None = None,
                       title: str | None = None, zoom: bool = True) -> Figure:
    """:func:`bifurcation_diagram` on a figure of its own; where its special-point markers
    crowd (:func:`~whirl_cli.plots.markers.crowded_box`) and ``zoom``, a zoom panel on the
    largest crowd to its right, the diagram drawn again there (no legend, its markers set
    apart at that scale), the zoomed region outlined on the diagram."""
    from matplotlib.patches import Rectangle

    figure = bifurcation_diagram(continuation, state, title=title)
    box = crowded_box(figure.axes[0]) if zoom else None
    if box is None:
        return figure
    width, height = figure.get_size_inches()
    figure = new_figure(figsize=(width * ZOOM_WIDTH, height))
    main, panel = figure.subplots(1, 2, width_ratios=(1.0, ZOOM_WIDTH - 1.0))
    bifurcation_diagram(continuation, state, ax=main, title=title)
    panel.set_xlim(*box[0])  # before the markers are set apart, at this scale
    panel.set_ylim(*box[1])
    bifurcation_diagram(continuation, state, ax=panel, title="zoom on the box at left")
    if panel.get_legend() is not None:
        panel.get_legend().remove()
    (x0, x1), (y0, y1) = box
    main.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, edgecolor=BLACK,
                             linewidth=0.8, zorder=5, label="_zoom"))
    return figure


#: The width of a bifurcation figure with a zoom panel, in widths of one without.
ZOOM_WIDTH = 1.7


#: The legend entry of a shaded overhang, and its shade (the unsafe region's colour, lighter:
#: the curves stay legible on it).
OVERHANG_LABEL = "unsafe (overhang)"
OVERHANG_ALPHA = 0.25


def overhangs(continuation: ContinuationResult) -> list[tuple[float, float]]:
    """The overhangs of ``continuation``: for each subcritical Hopf point, the parameter
    interval from it, towards the side where its equilibrium branch is stable, to the
    farthest fold of cycles (LPC) on that side of a periodic family born at or ending on it
    (its first or last row there, to 1e-3 of the parameter's span over the continuation: a
    family that returns to a Hopf point stops just short of it): where stable equilibria and
    limit cycles coexist beyond the linear onset. Each interval once (a mirror family gives
    the same), sorted."""
    values = [b.parameters[:, 0] for b in continuation.branches if len(b)]
    span = float(np.ptp(np.concatenate(values))) if values else 0.0
    by_name = {b.name: b for b in continuation.branches}
    bands = set()
    for hopf in continuation.special_points:
        if hopf.point_type != PointType.HB or hopf.criticality != Criticality.SUBCRITICAL:
            continue
        at = float(hopf.parameters[0])
        side = _stable_side(by_name.get(hopf.branch), hopf.index, at)
        folds = [float(p.parameters[0]) for family in continuation.branches
                 if family.is_periodic and len(family) and any(
                     abs(float(family.parameters[row, 0]) - at) <= 1e-3 * span
                     for row in (0, -1))
                 for p in continuation.special_points
                 if p.branch == family.name and p.point_type == PointType.LPC
                 and (float(p.parameters[0]) - at) * side > 0]
        if side and folds:
            far = max(folds, key=lambda value: abs(value - at))
            bands.add((min(at, far), max(at, far)))
    return sorted(bands)


def _stable_side(branch: Branch | None, index: int, at: float) -> float:
    """+1 or -1: the side of the parameter value ``at`` (row ``index`` of the equilibrium
    ``branch``) on which the branch is stable, by its rows two steps either way; 0 if
    neither or both."""
    if branch is None or not 0 <= index < len(branch):
        return 0.0
    sides = [np.sign(float(branch.parameters[row, 0]) - at) for row in (index - 2, index + 2)
             if 0 <= row < len(branch) and branch.stable[row]]
    return float(sides[0]) if len(sides) == 1 else 0.0


def _shade_overhangs(ax: Axes, bands: list[tuple[float, float]], unit: str):
    """Each band shaded across the axes, its width written at its top, or where no marker
    hides it (:func:`~whirl_cli.plots.markers.band_label`); the legend handle."""
    from matplotlib.patches import Patch

    style = BOUNDARY_KEY["unsafe"]
    for low, high in bands:
        ax.axvspan(low, high, color=style["color"], alpha=OVERHANG_ALPHA, linewidth=0,
                   zorder=0)
        band_label(ax, f"{high - low:.3g} {unit}".strip(), low, high, fontsize="small",
                   in_layout=False)  # inside the axes, or not drawn
    return Patch(color=style["color"], alpha=OVERHANG_ALPHA, linewidth=0)


def checked_branches(continuation: ContinuationResult, state: str | None,
                      which: Sequence[str]) -> tuple[tuple[str, ...], list[Branch], str]:
    """``which`` as a tuple, the plotted branches and the state drawn (``state``, or the first
    state of the first plotted branch if None); WhirlError if an argument is bad."""
    which = tuple(which)
    if not which or not set(which) <= {"max", "min"}:
        raise WhirlError(f"which must be a non-empty subset of ('max', 'min'), got {which}")
    branches = [b for b in continuation.branches if b.kind in PLOTTED_KINDS]
    if state is None:
        state = branches[0].state_names[0] if branches else ""
    for branch in branches:
        if state not in branch.state_names:
            raise WhirlError(f"state {state!r} not on branch {branch.name!r} "
                             f"(states: {', '.join(branch.state_names)})")
    return which, branches, state


def draw_bifurcation(ax: Axes, continuation: ContinuationResult, branches: list[Branch],
                      state: str, which: tuple[str, ...], degrees: bool
                      ) -> tuple[list, list[str]]:
    """Branches, special points and axis labels of a bifurcation diagram; legend entries."""
    first: dict[str, object] = {}  # style -> first artist drawn with it (legend handle)
    for branch in branches:
        _draw_branch(ax, branch, state, which, degrees, first)
    draw_special_points(ax, continuation, branches, state, degrees, first)
    label_axes(ax, continuation, branches, state, which, degrees)
    return ([first[key] for key in PLOT_KEY if key in first],
            [str(PLOT_KEY[key]["label"]) for key in PLOT_KEY if key in first])


def projections_figure(continuation: ContinuationResult, which: Sequence[str] = ("max",),
                       degrees: bool = True, title: str | None = None,
                       region: SubplotSpec | None = None) -> Figure:
    """One bifurcation diagram per state on a grid of ceil(n/2) x 2 axes sharing the x-axis
    (in a ``region`` wide enough for them, one row: :func:`~whirl_cli.plots.cuts.grid_columns`).

    The states are those common to every plotted (equilibrium or periodic) branch, in the order
    of the first; each panel is :func:`bifurcation_diagram` of one state (angles in deg, rates in
    deg/s unless ``degrees`` is False; ``which`` as there). Only the first panel has a legend and
    only the bottom panels an x label; the figure title is ``title`` (None: the continuation's
    name). Without
    plotted branches the figure has one empty axes. ``region``: draw into this part of an
    existing figure (a sheet's panel; the title then goes on the panel's first axes) instead
    of a new figure.
    """
    states = _common_states(continuation)
    columns = 2
    if region is not None:
        from .cuts import grid_columns

        columns = max(2, grid_columns(len(states), region)) if len(states) >= 4 else 2
    rows = max(1, -(-len(states) // columns))
    if region is None:
        figure = new_figure(figsize=(10.0, 3.2 * rows + 0.6), layout="constrained")
        grid = figure.add_gridspec(rows, 2)
    else:
        figure = region.get_gridspec().figure
        grid = region.subgridspec(rows, columns)
    title = continuation.name if title is None else title
    if not states:
        figure.add_subplot(grid[:, :]).set_title(title)
        return figure
    axes = grid.subplots(sharex=True, squeeze=False).ravel()
    for k, (ax, state) in enumerate(zip(axes, states, strict=False)):
        bifurcation_diagram(continuation, state=state, which=which, ax=ax, degrees=degrees)
        ax.set_title("")
        if k > 0 and ax.get_legend() is not None:
            ax.get_legend().remove()
        if k < len(states) - columns:  # another panel below in the same column
            ax.set_xlabel("")
    for ax in axes[len(states):]:
        figure.delaxes(ax)
    if columns == 2 and len(states) % 2 and len(states) > 1:  # lone last panel: label its
        # neighbour's x
        axes[len(states) - 2].xaxis.set_tick_params(labelbottom=True)
        axes[len(states) - 2].set_xlabel(axes[len(states) - 1].get_xlabel())
    if region is None:
        figure.suptitle(title)
    else:
        axes[0].set_title(title)
    return figure


def _common_states(continuation: ContinuationResult) -> tuple[str, ...]:
    """States on every plotted branch, in the order of the first (``()`` without branches)."""
    branches = [b for b in continuation.branches if b.kind in PLOTTED_KINDS]
    if not branches:
        return ()
    return tuple(s for s in branches[0].state_names if all(s in b.state_names for b in branches))


def period_plot(continuation: ContinuationResult, title: str | None = None,
                ax: Axes | None = None) -> Figure:
    """Period [s] of every periodic branch against its principal parameter (SI unit).

    Lines follow :data:`PLOT_KEY` (stable solid blue, unstable dotted red) split as in
    :func:`bifurcation_diagram`. Markers: LPC, PD, TR, BPC on periodic branches at their period
    (the branch's period at the point's row if the point has none), Hopf points with a finite
    period (where periodic branches are born), and HOMOCLINIC/HETEROCLINIC at (their parameter
    estimate, the period at the last point of their branch). A "bracketed" global point also
    gets its bracket drawn as a horizontal error bar at the top of the data, if wide enough to
    be seen beside its marker (:data:`BRACKET_VISIBLE`). A snaking family's folds are one
    cluster, markers at one place are set apart (:mod:`~whirl_cli.plots.markers`). The y-axis is
    logarithmic if the largest period exceeds 20 times the smallest. Without periodic branches
    the axes stay empty. Title: ``title`` (None: ``"<continuation>: period"``). Draws on ``ax``
    if given, else on a new figure; returns the figure.
    """
    if ax is None:
        ax = new_figure().add_subplot()
    periodic = [b for b in continuation.branches if b.is_periodic]
    first: dict[str, object] = {}
    for branch in periodic:
        x = branch.parameters[:, 0]
        for xs, ys, stable in stability_curves(x, branch.period, branch.stable,
                                                 branch.stability_known):
            plot_styled(ax, xs, ys, branch_style(branch.kind, stable), first)
    periods = np.concatenate([b.period for b in periodic]) if periodic else np.array([])
    periods = periods[np.isfinite(periods) & (periods > 0)]
    points, brackets = _period_points(continuation, periodic)
    brackets = _visible_brackets(brackets, continuation)
    markers = draw_marks(ax, points, first, _periodic_span(continuation))
    handles = [first[key] for key in PLOT_KEY if key in first]
    labels = [str(PLOT_KEY[key]["label"]) for key in PLOT_KEY if key in first]
    if brackets and periods.size:
        top = float(np.max(periods))
        for low, high in brackets:
            bar = ax.errorbar([(low + high) / 2], [top], xerr=[(high - low) / 2], fmt="none",
                              ecolor=BLACK, elinewidth=1.2, capsize=4, zorder=4,
                              label="_bracket")
        handles.append(bar)
        labels.append("bracket (global bifurcation)")
    log_scale_if_decades(ax, "y", periods)
    unstack(ax, [line for lines in markers.values() for line in lines])
    if periodic:
        ax.set_xlabel(axis_label(periodic[0].parameter_names[0], periodic[0].parameter_units[0]))
    ax.set_ylabel(axis_label("period", "s"))
    if handles:
        ax.legend(handles, labels, fontsize="small")
    ax.set_title(f"{continuation.name}: period" if title is None else title)
    return ax.figure


#: A bracket narrower than this fraction of the continuation's span is not drawn (nor listed):
#: it would be a dot under its point's marker.
BRACKET_VISIBLE = 0.005


def _visible_brackets(brackets: list[tuple[float, float]], continuation: ContinuationResult
                      ) -> list[tuple[float, float]]:
    """The ``brackets`` wide enough to be seen beside their marker (:data:`BRACKET_VISIBLE`)."""
    span = _periodic_span(continuation)
    return [(low, high) for low, high in brackets if high - low > BRACKET_VISIBLE * span]


def _periodic_span(continuation: ContinuationResult) -> float:
    """The span of the principal parameter over the periodic branches (0 without any)."""
    values = [b.parameters[:, 0] for b in continuation.branches if b.is_periodic and len(b)]
    return float(np.ptp(np.concatenate(values))) if values else 0.0


def _period_points(continuation: ContinuationResult, periodic: list[Branch]
                   ) -> tuple[dict[str, list[Mark]], list[tuple[float, float]]]:
    """Marker positions by style, and the finite brackets of "bracketed" global points."""
    by_name = {b.name: b for b in continuation.branches}
    periodic_names = {b.name for b in periodic}
    x_name = periodic[0].parameter_names[0] if periodic else None
    points: dict[str, list[Mark]] = {}
    brackets: list[tuple[float, float]] = []
    for point in continuation.special_points:
        kind = _point_type(point.point_type)
        branch = by_name.get(point.branch)
        if kind not in _PERIOD_POINTS or branch is None or point.parameter_names[0] != x_name:
            continue
        if kind != PointType.HB and point.branch not in periodic_names:
            continue
        if kind in _GLOBAL_POINTS:
            finite = branch.period[np.isfinite(branch.period)]
            period = float(finite[-1]) if finite.size else np.nan
            bracket = np.asarray(point.bracket, dtype=float)
            if point.status == LocateStatus.BRACKETED and bracket.shape == (2,) and np.isfinite(
                    bracket).all():
                brackets.append((float(bracket.min()), float(bracket.max())))
        else:
            period = float(point.period)
            if not np.isfinite(period) and 0 <= point.index < len(branch):
                period = float(branch.period[point.index])
        mark = Mark(float(point.parameters[0]), period, point.branch, point.index)
        if np.isfinite(mark.x) and np.isfinite(mark.y):
            points.setdefault(MARKER_STYLE[kind], []).append(mark)
    return points, brackets


def phase_plane(branch: Branch, labels: Sequence[int] | None = None, x: str | None = None,
                y: str | None = None, degrees: bool = True, ax: Axes | None = None,
                title: str | None = None) -> Figure:
    """Stored orbits of a periodic branch as closed curves of state ``y`` against state ``x``
    (None: the branch's first and second state, i.e. the model's first two degrees of freedom,
    or a single dof and its rate).

    All of ``branch.orbits`` if ``labels`` is None, else those with these AUTO labels; drawn
    (and listed in the legend) in order of the principal parameter. Each curve is closed (its
    first point repeated at the end unless already equal), drawn solid if the branch is
    stable at the orbit's row, dotted if not and dashed where its stability is unknown, each
    in its own colour (:func:`~whirl_cli.plots.key.next_colour`), and labelled
    ``"<parameter> = <value> (stable|unstable|stability unknown)"`` with the principal
    parameter (4 significant digits). Angles in degrees, rates in deg/s unless
    ``degrees`` is False; equal aspect when both axes have the same unit. Draws on ``ax`` if
    given, else on a new figure (its legend then beside the axes, clear of the orbits);
    returns the figure. The title is ``title`` (None: the
    branch's name).
    """
    if not branch.is_periodic:
        raise WhirlError(f"branch {branch.name!r} is {branch.kind}, not periodic: no orbits")
    x = branch.state_names[0] if x is None else x
    y = branch.state_names[1] if y is None else y
    for name in (x, y):
        if name not in branch.state_names:
            raise WhirlError(f"state {name!r} not on branch {branch.name!r} "
                             f"(states: {', '.join(branch.state_names)})")
    orbits = list(branch.orbits)
    if labels is not None:
        by_label = {orbit.label: orbit for orbit in orbits}
        missing = [label for label in labels if label not in by_label]
        if missing:
            raise WhirlError(f"no stored orbit with label(s) {missing} on branch "
                             f"{branch.name!r} (labels: {sorted(by_label)})")
        orbits = [by_label[label] for label in labels]
    orbits.sort(key=lambda orbit: float(orbit.parameters[0]))
    ix, iy = branch.state_names.index(x), branch.state_names.index(y)
    fx, unit_x = display_unit(branch.state_units[ix], degrees)
    fy, unit_y = display_unit(branch.state_units[iy], degrees)
    own = ax is None
    if ax is None:
        ax = new_figure().add_subplot()
    for orbit in orbits:
        colour = next_colour(ax.figure)
        states = np.asarray(orbit.states, dtype=float)
        if len(states) and not np.array_equal(states[0], states[-1]):
            states = np.vstack([states, states[:1]])
        stable = bool(branch.stable[orbit.index]) if 0 <= orbit.index < len(branch) \
            and branch.stability_known[orbit.index] else None
        status = {True: "stable", False: "unstable", None: "stability unknown"}[stable]
        ax.plot(states[:, ix] * fx, states[:, iy] * fy, color=colour,
                linestyle={True: "-", False: ":", None: "--"}[stable],
                label=f"{branch.parameter_names[0]} = {orbit.parameters[0]:.4g} ({status})")
    ax.set_xlabel(axis_label(x, unit_x))
    ax.set_ylabel(axis_label(y, unit_y))
    if unit_x == unit_y:
        ax.set_aspect("equal", adjustable="datalim")
    if orbits and own:  # beside the axes: never over an orbit
        ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.02, 1.0),
                  borderaxespad=0.0)
    elif orbits:
        ax.legend(fontsize="small")
    ax.set_title(branch.name if title is None else title)
    return ax.figure


def _draw_branch(ax: Axes, branch: Branch, state: str, which: tuple[str, ...], degrees: bool,
                 first: dict) -> None:
    """Draw one branch's max (and min, periodic only) curves, split by stability."""
    factor, _ = display_unit(branch.state_units[branch.state_names.index(state)], degrees)
    x = branch.parameters[:, 0]
    tables = [w for w in ("max", "min") if w in which] if branch.is_periodic else [which[0]]
    for table in tables:
        y = branch.state(state, table) * factor
        if not branch.is_periodic and is_neutral_line(x, branch.stable):
            plot_styled(ax, x, y, "neutral_equilibrium", first)
            continue
        for xs, ys, stable in stability_curves(x, y, branch.stable,
                                                 branch.stability_known):
            plot_styled(ax, xs, ys, branch_style(branch.kind, stable), first)


def draw_special_points(ax: Axes, continuation: ContinuationResult, branches: list[Branch],
                         state: str, degrees: bool, first: dict) -> None:
    """Markers for special points, one artist per marker style (a snaking family's folds
    as one cluster, markers at one place set apart: :mod:`~whirl_cli.plots.markers`).

    A point at a row of a drawn branch (:func:`_at_row`) sits on that branch's curve there (a
    global point stores the saddle's state, not the orbit's max); any other at its own state,
    read by the state names of its branch (or of the first plotted branch if its branch is
    not among them). Points not on the x-axis parameter are skipped.
    """
    by_name = {b.name: b for b in branches}
    x_name = branches[0].parameter_names[0] if branches else None
    points: dict[str, list[Mark]] = {}
    for point in continuation.special_points:
        style = MARKER_STYLE.get(_point_type(point.point_type))
        branch = by_name.get(point.branch, branches[0] if branches else None)
        if style is None or branch is None or point.parameter_names[0] != x_name:
            continue
        index = branch.state_names.index(state)
        factor, _ = display_unit(branch.state_units[index], degrees)
        y = branch.state(state)[point.index] if _at_row(point, branch) else point.state[index]
        mark = Mark(float(point.parameters[0]), float(y) * factor, point.branch, point.index)
        if np.isfinite(mark.x) and np.isfinite(mark.y):
            points.setdefault(style, []).append(mark)
    values = [b.parameters[:, 0] for b in branches if len(b)]
    span = float(np.ptp(np.concatenate(values))) if values else 0.0
    drawn = draw_marks(ax, points, first, span)
    unstack(ax, [line for lines in drawn.values() for line in lines])


def _at_row(point, branch: Branch) -> bool:
    """Whether ``point`` lies on ``branch`` at its row ``index``: the branch is its own and
    the row's principal parameter is the point's (to 1e-6 of the branch's span)."""
    if point.branch != branch.name or not 0 <= point.index < len(branch):
        return False
    x = branch.parameters[:, 0]
    gap = abs(float(x[point.index]) - float(point.parameters[0]))
    return gap <= 1e-6 * max(float(np.ptp(x)), 1e-300)


def _point_type(code: int) -> PointType | None:
    try:
        return PointType(int(code))
    except ValueError:
        return None


def label_axes(ax: Axes, continuation: ContinuationResult, branches: list[Branch], state: str,
                which: tuple[str, ...], degrees: bool) -> None:
    """Axis labels with units from the first plotted branch (nothing if there is none)."""
    if not branches:
        return
    ref = branches[0]
    ax.set_xlabel(axis_label(ref.parameter_names[0], ref.parameter_units[0]))
    _, unit = display_unit(ref.state_units[ref.state_names.index(state)], degrees)
    extent = ", ".join(which) if any(b.is_periodic for b in branches) else ""
    ax.set_ylabel(axis_label(f"{state} ({extent})" if extent else state, unit))

