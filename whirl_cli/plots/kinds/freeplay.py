"""The kind drawn by :mod:`whirl_cli.plots.freeplay`: ``amplitude``."""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import FigureJob, Figures, PlotKind

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ...results import ContinuationResult, StudyResult


def _has_amplitudes(continuation: ContinuationResult) -> bool:
    from ..freeplay import has_amplitudes

    return has_amplitudes(continuation)


def _no_amplitudes(result: StudyResult) -> str:
    if any(_has_amplitudes(c) for c in result.continuations):
        return ""
    return "no freeplay amplitudes (a periodic branch of a model with a freeplay law)"


def _amplitude_files(figures: Figures) -> list[FigureJob]:
    from ..freeplay import amplitude_diagram

    return [(f"{figures.stem}_{c.name}_amplitude.png", lambda c=c: amplitude_diagram(c))
            for c in figures.result.continuations if _has_amplitudes(c)]


def _amplitude_panel(result, ax, choice, caption) -> list[Axes]:
    from ..freeplay import amplitude_diagram
    from ..panels import continuation_title, pick_continuation

    continuation = pick_continuation(result, choice.continuation, "amplitude")
    amplitude_diagram(continuation, ax=ax)
    ax.set_title(continuation_title(continuation, choice, caption))
    return [ax]


AMPLITUDE = PlotKind("amplitude", 90, _amplitude_panel, missing=_no_amplitudes,
                     figures=_amplitude_files, fits=_has_amplitudes,
                     need="freeplay amplitudes")
