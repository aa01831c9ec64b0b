"""Figures of linear sweeps: frequency and damping ratio of each mode against the parameter;
the root locus (eigenvalues in the complex plane, coloured by the parameter).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..results import LinearSweep
from ..units import HZ_PER_RAD_S
from .key import _colours, _new_figure, axis_label

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


def linear_sweep_plot(sweep: LinearSweep, hz: bool = False, title: str | None = None,
                      axes: tuple[Axes, Axes] | None = None) -> Figure:
    """Frequency [rad/s, or Hz if ``hz``] (top) and damping ratio [-] (bottom) of each mode vs
    the parameter.

    One line per column of ``sweep.eigenvalues``, drawn only where Im(lambda) > 0 so each
    conjugate pair appears once (real eigenvalues are not drawn). Lines are labelled with their
    whirl direction ("BW"/"FW", after the mode group for models with several: "nacelle BW";
    numbered if repeated); the damping panel has a zero line.
    Title: ``title`` (None: ``"linear analysis vs <parameter>"``). Draws on ``axes``
    (frequency, damping) if given, else on a new figure; returns the figure.
    """
    if axes is None:
        axes = _new_figure(figsize=(6.4, 6.4)).subplots(2, 1, sharex=True)
    ax_freq, ax_damp = axes
    figure = ax_freq.figure
    for (column, label), colour in zip(_mode_labels(sweep), _colours(), strict=False):
        upper = sweep.eigenvalues[:, column].imag > 0
        freq = np.where(upper, sweep.frequency[:, column], np.nan) * (HZ_PER_RAD_S if hz
                                                                      else 1.0)
        damp = np.where(upper, sweep.damping_ratio[:, column], np.nan)
        ax_freq.plot(sweep.values, freq, color=colour, label=label)
        ax_damp.plot(sweep.values, damp, color=colour, label=label)
    ax_damp.axhline(0.0, color="black", linewidth=0.8, label="_zero")
    ax_freq.set_ylabel(axis_label("frequency", "Hz" if hz else "rad/s"))
    ax_damp.set_ylabel(axis_label("damping ratio", ""))
    ax_damp.set_xlabel(axis_label(sweep.parameter, sweep.unit))
    if ax_freq.get_lines():
        ax_freq.legend(fontsize="small")
    ax_freq.set_title(f"linear analysis vs {sweep.parameter}" if title is None else title)
    return figure


#: Markers of the root locus by whirl direction (real roots: "--").
WHIRL_MARKERS = {"FW": "o", "BW": "s", "--": "x"}


def root_locus_plot(sweep: LinearSweep, title: str | None = None, ax: Axes | None = None
                    ) -> Figure:
    """The eigenvalues of every point of ``sweep`` in the complex plane [1/s], coloured by
    the parameter (colour bar), one marker per whirl direction (circle FW, square BW, cross
    real), with the imaginary axis drawn: a root crossing it to the right is a Hopf point
    (flutter), through the origin a divergence. Title: ``title`` (None: ``"root locus vs
    <parameter>"``). Draws on ``ax`` if given, else on a new figure; returns the figure."""
    if ax is None:
        ax = _new_figure().add_subplot()
    figure = ax.figure
    whirl = np.asarray(sweep.whirl).astype(str)
    values = np.repeat(np.asarray(sweep.values)[:, None], sweep.eigenvalues.shape[1], axis=1)
    scale = None
    for direction, marker in WHIRL_MARKERS.items():
        chosen = whirl == direction
        if chosen.any():
            scale = ax.scatter(sweep.eigenvalues.real[chosen], sweep.eigenvalues.imag[chosen],
                               c=values[chosen], cmap="viridis", marker=marker, s=9,
                               vmin=float(np.min(sweep.values)),
                               vmax=float(np.max(sweep.values)),
                               label={"--": "real root"}.get(direction, direction))
    ax.axvline(0.0, color="black", linewidth=0.8, label="_imaginary axis")
    ax.axhline(0.0, color="grey", linewidth=0.5, label="_real axis")
    if scale is not None:
        figure.colorbar(scale, ax=ax, label=axis_label(sweep.parameter, sweep.unit))
        ax.legend(fontsize="small", loc="upper left")
    ax.set_xlabel(axis_label("Re lambda", "1/s"))
    ax.set_ylabel(axis_label("Im lambda", "rad/s"))
    ax.set_title(f"root locus vs {sweep.parameter}" if title is None else title)
    return figure


def _mode_labels(sweep: LinearSweep) -> list[tuple[int, str]]:
    """(column, label) of the columns with Im(lambda) > 0 somewhere; label = majority whirl
    (with its mode group first, "gimbal FW", for a model with several groups)."""
    modes = []
    for column in range(sweep.eigenvalues.shape[1]):
        upper = sweep.eigenvalues[:, column].imag > 0
        if not upper.any():
            continue
        labels = np.asarray(sweep.whirl)[upper, column].astype(str)
        if sweep.mode_group is not None:
            labels = np.char.add(np.char.add(
                np.asarray(sweep.mode_group)[upper, column].astype(str), " "), labels)
        names, counts = np.unique(labels, return_counts=True)
        modes.append((column, str(names[np.argmax(counts)])))
    totals = {label: sum(1 for _, other in modes if other == label) for _, label in modes}
    seen: dict[str, int] = {}
    labelled = []
    for column, label in modes:
        seen[label] = seen.get(label, 0) + 1
        labelled.append((column, f"{label} {seen[label]}" if totals[label] > 1 else label))
    return labelled

