"""The kinds drawn by :mod:`whirl_cli.plots.linear`: ``linear``, ``root_locus`` and
``damping_multiples``."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from . import FigureJob, Figures, PlotKind

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ...results import StudyResult
    from ..panels import PanelChoice


def _no_sweep(result: StudyResult) -> str:
    return "" if result.linear_sweeps else "no linear sweep (linear.sweeps)"


def _linear_files(figures: Figures) -> list[FigureJob]:
    from ..linear import linear_sweep_plot

    return [(f"{figures.stem}_linear_{s.parameter}.png",
             lambda s=s: linear_sweep_plot(s, hz=figures.view.hz,
                                           title=figures.caption().title({s.parameter})))
            for s in figures.result.linear_sweeps]


def _linear_panel(result, ax, choice, caption) -> list[Axes]:
    from ..linear import linear_sweep_plot
    from ..panels import pick_sweep, replaced

    sweep = pick_sweep(result, choice.sweep)
    title = caption.title({sweep.parameter}) if choice.title is None else choice.title
    return replaced(ax, lambda region: linear_sweep_plot(
        sweep, hz=choice.hz, title=title,
        axes=tuple(region.subgridspec(2, 1).subplots(sharex=True))))


LINEAR = PlotKind("linear", 20, _linear_panel, missing=_no_sweep, figures=_linear_files)


def _root_locus_files(figures: Figures) -> list[FigureJob]:
    from ..linear import root_locus_plot

    return [(f"{figures.stem}_root_locus_{s.parameter}.png",
             lambda s=s: root_locus_plot(s, title=figures.caption().title({s.parameter})))
            for s in figures.result.linear_sweeps]


def _root_locus_panel(result, ax, choice, caption) -> list[Axes]:
    from ..linear import root_locus_plot
    from ..panels import pick_sweep

    sweep = pick_sweep(result, choice.sweep)
    root_locus_plot(sweep, title=caption.title({sweep.parameter}) if choice.title is None
                    else choice.title, ax=ax)
    return [ax]


ROOT_LOCUS = PlotKind("root_locus", 30, _root_locus_panel, missing=_no_sweep,
                      figures=_root_locus_files)


def datums(result: StudyResult) -> dict[str, float]:
    """The datum of every parameter (for files whose sweeps do not store theirs)."""
    return {p.name: p.datum for p in result.parameters}


def multiple_sweeps(result: StudyResult) -> list:
    """The linear sweeps that can be drawn against parameter / datum (a non-zero datum)."""
    from ..linear import sweep_datum

    found = datums(result)
    return [s for s in result.linear_sweeps if sweep_datum(s, found) is not None]


def _no_multiples(result: StudyResult) -> str:
    if not result.linear_sweeps:
        return "no linear sweep (linear.sweeps)"
    if not multiple_sweeps(result):
        return "no linear sweep of a parameter with a non-zero datum (linear.sweeps)"
    return ""


def _multiples_files(figures: Figures) -> list[FigureJob]:
    from ..linear import damping_multiples_plot

    chosen = tuple(multiple_sweeps(figures.result))
    if not chosen:
        return []
    return [(f"{figures.stem}_damping_multiples.png",
             lambda: damping_multiples_plot(
                 chosen, datums(figures.result), hz=figures.view.hz,
                 title=figures.caption().title({s.parameter for s in chosen})))]


def _multiples_panel(result, ax, choice, caption) -> list[Axes]:
    from ..panels import replaced

    return replaced(ax, lambda region: _draw_multiples(result, region, choice, caption))


def _draw_multiples(result: StudyResult, region, choice: PanelChoice, caption,
                    axes=None) -> None:
    """The ``damping_multiples`` kind (every sweep with a non-zero datum, or ``choice.sweep``)
    into ``region`` (or onto ``axes``, damping and frequency)."""
    from ...errors import WhirlError
    from ..linear import damping_multiples_plot

    sweeps = [s for s in multiple_sweeps(result) if choice.sweep in (None, s.parameter)]
    if not sweeps:
        raise WhirlError(f"{result.study_name}: no linear sweep with a non-zero datum"
                         + (f" of {choice.sweep!r}" if choice.sweep else ""))
    if axes is None:
        axes = tuple(region.subgridspec(2, 1).subplots(sharex=True))
    title = choice.title or caption.title({s.parameter for s in sweeps})
    damping_multiples_plot(sweeps, datums(result), hz=choice.hz, title=title, axes=axes)


def _overlay_multiples(results: Sequence[StudyResult], names: Sequence[str], ax: Axes,
                       choice: PanelChoice, title: str | None) -> list[Axes]:
    """``ax`` split in two (damping, frequency) with every result's ``damping_multiples``:
    a colour per parameter, a line style per result (:func:`_multiples_into`)."""
    from ..panels import replaced

    return replaced(ax, lambda region: _multiples_into(results, names, region, choice,
                                                        title))


def _multiples_into(results: Sequence[StudyResult], names: Sequence[str], region,
                    choice: PanelChoice, title: str | None) -> None:
    """Every result's ``damping_multiples`` on one pair of axes in ``region``: a colour per
    parameter (in the order of each result's sweeps), a line style per result, its lines
    labelled ``"<name>: <parameter> (<whirl>)"``."""
    from ..captions import captions

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


DAMPING_MULTIPLES = PlotKind("damping_multiples", 40, _multiples_panel, missing=_no_multiples,
                             figures=_multiples_files, overlay=_overlay_multiples)
