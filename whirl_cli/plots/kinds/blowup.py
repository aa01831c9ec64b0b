"""The panel-only kind drawn by :mod:`whirl_cli.plots.blowup`: ``blowup``, the period of a
family near its global bifurcation and the fitted asymptote."""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import PlotKind

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ...results import ContinuationResult


def _ends_globally(continuation: ContinuationResult) -> bool:
    """Whether a special point of ``continuation`` is a homoclinic or heteroclinic one."""
    from ...results import PointType

    ends = (PointType.HOMOCLINIC, PointType.HETEROCLINIC)
    return any(p.point_type in ends for p in continuation.special_points)


def _blowup_panel(result, ax, choice, caption) -> list[Axes]:
    from ..blowup import blowup_plot
    from ..panels import continuation_title, pick_continuation

    continuation = pick_continuation(result, choice.continuation, "blowup")
    blowup_plot(continuation, branch=choice.branch, ax=ax,
                title=continuation_title(continuation, choice, caption))
    return [ax]


BLOWUP = PlotKind("blowup", 160, _blowup_panel, fits=_ends_globally,
                  need="periodic family ending in a global bifurcation")
