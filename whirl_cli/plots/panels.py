"""Any plot kind drawn onto a given matplotlib Axes: the panels of a sheet (``whirl figures``)
and of a notebook.

:func:`draw` draws one result's figure of one kind into an Axes (a kind with several panels
of its own, ``linear`` and ``projections``, splits that Axes' place in its figure);
:func:`draw_overlay` draws several results' bifurcation diagrams into one Axes, one colour per
result, labelled by what differs between them (:func:`differing_labels`). What a kind picks
from a result (which continuation, branch, sweep, slice) is said by :class:`PanelChoice`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from ..errors import WhirlError
from ..results import Branch, ContinuationResult, LinearSweep, PointType, StudyResult
from .captions import Fixed, captions
from .diagrams import (
    _checked_branches,
    _draw_special_points,
    _label_axes,
    bifurcation_diagram,
    period_plot,
    phase_plane,
    projections_figure,
)
from .freeplay import amplitude_diagram, has_amplitudes
from .key import PLOT_KEY, _colours, display_unit, stability_curves
from .linear import damping_multiples_plot, linear_sweep_plot, root_locus_plot
from .maps import _oriented_grid, boundary_plot, overhang_diagram

if TYPE_CHECKING:
    from matplotlib.axes import Axes

_GLOBAL_TYPES = (PointType.HOMOCLINIC, PointType.HETEROCLINIC)


@dataclass(frozen=True)
class PanelChoice:
    """What a panel takes from its result; None everywhere: the first that fits.

    ``continuation``: a continuation's name; ``branch``: a periodic branch's name (``phase``);
    ``state``: the state drawn (``bifurcation``, ``overhang``; a phase plane's y, x being the
    first state); ``sweep``: a linear sweep's parameter; ``slice``: a boundary slice index
    from 0 (``overhang``); ``orbits``: AUTO labels of the orbits a phase plane draws;
    ``simulation``: a simulation's name (``time_history``, ``hub_path``); ``hz``:
    frequencies in Hz; ``title``: replaces the study's title; ``cuts``: parameter values at
    which a ``phase`` panel draws every solution (:mod:`whirl_cli.plots.cuts`) and a
    ``bifurcation`` panel draws lines."""

    continuation: str | None = None
    branch: str | None = None
    state: str | None = None
    sweep: str | None = None
    slice: int | None = None
    orbits: tuple[int, ...] | None = None
    simulation: str | None = None
    hz: bool = False
    title: str | None = None
    cuts: tuple[float, ...] | None = None


def draw(result: StudyResult, kind: str, ax: Axes, choice: PanelChoice = PanelChoice()
         ) -> list[Axes]:
    """Draw ``result``'s figure of ``kind`` (:data:`PANEL_KINDS`) onto ``ax``; return the
    axes drawn on (``linear``, ``projections``, ``damping_multiples`` and ``time_history``
    replace ``ax`` by their own panels in its place). Titles name the study's fixed
    parameters (not the study: a figure's caption says what it shows) unless
    ``choice.title`` is set. A result without what the kind needs is a :class:`WhirlError`
    saying what is missing."""
    panel = _PANELS.get(kind)
    if panel is None:
        raise WhirlError(f"unknown panel kind {kind!r}; choose from {', '.join(PANEL_KINDS)}")
    return panel(result, ax, choice, replace(captions(result), named=False))


def _continuation_title(continuation: ContinuationResult, choice: PanelChoice, caption
                        ) -> str:
    """``choice.title``, else the study's title over what ``continuation`` does not vary."""
    if choice.title is not None:
        return choice.title
    varied = {n for b in continuation.branches for n in b.parameter_names}
    if continuation.explorations:
        varied.add(continuation.explorations[0].parameter)
    return caption.title(varied)


def _bifurcation_panel(result, ax, choice, caption) -> list[Axes]:
    continuation = pick_continuation(result, choice.continuation, "bifurcation")
    bifurcation_diagram(continuation, choice.state, ax=ax,
                        title=_continuation_title(continuation, choice, caption))
    if choice.cuts:
        from .cuts import mark_cuts

        mark_cuts(ax, choice.cuts)
    return [ax]


def _projections_panel(result, ax, choice, caption) -> list[Axes]:
    continuation = pick_continuation(result, choice.continuation, "projections")
    title = _continuation_title(continuation, choice, caption)
    return _replaced(ax, lambda region: projections_figure(continuation, title=title,
                                                           region=region))


def _period_panel(result, ax, choice, caption) -> list[Axes]:
    continuation = pick_continuation(result, choice.continuation, "period")
    period_plot(continuation, title=_continuation_title(continuation, choice, caption), ax=ax)
    return [ax]


def _blowup_panel(result, ax, choice, caption) -> list[Axes]:
    from .blowup import blowup_plot

    continuation = pick_continuation(result, choice.continuation, "blowup")
    blowup_plot(continuation, branch=choice.branch, ax=ax,
                title=_continuation_title(continuation, choice, caption))
    return [ax]


def _amplitude_panel(result, ax, choice, caption) -> list[Axes]:
    continuation = pick_continuation(result, choice.continuation, "amplitude")
    amplitude_diagram(continuation, ax=ax)
    ax.set_title(_continuation_title(continuation, choice, caption))
    return [ax]


def _poincare_panel(result, ax, choice, caption) -> list[Axes]:
    from .motion import poincare_plot

    continuation = pick_continuation(result, choice.continuation, "poincare")
    poincare_plot(continuation, ax=ax, title=_continuation_title(continuation, choice, caption))
    return [ax]


def _spectrum_panel(result, ax, choice, caption) -> list[Axes]:
    from .motion import spectrum_plot

    continuation = pick_continuation(result, choice.continuation, "spectrum")
    spectrum_plot(continuation, ax=ax, title=_continuation_title(continuation, choice, caption))
    return [ax]


def _orbit_diagram_panel(result, ax, choice, caption) -> list[Axes]:
    from .motion import orbit_diagram

    continuation = pick_continuation(result, choice.continuation, "orbit_diagram")
    orbit_diagram(continuation, choice.state, ax=ax,
                  title=_continuation_title(continuation, choice, caption))
    return [ax]


def _phase_panel(result, ax, choice, caption) -> list[Axes]:
    if choice.cuts:
        from .cuts import phase_cuts

        continuation = pick_continuation(result, choice.continuation, "period")
        return _replaced(ax, lambda region: phase_cuts(continuation, choice.cuts, region))
    branch = _pick_branch(result, choice)
    labels = list(choice.orbits) if choice.orbits is not None else None
    if labels is None:
        from .files import phase_labels

        labels = phase_labels(branch)
    phase_plane(branch, labels=labels, y=choice.state, ax=ax,
                title=caption.title(branch.parameter_names) if choice.title is None
                else choice.title)
    return [ax]


def _linear_panel(result, ax, choice, caption) -> list[Axes]:
    sweep = _pick_sweep(result, choice.sweep)
    title = caption.title({sweep.parameter}) if choice.title is None else choice.title
    return _replaced(ax, lambda region: linear_sweep_plot(
        sweep, hz=choice.hz, title=title,
        axes=tuple(region.subgridspec(2, 1).subplots(sharex=True))))


def _root_locus_panel(result, ax, choice, caption) -> list[Axes]:
    sweep = _pick_sweep(result, choice.sweep)
    root_locus_plot(sweep, title=caption.title({sweep.parameter}) if choice.title is None
                    else choice.title, ax=ax)
    return [ax]


def _multiples_panel(result, ax, choice, caption) -> list[Axes]:
    return _replaced(ax, lambda region: _draw_multiples(result, region, choice, caption))


def _simulation_panel(kind: str):
    """The panel of ``time_history`` or ``hub_path``."""
    return lambda result, ax, choice, caption: _draw_simulation(result, kind, ax, choice,
                                                                caption)


def _map_panel(kind: str):
    """The panel of ``boundary`` or ``overhang``."""
    return lambda result, ax, choice, caption: _draw_map(result, kind, ax, choice, caption)


def _law_panel(result: StudyResult, ax: Axes, choice: PanelChoice, caption=None
               ) -> list[Axes]:
    """The ``law`` kind: the nonlinear law on the dof ``choice.state`` (None: the first)."""
    from .laws import law_plot, nonlinear_laws

    found = [c for c in nonlinear_laws(result) if choice.state in (None, c.dof)]
    if not found:
        raise WhirlError(f"{result.study_name}: no nonlinear stiffness law"
                         + (f" on {choice.state!r}" if choice.state else ""))
    law_plot(found[0], ax=ax, title=choice.title)
    return [ax]


def _draw_simulation(result: StudyResult, kind: str, ax: Axes, choice: PanelChoice, caption
                     ) -> list[Axes]:
    """The ``time_history`` (one panel per dof, in ``ax``'s place) and ``hub_path`` kinds of
    the simulation ``choice.simulation`` (None: the first)."""
    from .simulations import hub_path, time_history

    found = [s for s in result.simulations if choice.simulation in (None, s.name)]
    if not found:
        have = ", ".join(s.name for s in result.simulations) or "none"
        raise WhirlError(f"{result.study_name}: no simulation"
                         + (f" {choice.simulation!r}" if choice.simulation else "")
                         + f" (simulations: {have})")
    simulation = found[0]
    title = choice.title or caption.simulation_title(simulation)
    if kind == "hub_path":
        hub_path(simulation, ax=ax, title=title)
        return [ax]
    if choice.state is not None:
        time_history(simulation, states=[choice.state], axes=ax, title=title)
        return [ax]
    dofs = len(simulation.dof_names)
    return _replaced(ax, lambda region: time_history(
        simulation, axes=list(region.subgridspec(dofs, 1).subplots(sharex=True, squeeze=False)
                              [:, 0]), title=title))


def _draw_multiples(result: StudyResult, region, choice: PanelChoice, caption,
                    axes=None) -> None:
    """The ``damping_multiples`` kind (every sweep with a non-zero datum, or ``choice.sweep``)
    into ``region`` (or onto ``axes``, damping and frequency)."""
    from .files import _datums, _multiple_sweeps

    sweeps = [s for s in _multiple_sweeps(result) if choice.sweep in (None, s.parameter)]
    if not sweeps:
        raise WhirlError(f"{result.study_name}: no linear sweep with a non-zero datum"
                         + (f" of {choice.sweep!r}" if choice.sweep else ""))
    if axes is None:
        axes = tuple(region.subgridspec(2, 1).subplots(sharex=True))
    title = choice.title or caption.title({s.parameter for s in sweeps})
    damping_multiples_plot(sweeps, _datums(result), hz=choice.hz, title=title, axes=axes)


def _draw_map(result: StudyResult, kind: str, ax: Axes, choice: PanelChoice, caption
              ) -> list[Axes]:
    """The ``boundary`` and ``overhang`` kinds."""
    grid = result.linear_grid
    if not result.boundaries:
        if kind == "boundary" and grid is not None:
            boundary_plot(None, grid, ax=ax, title=choice.title or caption.title(
                {grid.x_parameter, grid.y_parameter}))
            return [ax]
        raise WhirlError(f"{result.study_name}: no stability boundary (a two-parameter "
                         "continuation)" + (" and no linear grid" if kind == "boundary" else ""))
    names = [b.name for b in result.boundaries]
    wanted = choice.continuation or names[0]
    if wanted not in names:
        raise WhirlError(f"{result.study_name}: no boundary {wanted!r} (boundaries: "
                         f"{', '.join(names)})")
    boundary = result.boundaries[names.index(wanted)]
    if kind == "boundary":
        matched = None if grid is None else _oriented_grid(grid, boundary.parameter_names)
        boundary_plot(boundary, matched, cases=boundary.slices,
                      case_labels=caption.case_labels(boundary), ax=ax,
                      title=choice.title or caption.title(boundary.parameter_names))
        return [ax]
    k = 0 if choice.slice is None else choice.slice
    if not 0 <= k < len(boundary.slices):
        raise WhirlError(f"{result.study_name}: boundary {boundary.name!r} has slices 0 to "
                         f"{len(boundary.slices) - 1}, not {k}")
    value = boundary.slices[k]
    continuation = next((c for c in result.continuations if c.name == boundary.name), None)
    if continuation is None:
        raise WhirlError(f"{result.study_name}: no continuation {boundary.name!r} for the "
                         "overhang diagram")
    from .files import _slice_title

    title = choice.title or _slice_title(caption, boundary, k, value)
    overhang_diagram(continuation, boundary, value, state=choice.state, ax=ax, title=title)
    return [ax]


def _replaced(ax: Axes, make) -> list[Axes]:
    """Remove ``ax`` and let ``make(region)`` draw into its place; the new axes."""
    figure, region = ax.figure, ax.get_subplotspec()
    before = set(figure.axes)
    ax.remove()
    make(region)
    return [a for a in figure.axes if a not in before]


def pick_continuation(result: StudyResult, name: str | None, kind: str = "bifurcation"
                      ) -> ContinuationResult:
    """The one-parameter continuation named ``name`` (None: the first one that has what
    ``kind`` draws: periodic branches for ``period``, freeplay amplitudes for ``amplitude``)."""
    one = [c for c in result.continuations if c.kind == "one-parameter"]
    if name is not None:
        found = [c for c in one if c.name == name]
        if not found:
            raise WhirlError(f"{result.study_name}: no one-parameter continuation {name!r} "
                             f"(continuations: {', '.join(c.name for c in one) or 'none'})")
        return found[0]
    explored = lambda c: bool(c.explorations)  # noqa: E731
    blowup = lambda c: any(p.point_type in _GLOBAL_TYPES for p in c.special_points)  # noqa: E731
    fits = {"period": lambda c: any(b.is_periodic for b in c.branches),
            "amplitude": has_amplitudes, "poincare": explored, "spectrum": explored,
            "orbit_diagram": explored, "blowup": blowup}.get(kind, lambda c: True)
    found = [c for c in one if fits(c)]
    if not found:
        need = {"period": "periodic branch", "amplitude": "freeplay amplitudes",
                "poincare": "explored values", "spectrum": "explored values",
                "orbit_diagram": "explored values",
                "blowup": "periodic family ending in a global bifurcation"}.get(
            kind, "one-parameter continuation")
        raise WhirlError(f"{result.study_name}: nothing to draw as {kind}: no {need}")
    return found[0]


def _pick_branch(result: StudyResult, choice: PanelChoice) -> Branch:
    """The periodic branch with stored orbits named ``choice.branch`` (None: the first)."""
    candidates = [b for c in result.continuations
                  if choice.continuation in (None, c.name) for b in c.branches
                  if b.is_periodic and b.orbits]
    if choice.branch is not None:
        candidates = [b for b in candidates if b.name == choice.branch]
    if not candidates:
        raise WhirlError(f"{result.study_name}: no periodic branch with stored orbits"
                         + (f" named {choice.branch!r}" if choice.branch else ""))
    return candidates[0]


def _pick_sweep(result: StudyResult, parameter: str | None) -> LinearSweep:
    """The linear sweep of ``parameter`` (None: the first)."""
    sweeps = [s for s in result.linear_sweeps if parameter in (None, s.parameter)]
    if not sweeps:
        have = ", ".join(s.parameter for s in result.linear_sweeps) or "none"
        raise WhirlError(f"{result.study_name}: no linear sweep"
                         + (f" of {parameter!r}" if parameter else "") + f" (sweeps: {have})")
    return sweeps[0]


def differing_labels(results: Sequence[StudyResult]) -> list[str]:
    """One label per result naming the parameters whose values differ between them
    (``"K2 = 5 N m/rad^3"``; the study's name where nothing differs or a result has no stored
    parameter set)."""
    tables = [{p.name: p for p in r.parameters} for r in results]
    if not all(tables):
        return [r.study_name for r in results]
    names = [n for n in tables[0] if all(n in t for t in tables)
             and len({t[n].value for t in tables}) > 1]
    if not names:
        return [r.study_name for r in results]
    return [", ".join(str(Fixed(n, t[n].value, t[n].unit)) for n in names) for t in tables]


def draw_overlay(results: Sequence[StudyResult], kind: str, ax: Axes,
                 labels: Sequence[str | None] = (), choice: PanelChoice = PanelChoice(),
                 title: str | None = None) -> list[Axes]:
    """Several results' diagrams of ``kind`` (:data:`OVERLAY_KINDS`) on one Axes: for
    ``bifurcation`` each result in its own colour, stable branches solid and unstable dotted,
    special points with the markers of :data:`PLOT_KEY`; for ``damping_multiples`` each
    parameter in its own colour, each result in its own line style (the Axes split in
    damping and frequency); for ``law`` each result's stiffness law in its own colour and
    line style beside the linear spring. The legend names each result by
    ``labels`` (missing or None: :func:`differing_labels`). Title: ``title`` (None: the
    parameters off their datum that every result shares and the diagram does not vary)."""
    overlay = _OVERLAYS.get(kind)
    if overlay is None:
        raise WhirlError(f"kind {kind!r} cannot be overlaid; choose from "
                         f"{', '.join(OVERLAY_KINDS)}")
    if not results:
        raise WhirlError("an overlay needs at least one result")
    auto = differing_labels(results)
    names = [labels[k] if k < len(labels) and labels[k] else auto[k]
             for k in range(len(results))]
    return overlay(results, names, ax, choice, title)


def _overlay_bifurcations(results: Sequence[StudyResult], names: Sequence[str], ax: Axes,
                          choice: PanelChoice, title: str | None) -> list[Axes]:
    """Every result's bifurcation diagram on ``ax``, one colour per result."""
    first: dict[str, object] = {}
    handles = []
    state = choice.state
    for result, label, colour in zip(results, names, _colours(), strict=False):
        continuation = pick_continuation(result, choice.continuation)
        which, branches, state = _checked_branches(continuation, state, ("max",))
        handle = None
        for branch in branches:
            handle = _draw_coloured(ax, branch, state, colour) or handle
        if handle is not None:
            handle.set_label(label)
            handles.append(handle)
        _draw_special_points(ax, continuation, branches, state, True, first)
        if branches and not ax.get_xlabel():
            _label_axes(ax, continuation, branches, state, which, True)
    markers = [first[key] for key in PLOT_KEY if key in first]
    ax.legend(handles + markers,
              [h.get_label() for h in handles] + [str(PLOT_KEY[k]["label"]) for k in PLOT_KEY
                                                  if k in first], fontsize="small")
    if title is None:
        varied = {n for r in results for c in r.continuations for b in c.branches
                  for n in b.parameter_names}
        title = _shared_title(results, varied)
    ax.set_title(title)
    return [ax]


def _shared_title(results: Sequence[StudyResult], varied: set[str]) -> str:
    """The parameters off their datum that every result shares, but for ``varied``."""
    shared = [p for p in results[0].parameters if p.name not in varied
              and p.value != p.datum and all(
                  any(q.name == p.name and q.value == p.value for q in r.parameters)
                  for r in results[1:])]
    return ", ".join(str(Fixed(p.name, p.value, p.unit)) for p in shared)


def _overlay_laws(results: Sequence[StudyResult], names: Sequence[str], ax: Axes,
                  choice: PanelChoice, title: str | None) -> list[Axes]:
    """Every result's nonlinear law on the dof ``choice.state`` (None: the first) on ``ax``,
    beside the linear spring (:func:`~whirl_cli.plots.laws.laws_plot`)."""
    from .laws import laws_plot, nonlinear_laws

    chosen = []
    for result, name in zip(results, names, strict=True):
        found = [c for c in nonlinear_laws(result) if choice.state in (None, c.dof)]
        if not found:
            raise WhirlError(f"{result.study_name}: no nonlinear stiffness law"
                             + (f" on {choice.state!r}" if choice.state else ""))
        chosen.append((found[0], name))
    laws_plot(chosen, ax=ax, title=title)
    return [ax]


def _overlay_multiples(results: Sequence[StudyResult], names: Sequence[str], ax: Axes,
                       choice: PanelChoice, title: str | None) -> list[Axes]:
    """``ax`` split in two (damping, frequency) with every result's ``damping_multiples``:
    a colour per parameter, a line style per result (:func:`_multiples_into`)."""
    return _replaced(ax, lambda region: _multiples_into(results, names, region, choice,
                                                        title))


def _multiples_into(results: Sequence[StudyResult], names: Sequence[str], region,
                    choice: PanelChoice, title: str | None) -> None:
    """Every result's ``damping_multiples`` on one pair of axes in ``region``: a colour per
    parameter (in the order of each result's sweeps), a line style per result, its lines
    labelled ``"<name>: <parameter> (<whirl>)"``."""
    axes = tuple(region.subgridspec(2, 1).subplots(sharex=True))
    styles = ("-", "--", "-.", ":")
    for k, (result, name) in enumerate(zip(results, names, strict=True)):
        before = [len(a.lines) for a in axes]
        _draw_multiples(result, None, choice, captions(result), axes=axes)
        for ax, start in zip(axes, before, strict=True):  # colours: by parameter already
            for line in ax.lines[start:]:
                if not line.get_label().startswith("_"):
                    line.set_linestyle(styles[k % len(styles)])
                    line.set_label(f"{name}: {line.get_label()}")
    axes[0].legend(fontsize="small")
    axes[0].set_title(title if title is not None else "")


def _draw_coloured(ax: Axes, branch: Branch, state: str, colour: str):
    """One branch in ``colour``: stable solid, unstable dotted, periodic drawn by its max;
    returns a solid line for the legend (None if nothing was drawn)."""
    factor, _ = display_unit(branch.state_units[branch.state_names.index(state)], True)
    y = branch.state(state, "max") * factor
    solid = None
    for xs, ys, stable in stability_curves(branch.parameters[:, 0], y, branch.stable,
                                             branch.stability_known):
        (line,) = ax.plot(xs, ys, color=colour, linestyle="-" if stable else ":",
                          linewidth=1.4 if branch.is_periodic else 1.0, label="_curve")
        solid = line if stable and solid is None else solid
    if solid is None and len(y):
        (solid,) = ax.plot([], [], color=colour, linestyle="-")
    return solid if np.size(y) else None


_PANELS = {
    "bifurcation": _bifurcation_panel, "projections": _projections_panel,
    "period": _period_panel, "phase": _phase_panel, "linear": _linear_panel,
    "root_locus": _root_locus_panel, "damping_multiples": _multiples_panel,
    "boundary": _map_panel("boundary"), "overhang": _map_panel("overhang"),
    "amplitude": _amplitude_panel, "time_history": _simulation_panel("time_history"),
    "hub_path": _simulation_panel("hub_path"), "law": _law_panel,
    "poincare": _poincare_panel, "spectrum": _spectrum_panel,
    "orbit_diagram": _orbit_diagram_panel, "blowup": _blowup_panel,
}
"""Panel kind -> its drawer (result, axes, choice, captions) -> the axes drawn on."""

PANEL_KINDS = tuple(_PANELS)
"""Kinds :func:`draw` accepts (``overhang``: one slice of a boundary, its unsafe intervals
shaded; ``blowup``: the period of a family near its global bifurcation, the fitted
asymptote)."""

_OVERLAYS = {"bifurcation": _overlay_bifurcations, "damping_multiples": _overlay_multiples,
             "law": _overlay_laws}
"""Overlay kind -> its drawer (results, labels, axes, choice, title) -> the axes drawn on."""

OVERLAY_KINDS = tuple(_OVERLAYS)
"""Kinds :func:`draw_overlay` accepts."""
