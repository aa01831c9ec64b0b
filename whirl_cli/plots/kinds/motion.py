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


def _drawn_by(name: str):
    """The function of :mod:`whirl_cli.plots.motion` named ``name`` (imported when drawing)."""
    from .. import motion

    return getattr(motion, name)


def _whole_figure_kind(kind: str, rank: int, draw: str) -> PlotKind:
    """A kind drawn by ``motion.<draw>(continuation, ax=None, title=...)``: one file per
    explored continuation, or one panel."""
    def files(figures: Figures) -> list[FigureJob]:
        return _per_continuation(figures, kind,
                                 lambda c, title: _drawn_by(draw)(c, title=title))

    def panel(result, ax, choice, caption) -> list[Axes]:
        from ..panels import continuation_title, pick_continuation

        continuation = pick_continuation(result, choice.continuation, kind)
        _drawn_by(draw)(continuation, ax=ax,
                        title=continuation_title(continuation, choice, caption))
        return [ax]

    return PlotKind(kind, rank, panel, missing=_not_explored, figures=files, fits=_explored,
                    need="explored values")


POINCARE = _whole_figure_kind("poincare", 130, "poincare_plot")
SPECTRUM = _whole_figure_kind("spectrum", 140, "spectrum_plot")


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
