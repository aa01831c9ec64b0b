"""The kind drawn by :mod:`whirl_cli.plots.laws`: ``law``."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from . import FigureJob, Figures, PlotKind

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ...results import StudyResult
    from ..panels import PanelChoice


def _no_law(result: StudyResult) -> str:
    from ..laws import nonlinear_laws

    return "" if nonlinear_laws(result) else \
        "no nonlinear stiffness law (nonlinearity) in the stored study"


def _law_files(figures: Figures) -> list[FigureJob]:
    from ..laws import law_plot, nonlinear_laws

    return [(f"{figures.stem}_law_{curve.dof}.png", lambda c=curve: law_plot(c))
            for curve in nonlinear_laws(figures.result)]


def _chosen_law(result: StudyResult, choice: PanelChoice):
    """The stored curve of the nonlinear law on the dof ``choice.state`` (None: the first)."""
    from ...errors import WhirlError
    from ..laws import nonlinear_laws

    found = [c for c in nonlinear_laws(result) if choice.state in (None, c.dof)]
    if not found:
        raise WhirlError(f"{result.study_name}: no nonlinear stiffness law"
                         + (f" on {choice.state!r}" if choice.state else ""))
    return found[0]


def _law_panel(result, ax, choice, caption=None) -> list[Axes]:
    from ..laws import law_plot

    law_plot(_chosen_law(result, choice), ax=ax, title=choice.title)
    return [ax]


def _overlay_laws(results: Sequence[StudyResult], names: Sequence[str], ax: Axes,
                  choice: PanelChoice, title: str | None) -> list[Axes]:
    """Every result's nonlinear law on the dof ``choice.state`` (None: the first) on ``ax``,
    beside the linear spring (:func:`~whirl_cli.plots.laws.laws_plot`)."""
    from ..laws import laws_plot

    chosen = [(_chosen_law(result, choice), name)
              for result, name in zip(results, names, strict=True)]
    laws_plot(chosen, ax=ax, title=title)
    return [ax]


LAW = PlotKind("law", 120, _law_panel, missing=_no_law, figures=_law_files,
               overlay=_overlay_laws)
