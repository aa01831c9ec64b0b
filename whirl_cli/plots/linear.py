"""Figures of linear sweeps: frequency and damping ratio of each mode against the parameter.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..results import LinearSweep
from ..units import HZ_PER_RAD_S
from .key import _colours, _new_figure, axis_label

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def linear_sweep_plot(sweep: LinearSweep, hz: bool = False, title: str | None = None
                      ) -> Figure:
    """Frequency [rad/s, or Hz if ``hz``] (top) and damping ratio [-] (bottom) of each mode vs
    the parameter.

    One line per column of ``sweep.eigenvalues``, drawn only where Im(lambda) > 0 so each
    conjugate pair appears once (real eigenvalues are not drawn). Lines are labelled with their
    whirl direction ("BW"/"FW", after the mode group for models with several: "nacelle BW";
    numbered if repeated); the damping panel has a zero line.
    Title: ``title`` (None: ``"linear analysis vs <parameter>"``).
    """
    figure = _new_figure(figsize=(6.4, 6.4))
    ax_freq, ax_damp = figure.subplots(2, 1, sharex=True)
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

