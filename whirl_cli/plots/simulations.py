"""Figures of time simulations from stated initial states (a study's ``simulations:``):
time histories, one panel per degree of freedom, and the hub path in the plane normal to the
spin axis (thesis figures 3.6-3.8).

No state name is assumed: the dofs are the first half of a simulation's states, and the hub
path is the combination of states the model declares (:attr:`Simulation.hub`; classical:
(y, z) = (-psi, -theta), the hub offset up to the factor a R).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..errors import WhirlError
from ..results import Simulation
from .key import _BLACK, _new_figure, axis_label, display_unit, next_colour

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Colour map of the hub path: the colour runs with time (dark at the start).
TIME_MAP = "viridis"


def time_history(simulation: Simulation, states: Sequence[str] | None = None,
                 axes: Axes | Sequence[Axes] | None = None, degrees: bool = True,
                 title: str | None = None) -> Figure:
    """``states`` (default: every dof of the model) against time, one panel each, stacked
    and sharing the time axis; angles in degrees (rates in deg/s) unless ``degrees`` is
    False, other states in their SI units. Draws on ``axes`` if given (one per state, or an
    Axes when one state is drawn), else on a new figure; returns the figure. The first
    panel's title is ``title`` (None: the simulation's name); a simulation that stopped early
    says why under it."""
    names = tuple(simulation.dof_names if states is None else states)
    unknown = [s for s in names if s not in simulation.state_names]
    if unknown or not names:
        raise WhirlError(f"state(s) {', '.join(unknown) or '(none)'} not in simulation "
                         f"{simulation.name!r} (states: {', '.join(simulation.state_names)})")
    if axes is None:
        figure = _new_figure(figsize=(8.0, 1.0 + 2.2 * len(names)))
        axes = figure.subplots(len(names), 1, sharex=True, squeeze=False)[:, 0]
    elif not isinstance(axes, Sequence | np.ndarray):
        axes = [axes]
    if len(axes) != len(names):
        raise WhirlError(f"time_history draws {len(names)} state(s) on as many axes, got "
                         f"{len(axes)}")
    units = dict(zip(simulation.state_names, simulation.state_units, strict=True))
    for ax, name in zip(axes, names, strict=True):
        factor, unit = display_unit(units[name], degrees)
        column = simulation.state_names.index(name)
        ax.plot(simulation.time, factor * simulation.states[:, column],
                color=next_colour(ax.figure),
                linewidth=0.8, label=name)
        ax.set_ylabel(axis_label(name, unit))
        ax.axhline(0.0, color=_BLACK, linewidth=0.5, zorder=0)
    axes[-1].set_xlabel(axis_label("t", "s"))
    axes[0].set_title(_with_status(simulation, title))
    return axes[0].figure


def hub_path(simulation: Simulation, ax: Axes | None = None, degrees: bool = True,
             title: str | None = None) -> Figure:
    """The hub's path (y, z) normal to the spin axis, as the model declares it
    (:attr:`Simulation.hub`, in degrees where it is in rad unless ``degrees`` is False),
    coloured by time (:data:`TIME_MAP`, with a colour bar in s), its start marked by a hollow
    circle and its end by a cross; equal aspect. Draws on ``ax`` if given, else on a new
    figure; returns the figure. Title ``title`` (None: the simulation's name)."""
    from matplotlib.collections import LineCollection

    if ax is None:
        ax = _new_figure(figsize=(6.4, 5.6)).add_subplot()
    factor, unit = display_unit(simulation.hub_unit, degrees)
    path = factor * np.asarray(simulation.hub, dtype=float).reshape(-1, 2)
    time = np.asarray(simulation.time, dtype=float)
    if len(path) > 1:
        segments = np.stack([path[:-1], path[1:]], axis=1)
        lines = LineCollection(segments, cmap=TIME_MAP, linewidth=0.8, label="hub path")
        lines.set_array(0.5 * (time[:-1] + time[1:]))
        ax.add_collection(lines)
        ax.figure.colorbar(lines, ax=ax, label=axis_label("t", "s"))
    if len(path):
        ax.plot(*path[0], marker="o", markerfacecolor="none", markeredgecolor=_BLACK,
                linestyle="none", markersize=8, zorder=3, label="start")
        ax.plot(*path[-1], marker="x", color=_BLACK, linestyle="none", markersize=8,
                zorder=3, label=f"end (t = {time[-1]:.3g} s)")
    ax.autoscale_view()
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(axis_label("hub y", unit))
    ax.set_ylabel(axis_label("hub z", unit))
    ax.legend(fontsize="small", loc="upper right")
    ax.set_title(_with_status(simulation, title))
    return ax.figure


def _with_status(simulation: Simulation, title: str | None) -> str:
    """``title`` (None: the simulation's name), with the reason it stopped early if so."""
    text = simulation.name if title is None else title
    if simulation.status != 0:
        text += f"\nstopped: {simulation.message}"
    return text
