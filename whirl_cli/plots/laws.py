"""The stiffness laws themselves: restoring force against the dof, as AUTO continues it
(smoothed) and exact, beside the linear spring K x, drawn from the curves a result's
provenance stores (:class:`~whirl_cli.results.LawCurve`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..results import LawCurve, StudyResult
from .key import axis_label, display_unit, new_figure, symbol

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Styles: the law as AUTO continues it, its exact form, the linear spring of stiffness K.
LAW_STYLE = {"color": "C0", "linestyle": "-", "linewidth": 1.5}
EXACT_STYLE = {"color": "black", "linestyle": "--", "linewidth": 1.0}
LINEAR_STYLE = {"color": "grey", "linestyle": ":", "linewidth": 1.0}


def law_plot(curve: LawCurve, ax: Axes | None = None, title: str | None = None) -> Figure:
    """Restoring force M(x) of the law ``curve`` against x: as AUTO continues it (solid), its
    exact piecewise form where the law smooths one (dashed, e.g. freeplay), and the linear
    spring K x of the dof's stiffness (dotted); the breakpoints as thin vertical lines. x in
    degrees for angles; M in the stiffness's unit times the dof's (N m for an angle with K in
    N m/rad). Draws on ``ax`` if given, else on a new figure; returns the figure. Title:
    ``title`` (None: the law and its coefficients), wrapped at the canvas edge."""
    factor, unit = display_unit(curve.dof_unit, True)
    if ax is None:
        ax = new_figure().add_subplot()
    x, k = curve.x, curve.stiffness_value
    ax.plot(factor * x, k * x, label=f"linear spring ({symbol(curve.stiffness)} = {k:g})",
            **LINEAR_STYLE)
    ax.plot(factor * x, curve.force,
            label="as continued (smoothed)" if curve.exact is not None else "law", **LAW_STYLE)
    if curve.exact is not None:
        ax.plot(factor * x, curve.exact, label="exact", **EXACT_STYLE)
    for b in curve.breakpoints:
        ax.axvline(factor * b, color="grey", linewidth=0.5, label="_breakpoint")
    _labels(ax, curve, unit)
    ax.axhline(0.0, color="black", linewidth=0.5, zorder=0)
    ax.legend(fontsize="small")
    shown = ", ".join(f"{symbol(key)} = {value:.3g}"
                      for key, value in curve.coefficients.items())
    ax.set_title(f"{curve.law} law on {symbol(curve.dof)}: {shown}" if title is None else title,
                 wrap=True)
    return ax.figure


def _labels(ax: Axes, curve: LawCurve, unit: str) -> None:
    ax.set_xlabel(axis_label(curve.dof, unit))
    ax.set_ylabel(axis_label(f"restoring force on {curve.dof}", curve.force_unit))


def nonlinear_laws(result: StudyResult) -> tuple[LawCurve, ...]:
    """The laws of ``result`` that are not a linear spring at its study's values."""
    return result.provenance.nonlinear_laws


#: Line styles of the laws of :func:`laws_plot`, in turn (with the colour cycle).
LAW_LINESTYLES = ("-", "--", "-.", (0, (5, 1, 1, 1, 1, 1)))


def laws_plot(entries, ax: Axes | None = None, title: str | None = None) -> Figure:
    """Several stiffness laws on one axes: per entry (law curve, label) the restoring force as
    continued, each in its own colour and line style, beside the linear spring K x of each
    distinct linear stiffness (grey, dotted). x over the first entry's span, in degrees for
    angles. Title: ``title`` (None: none)."""
    from matplotlib import rcParams

    if ax is None:
        ax = new_figure().add_subplot()
    colours = rcParams["axes.prop_cycle"].by_key()["color"]
    springs: dict[float, str] = {}
    span = None
    for k, (curve, label) in enumerate(entries):
        span = float(np.max(np.abs(curve.x))) if span is None else span
        inside = np.abs(curve.x) <= span * (1 + 1e-12)
        x = curve.x[inside]
        factor, unit = display_unit(curve.dof_unit, True)
        stiffness = curve.stiffness_value
        if stiffness not in springs:
            springs[stiffness] = curve.stiffness
            ax.plot(factor * x, stiffness * x, **LINEAR_STYLE,
                    label=f"linear ({curve.stiffness} = {stiffness:g})")
        ax.plot(factor * x, curve.force[inside], color=colours[k % len(colours)],
                linestyle=LAW_LINESTYLES[k % len(LAW_LINESTYLES)], linewidth=1.5, label=label)
        _labels(ax, curve, unit)
    ax.axhline(0.0, color="black", linewidth=0.5, zorder=0, label="_zero")
    ax.axvline(0.0, color="black", linewidth=0.5, zorder=0, label="_zero")
    ax.legend(fontsize="small")
    if title is not None:
        ax.set_title(title)
    return ax.figure
