"""Figures of study results (matplotlib, Agg): bifurcation diagrams, state projections, period
plots, phase planes of stored orbits, linear sweeps, two-parameter stability maps with the
unsafe (overhang) region and the bifurcation diagrams of their slices.

The only module that imports matplotlib, and only inside functions (the CLI starts without it).
Figures are built with the object-oriented API on an Agg canvas, never through pyplot, so they
need no display, are not kept alive by pyplot's figure registry and are freed once unreferenced.

Units: data arrive in SI (angles in rad, rates in rad/s, eigenvalues in 1/s). Bifurcation
diagrams show angle states in degrees by default ("rad" -> "deg", "rad/s" -> "deg/s");
parameters are always shown in their own (SI) units; periods in s. Linear sweeps show frequency
in rad/s and the damping ratio (dimensionless).

Plot key (thesis Table 2.1) is :data:`PLOT_KEY`: one entry per semantic style, with the
matplotlib ``Line2D`` keyword arguments that draw it and its legend label. Stability maps
(thesis figures 3.13, 3.15, 3.28, 3.29) use :data:`BOUNDARY_KEY` in the same way.
"""

from __future__ import annotations

import io
import itertools
import re
from collections.abc import Iterator, Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .errors import OutputError, WhirlError
from .results import (
    Boundary,
    Branch,
    BranchKind,
    ContinuationResult,
    LinearGrid,
    LinearSweep,
    PointType,
    StudyResult,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

_BLACK = "black"
_MARKER_SIZE = 8.0

PLOT_KEY: dict[str, dict[str, object]] = {
    # branches
    "stable_equilibrium": {"color": "green", "linestyle": "-", "label": "stable equilibrium"},
    "unstable_equilibrium": {"color": "magenta", "linestyle": "--",
                             "label": "unstable equilibrium"},
    "stable_periodic": {"color": "blue", "linestyle": "-", "label": "stable periodic"},
    "unstable_periodic": {"color": "red", "linestyle": ":", "label": "unstable periodic"},
    # special points
    "hopf": {"marker": "s", "markerfacecolor": "none", "markeredgecolor": _BLACK,
             "label": "Hopf (HB)"},
    "branch_point": {"marker": "*", "markerfacecolor": _BLACK, "markeredgecolor": _BLACK,
                     "label": "branch point (BP, BPC)"},
    "fold": {"marker": "o", "markerfacecolor": _BLACK, "markeredgecolor": _BLACK,
             "label": "fold (LP, LPC)"},
    "homoclinic": {"marker": "^", "markerfacecolor": _BLACK, "markeredgecolor": _BLACK,
                   "label": "homoclinic"},
    "heteroclinic": {"marker": "^", "markerfacecolor": "none", "markeredgecolor": _BLACK,
                     "label": "heteroclinic"},
    "torus": {"marker": "o", "markerfacecolor": "none", "markeredgecolor": _BLACK,
              "label": "torus (TR)"},
    "period_doubling": {"marker": "D", "markerfacecolor": _BLACK, "markeredgecolor": _BLACK,
                        "label": "period doubling (PD)"},
}
"""Semantic style -> Line2D keyword arguments (including ``label``). Do not mutate."""

MARKER_STYLE: dict[PointType, str] = {
    PointType.HB: "hopf",
    PointType.BP: "branch_point",
    PointType.BPC: "branch_point",
    PointType.LP: "fold",
    PointType.LPC: "fold",
    PointType.HOMOCLINIC: "homoclinic",
    PointType.HETEROCLINIC: "heteroclinic",
    PointType.TR: "torus",
    PointType.PD: "period_doubling",
}
"""Point type -> key of :data:`PLOT_KEY`; types not listed (REGULAR, RG, UZ, EP, MX, ...) get
no marker."""

_UNSAFE_LABEL = "unsafe (overhang)"
BOUNDARY_KEY: dict[str, dict[str, object]] = {
    # linear analysis over a grid
    "linearly_unstable": {"color": "lightgrey", "label": "linearly unstable"},
    "linear_flutter": {"color": _BLACK, "linestyle": "-", "linewidth": 0.8,
                       "label": "linear boundary (flutter)"},
    "linear_divergence": {"color": _BLACK, "linestyle": "--", "linewidth": 0.8,
                          "label": "linear boundary (divergence)"},
    # loci of the two-parameter continuation, by Boundary.loci kind
    "hopf": {"color": "darkblue", "linestyle": "-", "linewidth": 1.5,
             "label": "Hopf locus (flutter)"},
    "branch_point": {"color": _BLACK, "linestyle": "--", "linewidth": 1.5,
                     "label": "branch point locus (divergence)"},
    "fold": {"color": "grey", "linestyle": "-.", "linewidth": 1.5, "label": "fold locus (LP)"},
    "fold_of_cycles": {"color": "orange", "linestyle": "-", "linewidth": 1.5,
                       "label": "fold of cycles locus (LPC)"},
    # the unsafe region
    "unsafe": {"color": "red", "alpha": 0.5, "label": _UNSAFE_LABEL},
}
"""Stability-map style -> keyword arguments (``Line2D`` for lines, patch colour/alpha for the
"linearly_unstable" shading and the "unsafe" polygons), including the legend ``label``. The
locus entries are keyed by the kinds of :attr:`Boundary.loci`. Do not mutate."""
_LOCUS_KINDS = ("hopf", "branch_point", "fold", "fold_of_cycles")
_SLICE_TOLERANCE = 1e-12  # slice values equal within this are the same slice
_BAND_ALPHA = 0.25  # unsafe bands of overhang diagrams
_CASE_LABEL_GAP = 0.04  # least distance of case labels, in axes fractions
_LIMIT_MARGIN = 0.02  # fraction of the data span added around loci-derived axis limits

_PLOTTED_KINDS = (BranchKind.EQUILIBRIUM, BranchKind.PERIODIC)
PLOT_KINDS = ("bifurcation", "linear", "projections", "period", "phase", "boundary")
"""Kinds accepted by :func:`save_study_plots`."""
_PERIOD_POINTS = (PointType.HB, PointType.LPC, PointType.PD, PointType.TR, PointType.BPC,
                  PointType.HOMOCLINIC, PointType.HETEROCLINIC)
_GLOBAL_POINTS = (PointType.HOMOCLINIC, PointType.HETEROCLINIC)
_LOG_SPAN = 20.0  # period plots switch to a log y-axis above this max/min ratio


def branch_style(kind: str, stable: bool) -> str:
    """Key of :data:`PLOT_KEY` for a branch piece of ``kind`` (a :class:`BranchKind`)."""
    family = "periodic" if kind == BranchKind.PERIODIC else "equilibrium"
    return f"{'stable' if stable else 'unstable'}_{family}"


def stability_segments(x: np.ndarray, y: np.ndarray, stable: np.ndarray,
                       known: np.ndarray | None = None
                       ) -> list[tuple[np.ndarray, np.ndarray, bool]]:
    """Split a curve into runs of equal stability, ``[(x_i, y_i, stable_i), ...]`` in order.

    The first point of each new run (the switching point) also ends the previous run, so drawn
    pieces join without gaps. Points whose stability is not ``known`` (e.g. the first point of
    a periodic family, where AUTO printed no multipliers) have none of their own: each joins
    the run before it (leading ones the run after), so they never make a stub of their own;
    with no point known, ``stable`` is drawn as it is. Units are those of ``x`` and ``y``;
    empty input gives ``[]``.
    """
    x = np.asarray(x)
    y = np.asarray(y)
    stable = np.asarray(stable, dtype=bool)
    if not (x.shape == y.shape == stable.shape) or x.ndim != 1:
        raise ValueError(f"x, y and stable must be 1-D of equal length, got shapes "
                         f"{x.shape}, {y.shape}, {stable.shape}")
    if len(x) == 0:
        return []
    if known is not None and np.asarray(known, dtype=bool).any():
        known = np.asarray(known, dtype=bool)
        if known.shape != stable.shape:
            raise ValueError(f"known must have the shape of stable {stable.shape}, got "
                             f"{known.shape}")
        # the stability of the nearest known point before (the first known one for leading
        # unknown points)
        last_known = np.maximum.accumulate(np.where(known, np.arange(len(x)), -1))
        stable = stable[np.where(last_known >= 0, last_known, np.flatnonzero(known)[0])]
    starts = np.concatenate(([0], np.flatnonzero(stable[1:] != stable[:-1]) + 1))
    ends = np.append(starts[1:] + 1, len(x))  # inclusive of the next run's first point
    return [(x[a:b], y[a:b], bool(stable[a])) for a, b in zip(starts, ends, strict=True)]


def display_unit(unit: str, degrees: bool = True) -> tuple[float, str]:
    """(factor, unit) to show an SI quantity: rad -> deg (and rad/s -> deg/s) if ``degrees``."""
    if degrees and re.fullmatch(r"rad(/.*)?", unit):
        return float(np.degrees(1.0)), "deg" + unit[3:]
    return 1.0, unit


def axis_label(name: str, unit: str) -> str:
    """``"name [unit]"``, with ``[-]`` for dimensionless quantities (unit "" or "1")."""
    return f"{name} [{unit if unit not in ('', '1') else '-'}]"


def bifurcation_diagram(continuation: ContinuationResult, state: str = "theta",
                        which: Sequence[str] = ("max",), ax: Axes | None = None,
                        degrees: bool = True) -> Figure:
    """One-parameter bifurcation diagram: ``state`` against each branch's principal parameter.

    Equilibrium and periodic branches are drawn (other kinds, e.g. loci, are skipped) with
    y = max of ``state`` over the orbit (the state itself for equilibria), and for periodic
    branches also the min when "min" is in ``which``; line styles follow :data:`PLOT_KEY` by kind
    and stability. Special points get markers at (principal parameter, ``state`` value). Angle
    states are shown in degrees (rad -> deg, rad/s -> deg/s) unless ``degrees`` is False; the
    parameter keeps its SI unit. Draws on ``ax`` if given, else on a new figure; returns the
    figure. The legend lists only styles present; the title is the continuation's name.
    """
    which, branches = _checked_branches(continuation, state, which)
    if ax is None:
        ax = _new_figure().add_subplot()
    handles, labels = _draw_bifurcation(ax, continuation, branches, state, which, degrees)
    if handles:
        ax.legend(handles, labels, fontsize="small")
    ax.set_title(continuation.name)
    return ax.figure


def _checked_branches(continuation: ContinuationResult, state: str, which: Sequence[str]
                      ) -> tuple[tuple[str, ...], list[Branch]]:
    """``which`` as a tuple and the plotted branches; WhirlError if either argument is bad."""
    which = tuple(which)
    if not which or not set(which) <= {"max", "min"}:
        raise WhirlError(f"which must be a non-empty subset of ('max', 'min'), got {which}")
    branches = [b for b in continuation.branches if b.kind in _PLOTTED_KINDS]
    for branch in branches:
        if state not in branch.state_names:
            raise WhirlError(f"state {state!r} not on branch {branch.name!r} "
                             f"(states: {', '.join(branch.state_names)})")
    return which, branches


def _draw_bifurcation(ax: Axes, continuation: ContinuationResult, branches: list[Branch],
                      state: str, which: tuple[str, ...], degrees: bool
                      ) -> tuple[list, list[str]]:
    """Branches, special points and axis labels of a bifurcation diagram; legend entries."""
    first: dict[str, object] = {}  # style -> first artist drawn with it (legend handle)
    for branch in branches:
        _draw_branch(ax, branch, state, which, degrees, first)
    _draw_special_points(ax, continuation, branches, state, degrees, first)
    _label_axes(ax, continuation, branches, state, which, degrees)
    return ([first[key] for key in PLOT_KEY if key in first],
            [str(PLOT_KEY[key]["label"]) for key in PLOT_KEY if key in first])


def projections_figure(continuation: ContinuationResult, which: Sequence[str] = ("max",),
                       degrees: bool = True) -> Figure:
    """One bifurcation diagram per state on a grid of ceil(n/2) x 2 axes sharing the x-axis.

    The states are those common to every plotted (equilibrium or periodic) branch, in the order
    of the first; each panel is :func:`bifurcation_diagram` of one state (angles in deg, rates in
    deg/s unless ``degrees`` is False; ``which`` as there). Only the first panel has a legend and
    only the bottom panels an x label; the figure title is the continuation's name. Without
    plotted branches the figure has one empty axes.
    """
    states = _common_states(continuation)
    rows = max(1, -(-len(states) // 2))
    figure = _new_figure(figsize=(10.0, 3.2 * rows + 0.6), layout="constrained")
    if not states:
        figure.add_subplot().set_title(continuation.name)
        return figure
    axes = figure.subplots(rows, 2, sharex=True, squeeze=False).ravel()
    for k, (ax, state) in enumerate(zip(axes, states, strict=False)):
        bifurcation_diagram(continuation, state=state, which=which, ax=ax, degrees=degrees)
        ax.set_title("")
        if k > 0 and ax.get_legend() is not None:
            ax.get_legend().remove()
        if k < len(states) - 2:  # another panel below in the same column
            ax.set_xlabel("")
    for ax in axes[len(states):]:
        figure.delaxes(ax)
    if len(states) % 2 and len(states) > 1:  # lone last panel: label its neighbour's x
        axes[len(states) - 2].xaxis.set_tick_params(labelbottom=True)
        axes[len(states) - 2].set_xlabel(axes[len(states) - 1].get_xlabel())
    figure.suptitle(continuation.name)
    return figure


def _common_states(continuation: ContinuationResult) -> tuple[str, ...]:
    """States on every plotted branch, in the order of the first (``()`` without branches)."""
    branches = [b for b in continuation.branches if b.kind in _PLOTTED_KINDS]
    if not branches:
        return ()
    return tuple(s for s in branches[0].state_names if all(s in b.state_names for b in branches))


def period_plot(continuation: ContinuationResult) -> Figure:
    """Period [s] of every periodic branch against its principal parameter (SI unit).

    Lines follow :data:`PLOT_KEY` (stable solid blue, unstable dotted red) split as in
    :func:`bifurcation_diagram`. Markers: LPC, PD, TR, BPC on periodic branches at their period
    (the branch's period at the point's row if the point has none), Hopf points with a finite
    period (where periodic branches are born), and HOMOCLINIC/HETEROCLINIC at (their parameter
    estimate, the period at the last point of their branch). A "bracketed" global point also
    gets its bracket drawn as a horizontal error bar at the top of the data. The y-axis is
    logarithmic if the largest period exceeds 20 times the smallest. Without periodic branches
    the axes stay empty.
    """
    ax = _new_figure().add_subplot()
    periodic = [b for b in continuation.branches if b.is_periodic]
    first: dict[str, object] = {}
    for branch in periodic:
        x = branch.parameters[:, 0]
        for xs, ys, stable in stability_segments(x, branch.period, branch.stable,
                                                 branch.stability_known):
            _plot_styled(ax, xs, ys, branch_style(branch.kind, stable), first)
    periods = np.concatenate([b.period for b in periodic]) if periodic else np.array([])
    periods = periods[np.isfinite(periods) & (periods > 0)]
    points, brackets = _period_points(continuation, periodic)
    for style in PLOT_KEY:
        if style in points:
            xs, ys = np.array(points[style]).T
            _plot_styled(ax, xs, ys, style, first)
    handles = [first[key] for key in PLOT_KEY if key in first]
    labels = [str(PLOT_KEY[key]["label"]) for key in PLOT_KEY if key in first]
    if brackets and periods.size:
        top = float(np.max(periods))
        for low, high in brackets:
            bar = ax.errorbar([(low + high) / 2], [top], xerr=[(high - low) / 2], fmt="none",
                              ecolor=_BLACK, elinewidth=1.2, capsize=4, zorder=4,
                              label="_bracket")
        handles.append(bar)
        labels.append("bracket (global bifurcation)")
    if periods.size and periods.max() > _LOG_SPAN * periods.min():
        ax.set_yscale("log")
    if periodic:
        ax.set_xlabel(axis_label(periodic[0].parameter_names[0], periodic[0].parameter_units[0]))
    ax.set_ylabel(axis_label("period", "s"))
    if handles:
        ax.legend(handles, labels, fontsize="small")
    ax.set_title(f"{continuation.name}: period")
    return ax.figure


def _period_points(continuation: ContinuationResult, periodic: list[Branch]
                   ) -> tuple[dict[str, list[tuple[float, float]]], list[tuple[float, float]]]:
    """Marker positions by style, and the finite brackets of "bracketed" global points."""
    by_name = {b.name: b for b in continuation.branches}
    periodic_names = {b.name for b in periodic}
    x_name = periodic[0].parameter_names[0] if periodic else None
    points: dict[str, list[tuple[float, float]]] = {}
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
            if point.status == "bracketed" and bracket.shape == (2,) and np.isfinite(
                    bracket).all():
                brackets.append((float(bracket.min()), float(bracket.max())))
        else:
            period = float(point.period)
            if not np.isfinite(period) and 0 <= point.index < len(branch):
                period = float(branch.period[point.index])
        xy = (float(point.parameters[0]), period)
        if np.all(np.isfinite(xy)):
            points.setdefault(MARKER_STYLE[kind], []).append(xy)
    return points, brackets


def phase_plane(branch: Branch, labels: Sequence[int] | None = None, x: str = "theta",
                y: str = "psi", degrees: bool = True, ax: Axes | None = None) -> Figure:
    """Stored orbits of a periodic branch as closed curves of state ``y`` against state ``x``.

    All of ``branch.orbits`` if ``labels`` is None, else those with these AUTO labels (in the
    order given). Each curve is closed (its first point repeated at the end unless already
    equal), drawn solid if the branch is stable at the orbit's row, dotted if not and dashed
    where its stability is unknown, in the default colour cycle, and labelled
    ``"<parameter> = <value> (stable|unstable|stability unknown)"`` with the
    principal parameter (4 significant digits). Angles in degrees, rates in deg/s unless
    ``degrees`` is False; equal aspect when both axes have the same unit. Draws on ``ax`` if
    given, else on a new figure; returns the figure. The title is the branch's name.
    """
    if not branch.is_periodic:
        raise WhirlError(f"branch {branch.name!r} is {branch.kind}, not periodic: no orbits")
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
    ix, iy = branch.state_names.index(x), branch.state_names.index(y)
    fx, unit_x = display_unit(branch.state_units[ix], degrees)
    fy, unit_y = display_unit(branch.state_units[iy], degrees)
    if ax is None:
        ax = _new_figure().add_subplot()
    for orbit, colour in zip(orbits, _colours(), strict=False):
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
    if orbits:
        ax.legend(fontsize="small")
    ax.set_title(branch.name)
    return ax.figure


def _new_figure(**kwargs) -> Figure:
    """A Figure on an Agg canvas, outside pyplot (needs no display, no closing)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(**{"layout": "constrained", **kwargs})  # no clipped labels, no bbox pass
    FigureCanvasAgg(figure)
    return figure


def _plot_styled(ax: Axes, x: np.ndarray, y: np.ndarray, style: str, first: dict) -> None:
    """Plot with ``PLOT_KEY[style]``; remember the first artist of each style for the legend."""
    kwargs = dict(PLOT_KEY[style])
    kwargs["label"] = "_" + str(kwargs["label"])  # legend is assembled from ``first``
    if "marker" in kwargs:
        kwargs.update(linestyle="none", markersize=_MARKER_SIZE, zorder=3)
    (line,) = ax.plot(x, y, **kwargs)
    first.setdefault(style, line)


def _draw_branch(ax: Axes, branch: Branch, state: str, which: tuple[str, ...], degrees: bool,
                 first: dict) -> None:
    """Draw one branch's max (and min, periodic only) curves, split by stability."""
    factor, _ = display_unit(branch.state_units[branch.state_names.index(state)], degrees)
    x = branch.parameters[:, 0]
    tables = [w for w in ("max", "min") if w in which] if branch.is_periodic else [which[0]]
    for table in tables:
        y = branch.state(state, table) * factor
        for xs, ys, stable in stability_segments(x, y, branch.stable,
                                                 branch.stability_known):
            _plot_styled(ax, xs, ys, branch_style(branch.kind, stable), first)


def _draw_special_points(ax: Axes, continuation: ContinuationResult, branches: list[Branch],
                         state: str, degrees: bool, first: dict) -> None:
    """Markers for special points, one artist per marker style.

    A point's state is read by the state names of its branch (or of the first plotted branch if
    its branch is not among them); points not on the x-axis parameter are skipped.
    """
    by_name = {b.name: b for b in branches}
    x_name = branches[0].parameter_names[0] if branches else None
    points: dict[str, list[tuple[float, float]]] = {}
    for point in continuation.special_points:
        style = MARKER_STYLE.get(_point_type(point.point_type))
        branch = by_name.get(point.branch, branches[0] if branches else None)
        if style is None or branch is None or point.parameter_names[0] != x_name:
            continue
        index = branch.state_names.index(state)
        factor, _ = display_unit(branch.state_units[index], degrees)
        xy = (float(point.parameters[0]), float(point.state[index]) * factor)
        if np.all(np.isfinite(xy)):
            points.setdefault(style, []).append(xy)
    for style in PLOT_KEY:
        if style in points:
            xs, ys = np.array(points[style]).T
            _plot_styled(ax, xs, ys, style, first)


def _point_type(code: int) -> PointType | None:
    try:
        return PointType(int(code))
    except ValueError:
        return None


def _label_axes(ax: Axes, continuation: ContinuationResult, branches: list[Branch], state: str,
                which: tuple[str, ...], degrees: bool) -> None:
    """Axis labels with units from the first plotted branch (nothing if there is none)."""
    if not branches:
        return
    ref = branches[0]
    ax.set_xlabel(axis_label(ref.parameter_names[0], ref.parameter_units[0]))
    _, unit = display_unit(ref.state_units[ref.state_names.index(state)], degrees)
    extent = ", ".join(which) if any(b.is_periodic for b in branches) else ""
    ax.set_ylabel(axis_label(f"{state} ({extent})" if extent else state, unit))


def linear_sweep_plot(sweep: LinearSweep) -> Figure:
    """Frequency [rad/s] (top) and damping ratio [-] (bottom) of each mode vs the parameter.

    One line per column of ``sweep.eigenvalues``, drawn only where Im(lambda) > 0 so each
    conjugate pair appears once (real eigenvalues are not drawn). Lines are labelled with their
    whirl direction ("BW"/"FW", numbered if repeated); the damping panel has a zero line.
    """
    figure = _new_figure(figsize=(6.4, 6.4))
    ax_freq, ax_damp = figure.subplots(2, 1, sharex=True)
    for (column, label), colour in zip(_mode_labels(sweep), _colours(), strict=False):
        upper = sweep.eigenvalues[:, column].imag > 0
        freq = np.where(upper, sweep.frequency[:, column], np.nan)
        damp = np.where(upper, sweep.damping_ratio[:, column], np.nan)
        ax_freq.plot(sweep.values, freq, color=colour, label=label)
        ax_damp.plot(sweep.values, damp, color=colour, label=label)
    ax_damp.axhline(0.0, color="black", linewidth=0.8, label="_zero")
    ax_freq.set_ylabel(axis_label("frequency", "rad/s"))
    ax_damp.set_ylabel(axis_label("damping ratio", ""))
    ax_damp.set_xlabel(axis_label(sweep.parameter, sweep.unit))
    if ax_freq.get_lines():
        ax_freq.legend(fontsize="small")
    ax_freq.set_title(f"linear analysis vs {sweep.parameter}")
    return figure


def _mode_labels(sweep: LinearSweep) -> list[tuple[int, str]]:
    """(column, label) of the columns with Im(lambda) > 0 somewhere; label = majority whirl."""
    modes = []
    for column in range(sweep.eigenvalues.shape[1]):
        upper = sweep.eigenvalues[:, column].imag > 0
        if not upper.any():
            continue
        names, counts = np.unique(np.asarray(sweep.whirl)[upper, column].astype(str),
                                  return_counts=True)
        modes.append((column, str(names[np.argmax(counts)])))
    totals = {label: sum(1 for _, other in modes if other == label) for _, label in modes}
    seen: dict[str, int] = {}
    labelled = []
    for column, label in modes:
        seen[label] = seen.get(label, 0) + 1
        labelled.append((column, f"{label} {seen[label]}" if totals[label] > 1 else label))
    return labelled


def _colours() -> Iterator[str]:
    """Endless cycle of the default matplotlib line colours."""
    from matplotlib import rcParams

    return itertools.cycle(rcParams["axes.prop_cycle"].by_key().get("color", ["C0"]))


def boundary_plot(boundary: Boundary | None, grid: LinearGrid | None,
                  cases: Sequence[float] = (), ax: Axes | None = None) -> Figure:
    """Stability map in two parameters (thesis figures 3.13, 3.15, 3.28, 3.29).

    x is the first parameter of ``boundary`` (or ``grid.x_parameter``), y the second, both in
    their own (SI) units. Drawn, styled after :data:`BOUNDARY_KEY`:

    * from ``grid``: the linearly unstable region (``max_real`` > 0) shaded light grey and the
      linear zero contour thin black, solid where the critical eigenvalue is complex (flutter),
      dashed where it is real (divergence);
    * from ``boundary``: its loci (Hopf solid dark blue, branch point dashed black, fold
      dash-dot grey, fold of cycles solid orange; other kinds are not drawn) and the unsafe
      (overhang) region, its polygons filled red;
    * a thin dotted horizontal line at each value of ``cases`` (e.g. ``boundary.slices``),
      labelled "case 1", "case 2", ... just right of the axes (labels only for lines within
      the y limits, nudged up where they would overlap).

    The legend lists only what is drawn. Axis limits are the grid's extent, else the extent of
    the loci (or, without loci, of the polygons) plus a 2 % margin, else matplotlib's. A grid
    over the same two parameters in the other order is transposed; over other parameters it is
    a :class:`WhirlError`, as is passing neither. Title: ``boundary.name`` (else "linear
    stability"). Draws on ``ax`` if given, else on a new figure; returns the figure.
    """
    if boundary is None and grid is None:
        raise WhirlError("boundary_plot needs a boundary, a linear grid or both")
    if boundary is not None and grid is not None:
        oriented = _oriented_grid(grid, boundary.parameter_names)
        if oriented is None:
            raise WhirlError(f"linear grid over ({grid.x_parameter}, {grid.y_parameter}) does "
                             f"not match boundary {boundary.name!r} over "
                             f"({', '.join(boundary.parameter_names)})")
        grid = oriented
    if ax is None:
        ax = _new_figure().add_subplot()
    first: dict[str, object] = {}
    if grid is not None:
        _draw_grid(ax, grid, first)
    if boundary is not None:
        _draw_loci(ax, boundary, first)
        for polygon in boundary.polygons:
            polygon = np.asarray(polygon, dtype=float)
            if len(polygon) >= 3:
                style = dict(BOUNDARY_KEY["unsafe"], label="_unsafe")
                (patch,) = ax.fill(polygon[:, 0], polygon[:, 1], **style, zorder=2)
                first.setdefault("unsafe", patch)
    _set_map_limits(ax, boundary, grid)
    _draw_cases(ax, cases)
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
    ax.set_title(boundary.name if boundary is not None else "linear stability")
    return ax.figure


def _oriented_grid(grid: LinearGrid, names: Sequence[str]) -> LinearGrid | None:
    """``grid`` with x = ``names[0]`` and y = ``names[1]`` (transposed if needed), else None."""
    if (grid.x_parameter, grid.y_parameter) == tuple(names):
        return grid
    if (grid.y_parameter, grid.x_parameter) == tuple(names):
        return LinearGrid(grid.y_parameter, grid.x_parameter, grid.y_unit, grid.x_unit,
                          grid.y, grid.x, np.asarray(grid.max_real).T,
                          np.asarray(grid.oscillatory).T,
                          tuple(np.asarray(line)[:, ::-1] for line in grid.flutter),
                          tuple(np.asarray(line)[:, ::-1] for line in grid.divergence))
    return None


def _draw_grid(ax: Axes, grid: LinearGrid, first: dict) -> None:
    """Shade max_real > 0 (contourf, levels [0, inf]); draw the zero contour by kind."""
    max_real = np.ma.masked_invalid(np.asarray(grid.max_real, dtype=float))
    if np.ma.any(max_real > 0):
        style = BOUNDARY_KEY["linearly_unstable"]
        ax.contourf(grid.x, grid.y, max_real, levels=[0.0, np.inf], colors=[style["color"]],
                    zorder=0)
        first["linearly_unstable"] = _patch_proxy(style)
    for key, lines in (("linear_flutter", grid.flutter), ("linear_divergence", grid.divergence)):
        for line in lines:
            _plot_polyline(ax, line, key, first, zorder=1)


def _patch_proxy(style: dict[str, object]):
    """A legend handle for a filled area of ``style``'s colour (and alpha)."""
    from matplotlib.patches import Patch

    return Patch(facecolor=style["color"], alpha=style.get("alpha"), label=style["label"])


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
    """Grid extent; else loci extent (polygons if no loci) with a margin; else leave as is."""
    if grid is not None and len(grid.x) and len(grid.y):
        ax.set_xlim(float(np.min(grid.x)), float(np.max(grid.x)))
        ax.set_ylim(float(np.min(grid.y)), float(np.max(grid.y)))
        return
    if boundary is None:
        return
    curves = [np.asarray(c, dtype=float) for kind, c in boundary.loci.values()
              if kind in _LOCUS_KINDS]
    if not any(c.ndim == 2 and len(c) >= 2 for c in curves):
        curves = [np.asarray(p, dtype=float) for p in boundary.polygons]
    points = [c for c in curves if c.ndim == 2 and c.shape[1] == 2 and len(c)]
    if not points:
        return
    xy = np.concatenate(points)
    xy = xy[np.isfinite(xy).all(axis=1)]
    if not len(xy):
        return
    for setter, low, high in ((ax.set_xlim, xy[:, 0].min(), xy[:, 0].max()),
                              (ax.set_ylim, xy[:, 1].min(), xy[:, 1].max())):
        pad = _LIMIT_MARGIN * (high - low)
        if pad > 0:
            setter(float(low - pad), float(high + pad))


def _draw_cases(ax: Axes, cases: Sequence[float]) -> None:
    """Dotted horizontal lines at the case values, labelled "case k" right of the axes."""
    for k, value in enumerate(cases, 1):
        ax.axhline(float(value), color=_BLACK, linestyle=":", linewidth=0.8, zorder=1,
                   label=f"_case {k}")
    bottom, top = ax.get_ylim()
    low, high = sorted((bottom, top))
    shown = sorted(((float(v) - bottom) / (top - bottom) if top != bottom else 0.5, k)
                   for k, v in enumerate(cases, 1) if low <= float(v) <= high)
    position = -np.inf
    for fraction, k in shown:  # in axes fractions, pushed up to keep close labels apart
        position = max(fraction, position + _CASE_LABEL_GAP)
        ax.text(1.01, position, f"case {k}", transform=ax.transAxes, ha="left", va="center",
                fontsize="small")


def slice_continuation(continuation: ContinuationResult, index: int) -> ContinuationResult:
    """The one-parameter continuation of slice ``index`` of a two-parameter continuation.

    Its branches are those named ``slice_<index>.<branch>``, renamed ``<branch>``, and its
    special points those on them (branch renamed likewise). Named
    ``<continuation>.slice_<index>``, kind "one-parameter"."""
    prefix = f"slice_{index}."
    branches = tuple(replace(b, name=b.name[len(prefix):]) for b in continuation.branches
                     if b.name.startswith(prefix))
    points = tuple(replace(p, branch=p.branch[len(prefix):]) for p in continuation.special_points
                   if p.branch.startswith(prefix))
    return ContinuationResult(f"{continuation.name}.slice_{index}", "one-parameter", branches,
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
                     slice_value: float, state: str = "theta", which: Sequence[str] = ("max",),
                     ax: Axes | None = None, degrees: bool = True) -> Figure:
    """Bifurcation diagram of one slice with its unsafe (overhang) intervals shaded.

    For a two-parameter ``continuation`` the diagram is :func:`bifurcation_diagram` of
    :func:`slice_continuation` at the index of ``slice_value`` in ``boundary.slices`` (a
    ``boundary`` is then required); a one-parameter continuation is drawn as it is. Every
    interval of ``boundary.intervals`` on this slice (``slice_value`` equal within 1e-12) is a
    red vertical band (alpha 0.25) from ``lower`` to ``upper``, with one legend entry
    "unsafe (overhang)". ``state``, ``which``, ``degrees`` and ``ax`` as in
    :func:`bifurcation_diagram`. Title: ``"<continuation>: <second parameter> = <value>"``
    (just the continuation's name without a boundary). Returns the figure.
    """
    if continuation.kind == "two-parameter":
        if boundary is None:
            raise WhirlError(f"continuation {continuation.name!r} is two-parameter: an "
                             "overhang diagram needs its boundary to find the slice")
        diagram = slice_continuation(continuation, slice_index(boundary, slice_value))
    else:
        diagram = continuation
    which, branches = _checked_branches(diagram, state, which)
    if ax is None:
        ax = _new_figure().add_subplot()
    handles, labels = _draw_bifurcation(ax, diagram, branches, state, which, degrees)
    band = None
    intervals = () if boundary is None else boundary.intervals
    for interval in intervals:
        if abs(float(interval.slice_value) - float(slice_value)) <= _SLICE_TOLERANCE:
            span = ax.axvspan(float(interval.lower), float(interval.upper), color="red",
                              alpha=_BAND_ALPHA, linewidth=0, zorder=0, label="_unsafe")
            band = band or span
    if band is not None:
        handles.append(band)
        labels.append(_UNSAFE_LABEL)
    if handles:
        ax.legend(handles, labels, fontsize="small")
    title = continuation.name
    if boundary is not None:
        title += f": {boundary.parameter_names[1]} = {float(slice_value):g}"
    ax.set_title(title)
    return ax.figure


def save_study_plots(result: StudyResult, kinds: tuple[str, ...], out_dir: Path, stem: str,
                     state: str = "theta", dpi: int = 150) -> list[Path]:
    """Write a study's figures as PNG files into ``out_dir``; return the paths, sorted.

    ``kinds`` (any of :data:`PLOT_KINDS`):

    * "bifurcation" -> ``<stem>_<continuation>_bifurcation.png`` per one-parameter continuation
      (``state`` vs the principal parameter, angles in degrees; the first state if the branches
      have no ``state``);
    * "projections" -> ``<stem>_<continuation>_projections.png`` per one-parameter continuation
      (:func:`projections_figure`);
    * "period" -> ``<stem>_<continuation>_period.png`` per continuation with a periodic branch
      (:func:`period_plot`);
    * "phase" -> ``<stem>_<continuation>_<branch>_phase.png`` per periodic branch with stored
      orbits (:func:`phase_plane`, psi vs theta, or the branch's first two states);
    * "linear" -> ``<stem>_linear_<parameter>.png`` per linear sweep;
    * "boundary" -> per boundary of ``result.boundaries``: ``<stem>_<boundary>_boundary.png``
      (:func:`boundary_plot` with ``result.linear_grid`` if it is over the same parameters, the
      slices as cases) and ``<stem>_<boundary>_slice_<k>_overhang.png`` per slice k
      (:func:`overhang_diagram` of the two-parameter continuation named like the boundary, or
      of no branches if there is none); without boundaries but with a linear grid,
      ``<stem>_linear_grid.png`` (the grid alone).

    Names are made filesystem-safe; repeats get ``_2``, ``_3``, ... (:func:`plot_names`).
    Each file is rendered in memory and published complete or not at all (an existing file
    of the same name is replaced). ``whirl run`` and ``whirl sweep`` publish a study's plots
    together with its HDF5 file instead (:mod:`whirl_cli.output.study_files`).
    """
    out_dir = Path(out_dir)
    rendered = render_study_plots(result, kinds, stem, state, dpi)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create plot directory {out_dir}: {exc}") from exc
    from .output.atomic import publish

    return sorted(publish(data, out_dir / name, overwrite=True, what="the plot")
                  for name, data in rendered)


def plot_names(result: StudyResult, kinds: tuple[str, ...], stem: str,
               state: str = "theta") -> list[str]:
    """The file names :func:`save_study_plots` writes for ``result`` (in drawing order),
    found without drawing anything."""
    return [name for name, _ in _named_jobs(result, kinds, stem, state)]


def render_study_plots(result: StudyResult, kinds: tuple[str, ...], stem: str,
                       state: str = "theta", dpi: int = 150) -> list[tuple[str, bytes]]:
    """(file name, PNG bytes) of every figure of :func:`save_study_plots`, rendered in
    memory; nothing is written."""
    return [(name, _png(make(), dpi)) for name, make in _named_jobs(result, kinds, stem, state)]


def _named_jobs(result: StudyResult, kinds: tuple[str, ...], stem: str, state: str):
    """(unique filesystem-safe file name, figure factory) pairs of the requested kinds."""
    unknown = set(kinds) - set(PLOT_KINDS)
    if unknown:
        raise WhirlError(f"unknown plot kind(s) {sorted(unknown)}; choose from {PLOT_KINDS}")
    taken: list[Path] = []
    jobs = []
    for name, make in _figure_jobs(result, kinds, stem, state):
        path = _unique(Path(_safe_name(name)), taken)
        taken.append(path)
        jobs.append((path.name, make))
    return jobs


def _figure_jobs(result: StudyResult, kinds: tuple[str, ...], stem: str, state: str):
    """(file name, figure factory) pairs for the requested kinds, in a stable order."""
    jobs = []
    if "bifurcation" in kinds:
        for continuation in result.continuations:
            if continuation.kind == "one-parameter":
                chosen = _state_for(continuation, state)
                jobs.append((f"{stem}_{continuation.name}_bifurcation.png",
                             lambda c=continuation, s=chosen: bifurcation_diagram(c, s)))
    if "projections" in kinds:
        for continuation in result.continuations:
            if continuation.kind == "one-parameter":
                jobs.append((f"{stem}_{continuation.name}_projections.png",
                             lambda c=continuation: projections_figure(c)))
    if "period" in kinds:
        for continuation in result.continuations:
            if any(b.is_periodic for b in continuation.branches):
                jobs.append((f"{stem}_{continuation.name}_period.png",
                             lambda c=continuation: period_plot(c)))
    if "phase" in kinds:
        for continuation in result.continuations:
            for branch in continuation.branches:
                if branch.is_periodic and branch.orbits and len(branch.state_names) >= 2:
                    x, y = _phase_states(branch)
                    jobs.append((f"{stem}_{continuation.name}_{branch.name}_phase.png",
                                 lambda b=branch, x=x, y=y: phase_plane(b, x=x, y=y)))
    if "linear" in kinds:
        for sweep in result.linear_sweeps:
            jobs.append((f"{stem}_linear_{sweep.parameter}.png",
                         lambda s=sweep: linear_sweep_plot(s)))
    if "boundary" in kinds:
        jobs += _boundary_jobs(result, stem, state)
    return jobs


def _boundary_jobs(result: StudyResult, stem: str, state: str):
    """(file name, figure factory) pairs of the "boundary" kind."""
    grid = result.linear_grid
    if not result.boundaries:
        if grid is None:
            return []
        return [(f"{stem}_linear_grid.png", lambda: boundary_plot(None, grid))]
    jobs = []
    for boundary in result.boundaries:
        matched = None if grid is None else _oriented_grid(grid, boundary.parameter_names)
        jobs.append((f"{stem}_{boundary.name}_boundary.png",
                     lambda b=boundary, g=matched: boundary_plot(b, g, cases=b.slices)))
        continuation = next((c for c in result.continuations if c.name == boundary.name
                             and c.kind == "two-parameter"),
                            ContinuationResult(boundary.name, "one-parameter", (), ()))
        for k, value in enumerate(boundary.slices):
            chosen = (_state_for(slice_continuation(continuation, k), state)
                      if continuation.kind == "two-parameter" else state)
            jobs.append((f"{stem}_{boundary.name}_slice_{k}_overhang.png",
                         lambda c=continuation, b=boundary, v=value, s=chosen:
                         overhang_diagram(c, b, v, state=s)))
    return jobs


def _phase_states(branch: Branch) -> tuple[str, str]:
    """("theta", "psi") if the branch has both, else its first two states."""
    if {"theta", "psi"} <= set(branch.state_names):
        return "theta", "psi"
    return branch.state_names[0], branch.state_names[1]


def _state_for(continuation: ContinuationResult, state: str) -> str:
    """``state`` if every plotted branch has it, else the first branch's first state."""
    branches = [b for b in continuation.branches if b.kind in _PLOTTED_KINDS]
    if not branches or all(state in b.state_names for b in branches):
        return state
    return branches[0].state_names[0]


def _safe_name(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._+-]", "_", name)


def _unique(path: Path, taken: list[Path]) -> Path:
    candidate, n = path, 1
    while candidate in taken:
        n += 1
        candidate = path.with_name(f"{path.stem}_{n}{path.suffix}")
    return candidate


def _png(figure: Figure, dpi: int) -> bytes:
    """``figure`` rendered as PNG bytes (the figure is cleared afterwards)."""
    buffer = io.BytesIO()
    try:
        figure.savefig(buffer, format="png", dpi=dpi)
    finally:
        figure.clear()
    return buffer.getvalue()
