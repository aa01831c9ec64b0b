"""Figures of the motion classified by simulation at a continuation's ``explore:`` values
(:class:`whirl_cli.results.Exploration`): the Poincaré sections, the frequencies found, and
the brute-force orbit diagram over the bifurcation diagram.

No state name is assumed: the Poincaré plane is the first two states (the model's first two
dofs), the orbit diagram draws the first state (the first dof) unless told otherwise.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import WhirlError
from ..results import ContinuationResult, Exploration, MotionKind
from .key import PLOTTED_KINDS, axis_label, display_unit, new_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Colour of each class of motion (orbit diagram, spectrum).
KIND_COLOURS = {MotionKind.EQUILIBRIUM: "tab:green", MotionKind.PERIODIC: "tab:blue",
                MotionKind.QUASI_PERIODIC: "tab:orange", MotionKind.CHAOTIC: "tab:red",
                MotionKind.DIVERGED: "tab:gray"}


def exploration_label(found: Exploration) -> str:
    """``"<parameter> = <value>: <kind>"`` (a period-k orbit says k > 1)."""
    kind = found.kind + (f" (period {found.multiplicity})" if found.multiplicity > 1 else "")
    return f"{found.parameter} = {found.value:g}: {kind}"


def _explorations(continuation: ContinuationResult) -> tuple[Exploration, ...]:
    if not continuation.explorations:
        raise WhirlError(f"continuation {continuation.name!r} has no explorations "
                         "(explore: values)")
    return continuation.explorations


def _column(found: Exploration, state: str | None, position: int) -> int:
    if state is None:
        return position
    if state not in found.state_names:
        raise WhirlError(f"state {state!r} not among {', '.join(found.state_names)}")
    return found.state_names.index(state)


def _settled(found: Exploration) -> np.ndarray:
    """The section points the orbit diagram draws (m, n): all of them, but only the last of
    an equilibrium (the transient spirals in towards it)."""
    points = np.asarray(found.section, dtype=float).reshape(-1, len(found.state_names))
    return points[-1:] if found.kind == MotionKind.EQUILIBRIUM else points


def poincare_plot(continuation: ContinuationResult, x: str | None = None,
                  y: str | None = None, ax: Axes | None = None, degrees: bool = True,
                  title: str | None = None) -> Figure:
    """The Poincaré section points of every explored value: ``y`` (default the second
    state) against ``x`` (default the first), angles in degrees unless ``degrees`` is False,
    one colour per value, legend ``"<parameter> = <value>: <kind>"`` (a value without section
    points, e.g. an equilibrium, is in the legend only). Draws on ``ax`` if given, else on a
    new figure; returns the figure. Title ``title`` (None: the continuation's name)."""
    found = _explorations(continuation)
    if ax is None:
        ax = new_figure(figsize=(6.8, 5.6)).add_subplot()
    first = found[0]
    ix, iy = _column(first, x, 0), _column(first, y, 1 if len(first.state_names) > 1 else 0)
    fx, ux = display_unit(first.state_units[ix], degrees)
    fy, uy = display_unit(first.state_units[iy], degrees)
    for k, item in enumerate(found):
        points = np.asarray(item.section, dtype=float).reshape(-1, len(item.state_names))
        ax.scatter(fx * points[:, ix], fy * points[:, iy], s=12, color=f"C{k % 10}",
                   label=exploration_label(item), zorder=2)
    ax.set_xlabel(axis_label(first.state_names[ix], ux))
    ax.set_ylabel(axis_label(first.state_names[iy], uy))
    ax.legend(fontsize="small")
    ax.set_title(f"{continuation.name if title is None else title}\nPoincaré sections")
    return ax.figure


def spectrum_plot(continuation: ContinuationResult, ax: Axes | None = None,
                  title: str | None = None) -> Figure:
    """The frequencies found at each explored value against the parameter: every spectral
    peak as a small grey dot, the classified frequencies (the fundamental of a periodic
    orbit, the bases of a torus, the strongest peaks otherwise) as markers coloured by class
    (:data:`KIND_COLOURS`). Draws on ``ax`` if given, else on a new figure; returns it."""
    found = _explorations(continuation)
    if ax is None:
        ax = new_figure().add_subplot()
    peaks = [(item.value, f) for item in found for f in np.atleast_1d(item.peaks)]
    if peaks:
        ax.plot(*np.array(peaks).T, linestyle="none", marker=".", color="0.6", markersize=4,
                label="spectral peaks", zorder=1)
    for kind, colour in KIND_COLOURS.items():
        points = [(item.value, f) for item in found if item.kind == kind
                  for f in np.atleast_1d(item.frequencies)]
        if points:
            ax.plot(*np.array(points).T, linestyle="none", marker="o", color=colour,
                    label=kind, zorder=2)
    first = found[0]
    ax.set_xlabel(axis_label(first.parameter, first.unit))
    ax.set_ylabel(axis_label("frequency", "Hz"))
    ax.legend(fontsize="small")
    ax.set_title(f"{continuation.name if title is None else title}\nfrequencies by simulation")
    return ax.figure


def orbit_diagram(continuation: ContinuationResult, state: str | None = None,
                  ax: Axes | None = None, degrees: bool = True, title: str | None = None,
                  branches: bool = True) -> Figure:
    """The brute-force orbit diagram: for each explored value, the Poincaré section's values of
    ``state`` (default the first state, the model's first dof; degrees unless ``degrees`` is False)
    as dots against the parameter, coloured by class (:data:`KIND_COLOURS`); an equilibrium by its
    last section point (the decaying oscillation's, nearest the equilibrium), a value without
    section points (an equilibrium that does not oscillate, a divergence) by a triangle on the
    parameter axis. With ``branches`` and branches to draw, over the continuation's bifurcation
    diagram (:func:`~whirl_cli.plots.diagrams.bifurcation_diagram` of the same state, max and
    min: on the study's default section, at the first dof's minima, a stable cycle's dots lie
    on its min curve). Draws on ``ax`` if given, else on a new figure;
    returns the figure. Title ``title`` (None: the continuation's name)."""
    found = _explorations(continuation)
    if ax is None:
        ax = new_figure().add_subplot()
    first = found[0]
    column = _column(first, state, 0)
    name = first.state_names[column]
    handles, labels = [], []
    if branches and any(b.kind in PLOTTED_KINDS and name in b.state_names
                        for b in continuation.branches):
        from .diagrams import bifurcation_diagram

        bifurcation_diagram(continuation, name, which=("max", "min"), ax=ax, degrees=degrees)
        legend = ax.get_legend()
        if legend is not None:
            handles, labels = list(legend.legend_handles), [t.get_text() for t in
                                                            legend.get_texts()]
            legend.remove()
    factor, unit = display_unit(first.state_units[column], degrees)
    for kind, colour in KIND_COLOURS.items():
        chosen = [item for item in found if item.kind == kind]
        if not chosen:
            continue
        dots = [(item.value, factor * v) for item in chosen
                for v in _settled(item)[:, column]]
        bare = [item.value for item in chosen if not np.asarray(item.section).size]
        handle = None
        if dots:
            (handle,) = ax.plot(*np.array(dots).T, linestyle="none", marker="o",
                                markersize=5, color=colour, zorder=4)
        if bare:
            (marker,) = ax.plot(bare, np.zeros(len(bare)), linestyle="none", marker="^",
                                markersize=7, color=colour, zorder=4,
                                transform=ax.get_xaxis_transform(), clip_on=False)
            handle = handle or marker
        handles.append(handle)
        labels.append(f"{kind} (simulation)")
    ax.set_xlabel(axis_label(first.parameter, first.unit))
    ax.set_ylabel(axis_label(f"{name} (section)", unit))
    ax.legend(handles, labels, fontsize="small")
    ax.set_title(f"{continuation.name if title is None else title}\norbit diagram")
    return ax.figure
