"""Freeplay figures: periodic branches as A/delta against the continuation parameter, with the
describing-function estimate dashed (:mod:`whirl_cli.analysis.freeplay`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..results import ContinuationResult
from .key import (
    PLOT_KEY,
    axis_label,
    branch_style,
    log_scale_if_decades,
    new_figure,
    plot_styled,
    stability_curves,
    symbol,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Style of the describing-function estimate (dashed black).
ESTIMATE_STYLE = {"color": "black", "linestyle": "--", "linewidth": 1.0}
#: The linear flutter onset with the dof's stiffness at K_out (dash-dotted grey).
ONSET_STYLE = {"color": "grey", "linestyle": "-.", "linewidth": 1.0}


def amplitude_diagram(continuation: ContinuationResult, ax: Axes | None = None) -> Figure:
    """A/delta (A: half peak-to-peak of the freeplay dof, delta its half-gap) of every periodic
    branch with freeplay amplitudes (``continuation.freeplay``) against its principal
    parameter, stable solid blue and unstable dotted red (:data:`PLOT_KEY`), and the
    describing-function estimate of each branch dashed; a dotted line marks A/delta = 1 (the
    gap), dash-dotted vertical lines the linear onset with the stiffness at K_out. Without
    freeplay amplitudes the axes stay empty. Draws on ``ax`` if given, else on a new figure;
    returns the figure."""
    if ax is None:
        ax = new_figure().add_subplot()
    by_name = {b.name: b for b in continuation.branches}
    first: dict[str, object] = {}
    estimate = None
    onsets: set[float] = set()
    dofs = []
    ratios = []
    x_label = None
    for found in continuation.freeplay:
        branch = by_name.get(found.branch)
        if branch is None:
            continue
        dofs.append(found.dof)
        ratios.append(found.amplitude_ratio)
        x_label = axis_label(branch.parameter_names[0], branch.parameter_units[0])
        for xs, ys, stable in stability_curves(branch.parameters[:, 0], found.amplitude_ratio,
                                                 branch.stable, branch.stability_known):
            plot_styled(ax, xs, ys, branch_style(branch.kind, stable), first)
        if len(found.estimate_ratio):
            (estimate,) = ax.plot(found.estimate_parameter, found.estimate_ratio,
                                  label="_estimate", **ESTIMATE_STYLE)
        onsets.update(float(v) for v in found.onset)
    handles = [first[key] for key in PLOT_KEY if key in first]
    labels = [str(PLOT_KEY[key]["label"]) for key in PLOT_KEY if key in first]
    if estimate is not None:
        handles.append(estimate)
        labels.append("describing function (one harmonic)")
    for k, value in enumerate(sorted(onsets)):
        line = ax.axvline(value, **ONSET_STYLE)
        if k == 0:
            handles.append(line)
            labels.append("linear onset (stiffness $K_{out}$)")
    if dofs:
        ax.axhline(1.0, color="grey", linestyle=":", linewidth=0.8)
        ax.set_xlabel(x_label)
        named = ", ".join(symbol(dof) for dof in sorted(set(dofs)))
        ax.set_ylabel(axis_label(f"$A/\\delta$ of {named}", "1"))
        if not log_scale_if_decades(ax, "y", np.concatenate(ratios)):
            ax.set_ylim(bottom=0.0)
    if handles:
        ax.legend(handles, labels, fontsize="small")
    ax.set_title(f"{continuation.name}: amplitude in half-gaps")
    return ax.figure


def has_amplitudes(continuation: ContinuationResult) -> bool:
    """True if the continuation has freeplay amplitudes to draw."""
    return any(np.size(f.amplitude_ratio) for f in continuation.freeplay)
