"""The kinds drawn by :mod:`whirl_cli.plots.motion` from a continuation's ``explore:``
classifications: ``poincare``, ``spectrum`` and ``orbit_diagram``."""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import FigureJob, Figures, PlotKind

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ...results import ContinuationResult, StudyResult


def _explored(continuation: ContinuationResult) -> bool:
    return bool(continuation.explorations)


def _not_explored(result: StudyResult) -> str:
    if any(_explored(c) for c in result.continuations):
        return ""
    return "no explored values (a one-parameter continuation with explore:)"


def _per_continuation(figures: Figures, suffix: str, draw) -> list[FigureJob]:
    """One file per explored continuation, ``<stem>_<continuation>_<suffix>.png``, drawn by
    ``draw(continuation, title)``."""

    return [(f"{figures.stem}_{c.name}_{suffix}.png",
             lambda c=c: draw(c, figures.title(c)))
            for c in figures.result.continuations if _explored(c)]


def _poincare_files(figures: Figures) -> list[FigureJob]:
    from ..motion import poincare_plot

    return _per_continuation(figures, "poincare",
                             lambda c, title: poincare_plot(c, title=title))


def _poincare_panel(result, ax, choice, caption) -> list[Axes]:
    from ..motion import poincare_plot
    from ..panels import continuation_title, pick_continuation

    continuation = pick_continuation(result, choice.continuation, "poincare")
    poincare_plot(continuation, ax=ax, title=continuation_title(continuation, choice, caption))
    return [ax]


POINCARE = PlotKind("poincare", 130, _poincare_panel, missing=_not_explored,
                    figures=_poincare_files, fits=_explored, need="explored values")


def _spectrum_files(figures: Figures) -> list[FigureJob]:
    from ..motion import spectrum_plot

    return _per_continuation(figures, "spectrum",
                             lambda c, title: spectrum_plot(c, title=title))


def _spectrum_panel(result, ax, choice, caption) -> list[Axes]:
    from ..motion import spectrum_plot
    from ..panels import continuation_title, pick_continuation

    continuation = pick_continuation(result, choice.continuation, "spectrum")
    spectrum_plot(continuation, ax=ax, title=continuation_title(continuation, choice, caption))
    return [ax]


SPECTRUM = PlotKind("spectrum", 140, _spectrum_panel, missing=_not_explored,
                    figures=_spectrum_files, fits=_explored, need="explored values")


def _orbit_diagram_files(figures: Figures) -> list[FigureJob]:
    """The section's values of the chosen state if the explorations have it, else of the
    first dof."""
    from ..motion import orbit_diagram

    def draw(continuation, title):
        names = continuation.explorations[0].state_names
        state = figures.state if figures.state in names else None
        return orbit_diagram(continuation, state, title=title)

    return _per_continuation(figures, "orbit_diagram", draw)


def _orbit_diagram_panel(result, ax, choice, caption) -> list[Axes]:
    from ..motion import orbit_diagram
    from ..panels import continuation_title, pick_continuation

    continuation = pick_continuation(result, choice.continuation, "orbit_diagram")
    orbit_diagram(continuation, choice.state, ax=ax,
                  title=continuation_title(continuation, choice, caption))
    return [ax]


ORBIT_DIAGRAM = PlotKind("orbit_diagram", 150, _orbit_diagram_panel, missing=_not_explored,
                         figures=_orbit_diagram_files, fits=_explored, need="explored values")
