"""Figures of linear sweeps: frequency and damping ratio of each mode against the parameter;
the root locus (eigenvalues in the complex plane, coloured by the parameter); the damping and
frequency of the least-damped mode of several sweeps against parameter / datum.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..results import LinearSweep, Spacing
from ..units import HZ_PER_RAD_S
from .key import axis_label, colour_cycle, log_scale_if_decades, new_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


def linear_sweep_plot(sweep: LinearSweep, hz: bool = False, title: str | None = None,
                      axes: tuple[Axes, Axes] | None = None) -> Figure:
    """Frequency [rad/s, or Hz if ``hz``] (top) and damping ratio [-] (bottom) of each mode vs
    the parameter.

    One line per column of ``sweep.eigenvalues``, drawn only where Im(lambda) > 0 so each
    conjugate pair appears once (real eigenvalues are not drawn). Lines are labelled with the
    stored labels along them (:func:`_mode_labels`); a mode whose damping ratio falls below
    zero somewhere (flutter) is
    drawn in :data:`UNSTABLE_COLOURS`, the others in :data:`STABLE_COLOURS`. Each crossing of
    zero by a damping ratio (:func:`zero_crossings`) is marked on both panels and named with
    its value in the legend (and the stored label there, on a line with several); the
    damping panel has a zero line. The parameter axis is log if
    the sweep spans decades or samples log (:func:`~.key.log_scale_if_decades`).
    Title: ``title`` (None: ``"linear analysis vs <parameter>"``). Draws on ``axes``
    (frequency, damping) if given, else on a new figure; returns the figure.
    """
    if axes is None:
        axes = new_figure(figsize=(6.4, 6.4)).subplots(2, 1, sharex=True)
    ax_freq, ax_damp = axes
    figure = ax_freq.figure
    scale = HZ_PER_RAD_S if hz else 1.0
    crossings = zero_crossings(sweep)
    unstable = iter(UNSTABLE_COLOURS * len(sweep.eigenvalues.T))
    stable = iter(STABLE_COLOURS * len(sweep.eigenvalues.T))
    stored = stored_labels(sweep)
    for column, label in _mode_labels(sweep):
        several = len(set(stored[sweep.eigenvalues[:, column].imag > 0, column])) > 1
        upper = sweep.eigenvalues[:, column].imag > 0
        freq = np.where(upper, sweep.frequency[:, column], np.nan) * scale
        damp = np.where(upper, sweep.damping_ratio[:, column], np.nan)
        flutters = bool(np.nanmin(damp) < 0.0)
        colour = next(unstable if flutters else stable)
        style = {"color": colour, "linewidth": 1.8 if flutters else 1.2}
        ax_freq.plot(sweep.values, freq, label=label, **style)
        ax_damp.plot(sweep.values, damp, label=label, **style)
        for value, frequency in crossings.get(column, ()):
            ax_freq.plot([value], [frequency * scale], **ONSET_STYLE, label="_onset")
            mode = f", {_label_at(sweep, stored[:, column], value)}" if several else ""
            ax_damp.plot([value], [0.0], **ONSET_STYLE,
                         label=f"damping ratio 0 ({_onset_text(sweep, value)}{mode})")
    for ax in (ax_freq, ax_damp):
        for value in sorted({v for found in crossings.values() for v, _ in found}):
            ax.axvline(value, color="black", linewidth=0.6, linestyle=":", label="_onset",
                       zorder=0)
    ax_damp.axhline(0.0, color="black", linewidth=0.8, label="_zero")
    ax_freq.set_ylabel(axis_label("frequency", "Hz" if hz else "rad/s"))
    ax_damp.set_ylabel(axis_label("damping ratio", ""))
    ax_damp.set_xlabel(axis_label(sweep.parameter, sweep.unit))
    for ax in (ax_freq, ax_damp):
        log_scale_if_decades(ax, "x", sweep.values, sweep.spacing)
    if ax_freq.get_lines():
        handles, labels = ax_freq.get_legend_handles_labels()
        more, named = ax_damp.get_legend_handles_labels()
        extra = [(h, n) for h, n in zip(more, named, strict=True) if n not in labels]
        ax_freq.legend(handles + [h for h, _ in extra], labels + [n for _, n in extra],
                       fontsize="small")
    ax_freq.set_title(f"linear analysis vs {sweep.parameter}" if title is None else title)
    return figure


#: Colours of the modes that flutter somewhere in a sweep, and of the others (in turn).
UNSTABLE_COLOURS = ("C3", "C1", "C6")
STABLE_COLOURS = ("C0", "C2", "C4", "C9", "C5", "C7", "C8")
#: The marker of a damping ratio crossing zero.
ONSET_STYLE = {"marker": "o", "markersize": 6, "markerfacecolor": "white",
               "markeredgecolor": "black", "linestyle": "none", "zorder": 4}


def zero_crossings(sweep: LinearSweep) -> dict[int, list[tuple[float, float]]]:
    """Per column of ``sweep`` (modes with Im(lambda) > 0 at both ends of an interval), the
    (parameter, frequency [rad/s]) where its damping ratio crosses zero, interpolated
    linearly between the sweep's points; a point exactly at zero counts once."""
    values = np.asarray(sweep.values, dtype=float)
    found: dict[int, list[tuple[float, float]]] = {}
    for column in range(sweep.eigenvalues.shape[1]):
        upper = np.asarray(sweep.eigenvalues)[:, column].imag > 0
        zeta = np.where(upper, np.asarray(sweep.damping_ratio)[:, column], np.nan)
        freq = np.asarray(sweep.frequency)[:, column]
        for k in range(len(values) - 1):
            a, b = zeta[k], zeta[k + 1]
            if not (np.isfinite(a) and np.isfinite(b)) or a == b or a * b > 0 or b == 0:
                continue
            t = a / (a - b)
            found.setdefault(column, []).append(
                (float(values[k] + t * (values[k + 1] - values[k])),
                 float(freq[k] + t * (freq[k + 1] - freq[k]))))
    return found


def _onset_text(sweep: LinearSweep, value: float) -> str:
    unit = f" {sweep.unit}" if sweep.unit not in ("", "1") else ""
    return f"{sweep.parameter} = {value:.4g}{unit}"


#: Markers of the root locus by whirl direction (real roots: "--").
WHIRL_MARKERS = {"FW": "o", "BW": "s", "--": "x"}


def root_locus_plot(sweep: LinearSweep, title: str | None = None, ax: Axes | None = None
                    ) -> Figure:
    """The eigenvalues of every point of ``sweep`` in the complex plane [1/s], coloured by
    the parameter (colour bar), one marker per whirl direction (circle FW, square BW, cross
    real), with the axes drawn under them: a root crossing the imaginary axis to the right
    is a Hopf point (flutter), through the origin a divergence. Marked
    (:mod:`whirl_cli.plots.argand`): each crossing of the imaginary axis and each
    coalescence of real roots, an arrow per oscillatory mode in the sense of the increasing
    parameter, and a zoom on the crossings in the emptiest corner. Title: ``title`` (None:
    ``"root locus vs <parameter>"``). Draws on ``ax`` if given, else on a new figure;
    returns the figure."""
    from .argand import direction_arrows, draw_zoom, locus_events, mark_events
    from .key import symbol

    if ax is None:
        ax = new_figure().add_subplot()
    figure = ax.figure
    scale = _draw_roots(ax, sweep)
    events = locus_events(sweep)
    mark_events(ax, events)
    direction_arrows(ax, sweep, f"{symbol(sweep.parameter)} increasing", events)
    if scale is not None:
        figure.colorbar(scale, ax=ax, label=axis_label(sweep.parameter, sweep.unit))
    corner = draw_zoom(ax, sweep, events, lambda inset: _draw_roots(inset, sweep))
    if scale is not None:  # the legend beside the zoom, if there is one
        ax.legend(fontsize="small", loc="best" if corner is None else
                  f"{'upper' if corner[1] > 0 else 'lower'} "
                  f"{'right' if corner[0] == 0 else 'left'}")
    ax.set_xlabel(axis_label("Re $\\lambda$", "1/s"))
    ax.set_ylabel(axis_label("Im $\\lambda$", "rad/s"))
    ax.set_title(f"root locus vs {sweep.parameter}" if title is None else title)
    return figure


def _draw_roots(ax: Axes, sweep: LinearSweep):
    """The roots of ``sweep`` on ``ax`` by whirl direction, over the real and imaginary
    axes; the last scatter (for a colour bar), None if nothing was drawn."""
    whirl = np.asarray(sweep.whirl).astype(str)
    values = np.repeat(np.asarray(sweep.values)[:, None], sweep.eigenvalues.shape[1], axis=1)
    scale = None
    for direction, marker in WHIRL_MARKERS.items():
        chosen = whirl == direction
        if chosen.any():
            scale = ax.scatter(sweep.eigenvalues.real[chosen], sweep.eigenvalues.imag[chosen],
                               c=values[chosen], cmap="viridis", marker=marker, s=9,
                               vmin=float(np.min(sweep.values)),
                               vmax=float(np.max(sweep.values)), zorder=2,
                               label={"--": "real root"}.get(direction, direction))
    ax.axvline(0.0, color="black", linewidth=0.8, label="_imaginary axis", zorder=0)
    ax.axhline(0.0, color="grey", linewidth=0.5, label="_real axis", zorder=0)
    return scale


def sweep_datum(sweep: LinearSweep, datums: Mapping[str, float] | None = None
                ) -> float | None:
    """The datum ``sweep`` is drawn in multiples of: the one it stores, else
    ``datums[parameter]`` (older files: the file's parameter set); None if neither has it
    or it is 0."""
    datum = sweep.datum if sweep.datum is not None else (datums or {}).get(sweep.parameter)
    return float(datum) if datum is not None and float(datum) != 0.0 else None


def least_damped(sweep: LinearSweep) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(damping ratio, frequency [rad/s], whirl label) per point of the oscillatory mode with
    the smallest damping ratio there (modes with Im(lambda) > 0; the label has the mode group
    first for models with several, "nacelle BW"); NaN and "" where no mode oscillates.
    Damping ratios equal to 1e-9 (FW and BW have equal ones without the aerodynamic
    coupling, ``aero_coupling = 0``) go to the lowest-frequency mode, so the curve does not
    hop between them."""
    upper = np.asarray(sweep.eigenvalues).imag > 0
    damping = np.where(upper, sweep.damping_ratio, np.inf)
    lowest = np.min(damping, axis=1, keepdims=True)
    tied = damping <= lowest + 1e-9 * np.where(np.isfinite(lowest), np.abs(lowest), 0.0) + 1e-15
    column = np.argmax(tied, axis=1)[:, None]  # the first (lowest-frequency) of equal ones
    some = upper.any(axis=1)
    zeta = np.where(some, np.take_along_axis(damping, column, axis=1)[:, 0], np.nan)
    freq = np.where(some, np.take_along_axis(np.asarray(sweep.frequency), column,
                                             axis=1)[:, 0], np.nan)
    labels = np.take_along_axis(stored_labels(sweep), column, axis=1)[:, 0]
    return zeta, freq, np.where(some, labels, "")


def damping_multiples_plot(sweeps: Sequence[LinearSweep],
                           datums: Mapping[str, float] | None = None, hz: bool = False,
                           title: str | None = None,
                           axes: tuple[Axes, Axes] | None = None) -> Figure:
    """Damping ratio [-] (top) and frequency [rad/s, or Hz if ``hz``] (bottom) of the
    least-damped mode (:func:`least_damped`) of each sweep against parameter / datum (thesis
    figs. 3.9-3.11): one line per sweep in each panel, labelled by its parameter and the whirl
    direction(s) of that mode in the order they appear along the sweep ("I_x (BW)",
    "R (BW, FW)"; the mode group first for models with several); a dot marks each point
    where the least-damped mode changes direction. The datum is the sweep's own
    (:func:`sweep_datum`, else ``datums``); sweeps without a non-zero datum are left out.
    A zero line on the damping panel, the datum (x = 1) dotted on both. The x axis is log if
    the multiples span decades or every sweep drawn samples log.

    ``axes``: (damping axes, frequency axes) to draw into (None: a new figure). Title:
    ``title`` (None: ``"least-damped mode vs parameter multiples"``).
    """
    if axes is None:
        figure = new_figure(figsize=(6.4, 6.4))
        ax_damp, ax_freq = figure.subplots(2, 1, sharex=True)
    else:
        ax_damp, ax_freq = axes
        figure = ax_damp.figure
    scale = HZ_PER_RAD_S if hz else 1.0
    colours = colour_cycle()
    drawn: list[tuple[np.ndarray, Spacing]] = []
    for sweep in sweeps:
        datum = sweep_datum(sweep, datums)
        if datum is None:
            continue
        zeta, freq, whirl = least_damped(sweep)
        shown = [w for w in dict.fromkeys(whirl) if w]
        label = f"{sweep.parameter} ({', '.join(shown)})" if shown else sweep.parameter
        changes = [k for k in range(1, len(whirl)) if whirl[k] and whirl[k - 1]
                   and whirl[k] != whirl[k - 1]]
        x = np.asarray(sweep.values, dtype=float) / datum
        style = {"color": next(colours), "label": label}
        if changes:
            style.update(marker="o", markersize=4, markevery=changes)
        ax_damp.plot(x, zeta, **style)
        ax_freq.plot(x, freq * scale, **style)
        drawn.append((x, sweep.spacing))
    ax_damp.axhline(0.0, color="black", linewidth=0.8, label="_zero")
    for ax in (ax_damp, ax_freq):
        ax.axvline(1.0, color="grey", linewidth=0.8, linestyle=":", label="_datum")
    ax_damp.set_ylabel(axis_label("damping ratio", ""))
    ax_freq.set_ylabel(axis_label("frequency", "Hz" if hz else "rad/s"))
    ax_freq.set_xlabel("parameter / datum")
    if drawn:
        spacing = Spacing.LOG if all(s == Spacing.LOG for _, s in drawn) else Spacing.LINEAR
        for ax in (ax_damp, ax_freq):
            log_scale_if_decades(ax, "x", np.concatenate([x for x, _ in drawn]), spacing)
        ax_damp.legend(fontsize="small")
    ax_damp.set_title("least-damped mode vs parameter multiples" if title is None else title)
    return figure


def stored_labels(sweep: LinearSweep) -> np.ndarray:
    """(M, n) str: each eigenvalue's stored whirl label, after its mode group for a model
    with several ("gimbal FW")."""
    labels = np.asarray(sweep.whirl).astype(str)
    if sweep.mode_group is None:
        return labels
    return np.char.add(np.char.add(np.asarray(sweep.mode_group).astype(str), " "), labels)


def _label_at(sweep: LinearSweep, labels: np.ndarray, value: float) -> str:
    """The one of ``labels`` (M,) stored at the sweep's point nearest ``value``."""
    return str(labels[int(np.argmin(np.abs(np.asarray(sweep.values, dtype=float) - value)))])


def _mode_labels(sweep: LinearSweep) -> list[tuple[int, str]]:
    """(column, label) of the columns with Im(lambda) > 0 somewhere; label = the stored
    labels (:func:`stored_labels`) along the column where Im(lambda) > 0, each once in the
    order they first appear ("BW", "BW, FW"; for several mode groups each group's
    directions after it, "nacelle FW, BW → gimbal FW, BW"); numbered if repeated."""
    stored = stored_labels(sweep)
    modes = []
    for column in range(sweep.eigenvalues.shape[1]):
        upper = sweep.eigenvalues[:, column].imag > 0
        if not upper.any():
            continue
        shown = dict.fromkeys(stored[upper, column].tolist())
        if sweep.mode_group is None:
            modes.append((column, ", ".join(shown)))
            continue
        groups: dict[str, list[str]] = {}
        for label in shown:
            group, _, whirl = label.rpartition(" ")
            groups.setdefault(group, []).append(whirl)
        modes.append((column, " → ".join(f"{group} {', '.join(whirls)}"
                                              for group, whirls in groups.items())))
    totals = {label: sum(1 for _, other in modes if other == label) for _, label in modes}
    seen: dict[str, int] = {}
    labelled = []
    for column, label in modes:
        seen[label] = seen.get(label, 0) + 1
        labelled.append((column, f"{label} {seen[label]}" if totals[label] > 1 else label))
    return labelled

