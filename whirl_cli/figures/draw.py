"""A sheet drawn from study results: one matplotlib Figure, panels on a grid
(:func:`draw_sheet`), each panel :func:`whirl_cli.plots.panels.draw` or
:func:`~whirl_cli.plots.panels.draw_overlay`.
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import WhirlError
from ..plots.key import legend_columns, new_figure
from ..plots.panels import PanelChoice, draw, draw_overlay
from ..results import StudyResult
from .sheet import PanelSpec, Sheet

if TYPE_CHECKING:
    from matplotlib.figure import Figure

def sheet_files(sheet: Sheet, results: Mapping[Path, StudyResult], formats: tuple[str, ...],
                dpi: int, key: str | None = None) -> dict[str, bytes]:
    """The figure of ``sheet`` in each of ``formats`` (:func:`whirl_cli.plots.files.
    rendered_formats`), drawn and written with the sheet's :attr:`~Sheet.style` (tick labels
    take their size when written)."""
    from matplotlib import rc_context

    from ..plots.files import rendered_formats

    with rc_context(sheet.style):
        return rendered_formats(draw_sheet(sheet, results), formats, dpi, key)


def draw_sheet(sheet: Sheet, results: Mapping[Path, StudyResult]) -> Figure:
    """The figure of ``sheet`` from ``results`` (keyed by :meth:`Sheet.resolve` paths):
    panels row by row on the sheet's layout, titled "Figure <number>: <caption>" (legends
    on the first panel only if the sheet says ``legends: first``).
    A panel that cannot be drawn is a :class:`WhirlError` naming the sheet and the panel."""
    rows, columns = sheet.shape
    size = sheet.figure_size
    figure = new_figure(figsize=size)
    grid = figure.add_gridspec(rows, columns)
    for k, panel in enumerate(sheet.panels):
        ax = figure.add_subplot(grid[k // columns, k % columns])
        try:
            _draw_panel(sheet, panel, results, ax)
        except WhirlError as error:
            raise WhirlError(f"{sheet.path}: panels[{k}] ({panel.kind}): {error}") from None
    if sheet.legends == "first":
        for ax in figure.axes[1:]:
            if ax.get_legend() is not None:
                ax.get_legend().remove()
    elif sheet.legends == "figure":
        figure_legend(figure)
    share_limits(figure.axes, sheet.share)
    width = max(40, int(size[0] * 14))
    figure.suptitle(textwrap.fill(f"Figure {sheet.figure}: {sheet.caption}", width),
                    fontsize="medium")
    return figure


def figure_legend(figure: Figure) -> None:
    """The panels' legends as one legend of ``figure`` below its panels: every entry once
    (by its label, the first panel's artist), the panels' own legends removed."""
    entries: dict[str, object] = {}
    for ax in figure.axes:
        legend = ax.get_legend()
        if legend is None:
            continue
        for handle, text in zip(legend.legend_handles, legend.get_texts(), strict=False):
            entries.setdefault(text.get_text(), handle)
        legend.remove()
    if not entries:
        return
    entries = _one_per_style(entries)
    columns = legend_columns(list(entries), figure.get_size_inches()[0])
    figure.legend(list(entries.values()), list(entries), loc="outside lower center",
                  ncols=columns, fontsize="small", frameon=False)


def _one_per_style(entries: dict[str, object]) -> dict[str, object]:
    """``entries`` (label -> handle) with one entry per marker style: of two markers drawn
    alike (one panel's "heteroclinic", another's "heteroclinic (whirl: ...)"), the entry
    whose label extends the other's, in the first one's place."""
    kept: dict[str, object] = {}
    for label, handle in entries.items():
        twin = next((k for k, h in kept.items() if _same_marker(h, handle)
                     and (label.startswith(k) or k.startswith(label))), None)
        if twin is None:
            kept[label] = handle
        elif len(label) > len(twin):
            kept = {label if k == twin else k: handle if k == twin else h
                    for k, h in kept.items()}
    return kept


def _same_marker(a, b) -> bool:
    """Whether ``a`` and ``b`` are marker handles drawn alike (marker, face and edge)."""
    from matplotlib.colors import same_color
    from matplotlib.lines import Line2D

    if not (isinstance(a, Line2D) and isinstance(b, Line2D)) or a.get_marker() in (
            "None", "", None):
        return False
    return (a.get_marker() == b.get_marker()
            and str(a.get_markerfacecolor()) == str(b.get_markerfacecolor())
            and same_color(a.get_markeredgecolor(), b.get_markeredgecolor()))


def share_limits(axes, share: str) -> None:
    """Give the axes that show the same quantity (the same axis label) the union of their
    limits on x (``share`` "x" or "both") and on y ("y" or "both")."""
    for axis in ("x", "y"):
        if share not in (axis, "both"):
            continue
        groups: dict[str, list] = {}
        for ax in axes:
            label = getattr(ax, f"get_{axis}label")()
            if label and ax.has_data():
                groups.setdefault(label, []).append(ax)
        for group in groups.values():
            limits = [getattr(ax, f"get_{axis}lim")() for ax in group]
            low = min(min(lim) for lim in limits)
            high = max(max(lim) for lim in limits)
            for ax in group:
                getattr(ax, f"set_{axis}lim")(low, high)


def _draw_panel(sheet: Sheet, panel: PanelSpec, results: Mapping[Path, StudyResult], ax
                ) -> None:
    choice = PanelChoice(continuation=panel.continuation, branch=panel.branch,
                         state=panel.state, sweep=panel.sweep, slice=panel.slice,
                         orbits=panel.orbits, simulation=panel.simulation, hz=panel.hz,
                         title=panel.title, cuts=panel.cuts)
    if panel.overlay:
        members = [results[sheet.resolve(m.study)] for m in panel.overlay]
        draw_overlay(members, panel.kind, ax, [m.label for m in panel.overlay], choice,
                     title=panel.title)
    else:
        draw(results[sheet.resolve(panel.study)], panel.kind, ax, choice)
