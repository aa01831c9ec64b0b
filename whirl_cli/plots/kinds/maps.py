"""The kinds drawn by :mod:`whirl_cli.plots.maps`: ``boundary`` (with the overhang diagram of
each slice among its files) and the panel-only ``overhang``."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...kinds import ContinuationKind
from . import FigureJob, Figures, PlotKind

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ...results import StudyResult
    from ..panels import PanelChoice


def _no_boundary(result: StudyResult) -> str:
    if result.boundaries or result.linear_grid is not None:
        return ""
    return "no stability boundary (a two-parameter continuation) and no linear grid " \
           "(linear.grid)"


def _boundary_files(figures: Figures) -> list[FigureJob]:
    """A map per boundary and an overhang diagram per slice; the linear grid alone if there
    is no boundary."""
    from ...results import ContinuationResult
    from ..files import slice_title, state_for
    from ..maps import boundary_plot, oriented_grid, overhang_diagram, slice_continuation

    result, stem, state, view, caption = (figures.result, figures.stem, figures.state,
                                          figures.view, figures.caption)
    grid = result.linear_grid
    if not result.boundaries:
        if grid is None:
            return []
        return [(f"{stem}_linear_grid.png", lambda: boundary_plot(
            None, grid, title=caption().title({grid.x_parameter, grid.y_parameter}),
            xlim=view.xlim, ylim=view.ylim))]
    jobs: list[FigureJob] = []
    for boundary in result.boundaries:
        matched = None if grid is None else oriented_grid(grid, boundary.parameter_names)
        jobs.append((f"{stem}_{boundary.name}_boundary.png",
                     lambda b=boundary, g=matched: boundary_plot(
                         b, g, cases=b.slices, case_labels=caption().case_labels(b),
                         title=caption().title(b.parameter_names),
                         xlim=view.xlim, ylim=view.ylim)))
        continuation = next((c for c in result.continuations if c.name == boundary.name
                             and c.kind == ContinuationKind.TWO_PARAMETER),
                            ContinuationResult(boundary.name, "one-parameter", (), ()))
        for k, value in enumerate(boundary.slices):
            chosen = (state_for(slice_continuation(continuation, k), state)
                      if continuation.kind == ContinuationKind.TWO_PARAMETER else state)
            jobs.append((f"{stem}_{boundary.name}_slice_{k}_overhang.png",
                         lambda c=continuation, b=boundary, v=value, s=chosen, k=k:
                         overhang_diagram(c, b, v, state=s,
                                          title=slice_title(caption(), b, k, v))))
    return jobs


def _boundary_panel(result, ax, choice, caption) -> list[Axes]:
    from ..maps import boundary_plot, oriented_grid

    grid = result.linear_grid
    if not result.boundaries and grid is not None:
        boundary_plot(None, grid, ax=ax, title=choice.title or caption.title(
            {grid.x_parameter, grid.y_parameter}))
        return [ax]
    boundary = _chosen_boundary(result, choice, " and no linear grid")
    matched = None if grid is None else oriented_grid(grid, boundary.parameter_names)
    boundary_plot(boundary, matched, cases=boundary.slices,
                  case_labels=caption.case_labels(boundary), ax=ax,
                  title=choice.title or caption.title(boundary.parameter_names))
    return [ax]


def _chosen_boundary(result: StudyResult, choice: PanelChoice, lacking: str = ""):
    """The boundary ``choice.continuation`` (None: the first)."""
    from ...errors import WhirlError

    if not result.boundaries:
        raise WhirlError(f"{result.study_name}: no stability boundary (a two-parameter "
                         "continuation)" + lacking)
    names = [b.name for b in result.boundaries]
    wanted = choice.continuation or names[0]
    if wanted not in names:
        raise WhirlError(f"{result.study_name}: no boundary {wanted!r} (boundaries: "
                         f"{', '.join(names)})")
    return result.boundaries[names.index(wanted)]


BOUNDARY = PlotKind("boundary", 80, _boundary_panel, missing=_no_boundary,
                    figures=_boundary_files)


def _overhang_panel(result, ax, choice, caption) -> list[Axes]:
    """One slice of a boundary (``choice.slice``, None: the first), its unsafe intervals
    shaded."""
    from ...errors import WhirlError
    from ..files import slice_title
    from ..maps import overhang_diagram

    boundary = _chosen_boundary(result, choice)
    k = 0 if choice.slice is None else choice.slice
    if not 0 <= k < len(boundary.slices):
        raise WhirlError(f"{result.study_name}: boundary {boundary.name!r} has slices 0 to "
                         f"{len(boundary.slices) - 1}, not {k}")
    value = boundary.slices[k]
    continuation = next((c for c in result.continuations if c.name == boundary.name), None)
    if continuation is None:
        raise WhirlError(f"{result.study_name}: no continuation {boundary.name!r} for the "
                         "overhang diagram")
    title = choice.title or slice_title(caption, boundary, k, value)
    overhang_diagram(continuation, boundary, value, state=choice.state, ax=ax, title=title)
    return [ax]


OVERHANG = PlotKind("overhang", 85, _overhang_panel)
