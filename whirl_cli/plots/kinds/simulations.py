"""The kinds drawn by :mod:`whirl_cli.plots.simulations`: ``time_history`` and ``hub_path``."""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import FigureJob, Figures, PlotKind

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ...results import Simulation, StudyResult
    from ..panels import PanelChoice


def _no_simulation(result: StudyResult) -> str:
    return "" if result.simulations else "no simulation (simulations:)"


def _per_simulation(figures: Figures, suffix: str, draw) -> list[FigureJob]:
    """One file per simulation, ``<stem>_<simulation>_<suffix>.png``, drawn by ``draw``."""
    return [(f"{figures.stem}_{s.name}_{suffix}.png",
             lambda s=s: draw(s, title=figures.caption().simulation_title(s)))
            for s in figures.result.simulations]


def _time_history_files(figures: Figures) -> list[FigureJob]:
    from ..simulations import time_history

    return _per_simulation(figures, "time_history", time_history)


def _hub_path_files(figures: Figures) -> list[FigureJob]:
    from ..simulations import hub_path

    return _per_simulation(figures, "hub_path", hub_path)


def _chosen(result: StudyResult, choice: PanelChoice) -> Simulation:
    """The simulation ``choice.simulation`` (None: the first)."""
    from ...errors import WhirlError

    found = [s for s in result.simulations if choice.simulation in (None, s.name)]
    if not found:
        have = ", ".join(s.name for s in result.simulations) or "none"
        raise WhirlError(f"{result.study_name}: no simulation"
                         + (f" {choice.simulation!r}" if choice.simulation else "")
                         + f" (simulations: {have})")
    return found[0]


def _time_history_panel(result, ax, choice, caption) -> list[Axes]:
    """Every dof against time, one panel each in ``ax``'s place (``choice.state``: that
    state alone, on ``ax``)."""
    from ..panels import replaced
    from ..simulations import time_history

    simulation = _chosen(result, choice)
    title = choice.title or caption.simulation_title(simulation)
    if choice.state is not None:
        time_history(simulation, states=[choice.state], axes=ax, title=title)
        return [ax]
    dofs = len(simulation.dof_names)
    return replaced(ax, lambda region: time_history(
        simulation, axes=list(region.subgridspec(dofs, 1).subplots(sharex=True, squeeze=False)
                              [:, 0]), title=title))


def _on_the_axes(draw: str):
    """The panel of a kind that ``simulations.<draw>(simulation, ax=, title=)`` draws on the
    panel's axes (imported when drawing)."""
    def panel(result, ax, choice, caption) -> list[Axes]:
        from .. import simulations

        simulation = _chosen(result, choice)
        getattr(simulations, draw)(simulation, ax=ax, title=choice.title
                                   or caption.simulation_title(simulation))
        return [ax]
    return panel


TIME_HISTORY = PlotKind("time_history", 100, _time_history_panel, missing=_no_simulation,
                        figures=_time_history_files)
HUB_PATH = PlotKind("hub_path", 110, _on_the_axes("hub_path"), missing=_no_simulation,
                    figures=_hub_path_files)


#: Panel-only (no files of its own): the thesis's figure of the whirl motion, snapshots of the
#: nacelle axis through the last cycle of a simulation.
WHIRL_SNAPSHOTS = PlotKind("whirl_snapshots", 115, _on_the_axes("whirl_snapshots"))
