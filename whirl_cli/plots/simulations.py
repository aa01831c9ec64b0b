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
from .key import BLACK, axis_label, display_unit, new_figure, next_colour, symbol

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
    says why under it. A state oscillating more than :data:`ENVELOPE_CYCLES` times, which
    would print as a solid band, is drawn as its envelope (:func:`draw_envelope`)."""
    names = tuple(simulation.dof_names if states is None else states)
    unknown = [s for s in names if s not in simulation.state_names]
    if unknown or not names:
        raise WhirlError(f"state(s) {', '.join(unknown) or '(none)'} not in simulation "
                         f"{simulation.name!r} (states: {', '.join(simulation.state_names)})")
    if axes is None:
        figure = new_figure(figsize=(8.0, 1.0 + 2.2 * len(names)))
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
        values = factor * simulation.states[:, column]
        colour = next_colour(ax.figure)
        if cycles(values) > ENVELOPE_CYCLES:
            draw_envelope(ax, simulation.time, values, colour, name)
        else:
            ax.plot(simulation.time, values, color=colour, linewidth=0.8, label=name)
        ax.set_ylabel(axis_label(name, unit))
        ax.axhline(0.0, color=BLACK, linewidth=0.5, zorder=0)
    axes[-1].set_xlabel(axis_label("t", "s"))
    axes[0].set_title(_with_status(simulation, title))
    return axes[0].figure


ENVELOPE_CYCLES = 120
"""More cycles than this in a time history are drawn as their envelope."""


def cycles(values: np.ndarray) -> int:
    """How many times ``values`` cross their mean upwards."""
    above = np.asarray(values, dtype=float) > np.mean(values)
    return int(np.count_nonzero(~above[:-1] & above[1:]))


def peaks(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the local maxima and of the local minima of ``values`` (interior points
    not lower, respectively not higher, than both neighbours and strictly beyond one)."""
    v = np.asarray(values, dtype=float)
    middle = v[1:-1]
    up = np.flatnonzero((middle >= v[:-2]) & (middle > v[2:])) + 1
    down = np.flatnonzero((middle <= v[:-2]) & (middle < v[2:])) + 1
    return up, down


def draw_envelope(ax: Axes, time: np.ndarray, values: np.ndarray, colour: str, name: str
                  ) -> None:
    """The upper and lower envelope of an oscillation (its maxima and minima joined), the
    band between them lightly filled; labelled "<name> (envelope of <n> cycles)"."""
    up, down = peaks(values)
    label = f"{symbol(name)} (envelope of {cycles(values)} cycles)"
    ax.plot(time[up], values[up], color=colour, linewidth=1.2, label=label)
    ax.plot(time[down], values[down], color=colour, linewidth=1.2, label="_lower envelope")
    grid = np.asarray(time, dtype=float)
    ax.fill_between(grid, np.interp(grid, time[down], values[down]),
                    np.interp(grid, time[up], values[up]), color=colour, alpha=0.2,
                    linewidth=0, label="_envelope band")
    ax.legend(fontsize="small", loc="upper left")


def hub_path(simulation: Simulation, ax: Axes | None = None, degrees: bool = True,
             title: str | None = None) -> Figure:
    """The hub's path (y, z) normal to the spin axis, as the model declares it
    (:attr:`Simulation.hub`, in degrees where it is in rad unless ``degrees`` is False),
    coloured by time (:data:`TIME_MAP`, with a colour bar in s), its start marked by a hollow
    circle and its end by a cross; outside it, curved arrows for the sense of the whirl over
    its last turn (FW or BW) and of the spin (:func:`sense_arrows`); equal aspect. Draws on
    ``ax`` if given, else on a new figure; returns the figure. Title ``title`` (None: the
    simulation's name)."""
    from matplotlib.collections import LineCollection

    if ax is None:
        ax = new_figure(figsize=(6.4, 5.6)).add_subplot()
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
        ax.plot(*path[0], marker="o", markerfacecolor="none", markeredgecolor=BLACK,
                linestyle="none", markersize=8, zorder=3, label="start")
        ax.plot(*path[-1], marker="x", color=BLACK, linestyle="none", markersize=8,
                zorder=3, label=f"end (t = {time[-1]:.3g} s)")
    ax.autoscale_view()
    if len(path) > 2:
        sense_arrows(ax, path)
    return _finish_hub_axes(ax, unit, simulation, title)


SPIN_SENSE = 1
"""The spin (+x, Omega > 0) turns counterclockwise in the hub plane drawn y right, z up: a
path enclosing a positive signed area whirls forward (:func:`~whirl_cli.analysis.simulate.
whirl_sense`)."""


def signed_area(path: np.ndarray) -> float:
    """The signed area a closed (N, 2) path encloses (> 0: counterclockwise)."""
    y, z = np.asarray(path, dtype=float).T
    return float(0.5 * np.sum(y * np.roll(z, -1) - np.roll(y, -1) * z))


def last_turn(path: np.ndarray) -> np.ndarray:
    """The end of ``path`` over its last full turn about the origin (the whole path if it
    does not turn once)."""
    angle = np.unwrap(np.arctan2(path[:, 1], path[:, 0]))
    turned = np.abs(angle - angle[-1]) >= 2 * np.pi
    start = int(np.flatnonzero(turned)[-1]) if turned.any() else 0
    return path[start:]


def sense_arrows(ax: Axes, path: np.ndarray) -> list:
    """Two curved arrows just outside ``path`` (in the hub plane): the whirl's sense over
    :func:`last_turn` (labelled FW or BW) at the upper left, the spin's (:data:`SPIN_SENSE`)
    at the lower right, their gids "whirl" and "spin"; the axes limits widened to hold them.
    Returns the arrows."""
    from matplotlib.patches import FancyArrowPatch

    turn = last_turn(path)
    whirl = 1 if signed_area(turn) > 0 else -1
    radius = 1.12 * float(np.max(np.hypot(path[:, 0], path[:, 1])))
    arrows = []
    for sense, middle, text in ((whirl, 135.0, "whirl (FW)" if whirl == SPIN_SENSE
                                 else "whirl (BW)"),
                                (SPIN_SENSE, -45.0, "spin $\\Omega$")):
        ends = np.radians(middle + sense * np.array([-25.0, 25.0]))
        a, b = (radius * np.array([np.cos(e), np.sin(e)]) for e in ends)
        arrow = FancyArrowPatch(a, b, connectionstyle=f"arc3,rad={0.22 * sense}",
                                arrowstyle="-|>", mutation_scale=16, linewidth=1.4,
                                color=BLACK, zorder=4, gid=text.split()[0],
                                label=f"_{text}",
                                linestyle="-" if text.startswith("whirl") else "--")
        ax.add_patch(arrow)
        arrows.append(arrow)
        at = np.radians(middle)
        ax.text(1.2 * radius * np.cos(at), 1.2 * radius * np.sin(at), text,
                ha="right" if np.cos(at) < 0 else "left", va="center", fontsize="small")
    reach = 1.35 * radius
    ax.update_datalim([(-reach, -reach), (reach, reach)])
    ax.autoscale_view()
    return arrows


def whirl_snapshots(simulation: Simulation, count: int = 8, ax: Axes | None = None,
                    degrees: bool = True, title: str | None = None) -> Figure:
    """The whirl motion seen along the spin axis: ``count`` snapshots, equally spaced in time
    over the last turn of the hub path (:func:`last_turn`), each the nacelle axis from the
    pivot to the hub (a line and a dot, coloured by :data:`TIME_MAP` in time order and
    numbered 1, 2, ...), the turn's path thin grey, the senses of the whirl and the spin
    (:func:`sense_arrows`); equal aspect. Draws on ``ax`` if given, else on a new figure;
    returns the figure. Title ``title`` (None: the simulation's name)."""
    from matplotlib import colormaps

    if ax is None:
        ax = new_figure(figsize=(6.4, 5.6)).add_subplot()
    factor, unit = display_unit(simulation.hub_unit, degrees)
    path = factor * np.asarray(simulation.hub, dtype=float).reshape(-1, 2)
    time = np.asarray(simulation.time, dtype=float)
    if len(path) < 3:
        raise WhirlError(f"simulation {simulation.name!r} has too few samples for snapshots")
    turn = last_turn(path)
    times = time[len(path) - len(turn):]
    ax.plot(turn[:, 0], turn[:, 1], color="grey", linewidth=0.8, zorder=1,
            label=f"hub path, last turn (t = {times[0]:.3g} to {times[-1]:.3g} s)")
    ax.plot([0.0], [0.0], marker="+", color=BLACK, markersize=10, linestyle="none",
            zorder=3, label="pivot")
    instants = times[0] + (times[-1] - times[0]) * np.arange(count) / count
    shades = colormaps[TIME_MAP](np.linspace(0.0, 0.85, count))
    reach = float(np.max(np.hypot(turn[:, 0], turn[:, 1])))
    for k, (at, shade) in enumerate(zip(instants, shades, strict=True)):
        y, z = (np.interp(at, times, turn[:, j]) for j in (0, 1))
        ax.plot([0.0, y], [0.0, z], color=shade, linewidth=1.6, zorder=2,
                label="nacelle axis at equal steps of time" if k == 0 else "_snapshot")
        ax.plot([y], [z], marker="o", color=shade, markersize=7, linestyle="none", zorder=3,
                label="_hub", gid="snapshot")
        norm = max(np.hypot(y, z), 1e-300)
        ax.text(y + 0.09 * reach * y / norm, z + 0.09 * reach * z / norm, str(k + 1),
                ha="center", va="center", fontsize="small", zorder=4)
    sense_arrows(ax, turn)
    return _finish_hub_axes(ax, unit, simulation, title)


def _finish_hub_axes(ax: Axes, unit: str, simulation: Simulation, title: str | None) -> Figure:
    """Equal axes of the hub's y and z in ``unit``, the legend, the title (with the
    simulation's status); returns the figure."""
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
