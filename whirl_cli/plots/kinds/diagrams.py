"""The kinds drawn by :mod:`whirl_cli.plots.diagrams`: ``bifurcation``, ``projections``,
``period`` and ``phase``."""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial
from typing import TYPE_CHECKING

from ...kinds import ContinuationKind
from . import FigureJob, Figures, PlotKind

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ...results import Branch, StudyResult
    from ..panels import PanelChoice


def _no_one_parameter(result: StudyResult) -> str:
    one = any(c.kind == ContinuationKind.ONE_PARAMETER for c in result.continuations)
    return "" if one else "no one-parameter continuation"


def _periodic(continuation) -> bool:
    return any(b.is_periodic for b in continuation.branches)


def _has_orbits(branch: Branch) -> bool:
    return branch.is_periodic and bool(branch.orbits) and len(branch.state_names) >= 2


def _bifurcation_files(figures: Figures) -> list[FigureJob]:
    from ..files import state_for

    return [(f"{figures.stem}_{c.name}_bifurcation.png",
             partial(_bifurcation_figure, c, state_for(c, figures.state), figures))
            for c in figures.one_parameter()]


def _bifurcation_figure(continuation, state: str | None, figures: Figures):
    from ..diagrams import bifurcation_figure

    view = figures.view
    return bifurcation_figure(continuation, state, title=figures.title(continuation),
                              zoom=view.xlim is None and view.ylim is None)


def _bifurcation_panel(result, ax, choice, caption) -> list[Axes]:
    from ..diagrams import bifurcation_diagram
    from ..panels import continuation_title, pick_continuation

    continuation = pick_continuation(result, choice.continuation, "bifurcation")
    bifurcation_diagram(continuation, choice.state, ax=ax,
                        title=continuation_title(continuation, choice, caption))
    if choice.cuts:
        from ..cuts import mark_cuts

        mark_cuts(ax, choice.cuts)
    return [ax]


def _overlay_bifurcations(results: Sequence[StudyResult], names: Sequence[str], ax: Axes,
                          choice: PanelChoice, title: str | None) -> list[Axes]:
    """Every result's bifurcation diagram on ``ax``, one colour per result."""
    from ..diagrams import checked_branches, draw_special_points, label_axes
    from ..key import PLOT_KEY, colour_cycle
    from ..panels import pick_continuation

    first: dict[str, object] = {}
    handles = []
    state = choice.state
    for result, label, colour in zip(results, names, colour_cycle(), strict=False):
        continuation = pick_continuation(result, choice.continuation)
        which, branches, state = checked_branches(continuation, state, ("max",))
        handle = None
        for branch in branches:
            handle = _draw_coloured(ax, branch, state, colour) or handle
        if handle is not None:
            handle.set_label(label)
            handles.append(handle)
        draw_special_points(ax, continuation, branches, state, True, first)
        if branches and not ax.get_xlabel():
            label_axes(ax, continuation, branches, state, which, True)
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
    from ..captions import Fixed

    shared = [p for p in results[0].parameters if p.name not in varied
              and p.value != p.datum and all(
                  any(q.name == p.name and q.value == p.value for q in r.parameters)
                  for r in results[1:])]
    return ", ".join(str(Fixed(p.name, p.value, p.unit)) for p in shared)


def _draw_coloured(ax: Axes, branch: Branch, state: str, colour: str):
    """One branch in ``colour``: stable solid, unstable dotted, periodic drawn by its max;
    returns a solid line for the legend (None if nothing was drawn)."""
    import numpy as np

    from ..key import display_unit, stability_curves

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


BIFURCATION = PlotKind(
    "bifurcation", 10, _bifurcation_panel, missing=_no_one_parameter,
    figures=_bifurcation_files, overlay=_overlay_bifurcations)


def _projections_files(figures: Figures) -> list[FigureJob]:
    from ..diagrams import projections_figure

    return [(f"{figures.stem}_{c.name}_projections.png",
             lambda c=c: projections_figure(c, title=figures.title(c)))
            for c in figures.one_parameter()]


def _projections_panel(result, ax, choice, caption) -> list[Axes]:
    from ..diagrams import projections_figure
    from ..panels import continuation_title, pick_continuation, replaced

    continuation = pick_continuation(result, choice.continuation, "projections")
    title = continuation_title(continuation, choice, caption)
    return replaced(ax, lambda region: projections_figure(continuation, title=title,
                                                           region=region))


PROJECTIONS = PlotKind("projections", 50, _projections_panel, missing=_no_one_parameter,
                       figures=_projections_files)


def _no_periodic(result: StudyResult) -> str:
    if any(_periodic(c) for c in result.continuations):
        return ""
    return "no periodic branch (a continuation with periodic: true)"


def _period_files(figures: Figures) -> list[FigureJob]:
    from ..diagrams import period_plot

    return [(f"{figures.stem}_{c.name}_period.png",
             lambda c=c: period_plot(c, title=figures.title(c)))
            for c in figures.result.continuations if _periodic(c)]


def _period_panel(result, ax, choice, caption) -> list[Axes]:
    from ..diagrams import period_plot
    from ..panels import continuation_title, pick_continuation

    continuation = pick_continuation(result, choice.continuation, "period")
    period_plot(continuation, title=continuation_title(continuation, choice, caption), ax=ax)
    return [ax]


PERIOD = PlotKind("period", 60, _period_panel, missing=_no_periodic, figures=_period_files,
                  fits=_periodic, need="periodic branch")


def _no_orbits(result: StudyResult) -> str:
    if any(_has_orbits(b) for c in result.continuations for b in c.branches):
        return ""
    return "no stored orbits on a periodic branch (periodic: true; orbits_at stores more)"


def _phase_files(figures: Figures) -> list[FigureJob]:
    from ..diagrams import phase_plane
    from ..files import phase_labels

    return [(f"{figures.stem}_{c.name}_{b.name}_phase.png",
             lambda b=b, c=c: phase_plane(b, labels=phase_labels(b),
                                          title=f"{figures.title(c)}\n{b.name}"))
            for c in figures.result.continuations for b in c.branches if _has_orbits(b)]


def _phase_panel(result, ax, choice, caption) -> list[Axes]:
    from ..diagrams import phase_plane
    from ..panels import pick_branch, pick_continuation, replaced

    if choice.cuts:
        from ..cuts import phase_cuts

        continuation = pick_continuation(result, choice.continuation, "period")
        return replaced(ax, lambda region: phase_cuts(continuation, choice.cuts, region))
    branch = pick_branch(result, choice)
    labels = list(choice.orbits) if choice.orbits is not None else None
    if labels is None:
        from ..files import phase_labels

        labels = phase_labels(branch)
    phase_plane(branch, labels=labels, y=choice.state, ax=ax,
                title=caption.title(branch.parameter_names) if choice.title is None
                else choice.title)
    return [ax]


PHASE = PlotKind("phase", 70, _phase_panel, missing=_no_orbits, figures=_phase_files)
