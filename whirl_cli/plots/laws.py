"""The stiffness laws themselves: restoring force against the dof, as AUTO continues it
(smoothed) and exact, beside the linear spring K x.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import WhirlError
from ..results import StudyResult
from .key import _new_figure, axis_label, display_unit

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..models import Model

#: Styles: the law as AUTO continues it, its exact form, the linear spring of stiffness K.
LAW_STYLE = {"color": "C0", "linestyle": "-", "linewidth": 1.5}
EXACT_STYLE = {"color": "black", "linestyle": "--", "linewidth": 1.0}
LINEAR_STYLE = {"color": "grey", "linestyle": ":", "linewidth": 1.0}
GAP_SPAN = 4.0  # a law with breakpoints is drawn over +-4 times its outermost breakpoint
DEFAULT_SPAN = 20.0  # else an angle over +-20 deg (other dofs: their typical amplitude)


def law_plot(model: Model, values: dict[str, float], dof: str, ax: Axes | None = None,
             span: float | None = None, title: str | None = None) -> Figure:
    """Restoring force M(x) of the law on ``dof`` of ``model`` at parameter ``values`` (by
    canonical name; unset ones at their datum) against x: as AUTO continues it (solid), its
    exact piecewise form where the law smooths one (dashed, e.g. freeplay), and the linear
    spring K x of the dof's stiffness (dotted); the breakpoints as thin vertical lines.
    x over +-``span`` (the dof's unit; None: 4 times the outermost breakpoint, else 20 deg /
    the dof's typical amplitude), shown in degrees for angles; M in the stiffness's unit
    times the dof's (N m for an angle with K in N m/rad). Draws on ``ax`` if given, else on
    a new figure; returns the figure. Title: ``title`` (None: the law and its coefficients)."""
    if dof not in model.family.dof_names:
        raise WhirlError(f"no dof {dof!r} (dofs: {', '.join(model.family.dof_names)})")
    law = model.law_on(dof)
    declared = model.family.dof(dof)
    coefficients = model.law_values(dof, values)
    full = {**model.defaults(), **values}
    k = full[declared.stiffness]
    breakpoints = law.breakpoints(coefficients) if law.breakpoints else ()
    if span is None:
        span = (GAP_SPAN * max(abs(b) for b in breakpoints) if breakpoints
                else np.radians(DEFAULT_SPAN) if declared.unit == "rad" else declared.amplitude)
    x = np.linspace(-span, span, 2001)
    if breakpoints:
        x = np.unique(np.concatenate([x, breakpoints]))  # the corners drawn exactly
    factor, unit = display_unit(declared.unit, True)
    if ax is None:
        ax = _new_figure().add_subplot()
    ax.plot(factor * x, k * x, label=f"linear spring ({declared.stiffness} = {k:g})",
            **LINEAR_STYLE)
    ax.plot(factor * x, law.force(x, k, coefficients),
            label="as continued (smoothed)" if law.exact else "law", **LAW_STYLE)
    if law.exact is not None:
        ax.plot(factor * x, law.exact_force(x, k, coefficients), label="exact", **EXACT_STYLE)
    for b in breakpoints:
        ax.axvline(factor * b, color="grey", linewidth=0.5, label="_breakpoint")
    stiffness_unit = model.parameter(declared.stiffness).unit
    moment_unit = stiffness_unit.removesuffix(f"/{declared.unit}") or stiffness_unit
    ax.set_xlabel(axis_label(dof, unit))
    ax.set_ylabel(axis_label(f"restoring force on {dof}", moment_unit))
    ax.axhline(0.0, color="black", linewidth=0.5, zorder=0)
    ax.legend(fontsize="small")
    shown = ", ".join(f"{key} = {value:g}" for key, value in coefficients.items())
    ax.set_title(f"{law.name} law on {dof}: {shown}" if title is None else title)
    return ax.figure


def nonlinear_laws(result: StudyResult) -> list[tuple[Model, dict[str, float], str]]:
    """(model variant, parameter values, dof) of every dof of ``result``'s stored study whose
    law is not a linear spring at its values ([] if the study text does not validate)."""
    from ..study import stored_study

    try:
        study = stored_study(result.attributes)
    except WhirlError:
        return []
    model, values = study.variant(), study.parameter_values()
    found = []
    for dof in model.family.dof_names:
        law = model.law_on(dof)
        if not law.is_linear(model.law_values(dof, values)):
            found.append((model, values, dof))
    return found


#: Line styles of the laws of :func:`laws_plot`, in turn (with the colour cycle).
LAW_LINESTYLES = ("-", "--", "-.", (0, (5, 1, 1, 1, 1, 1)))


def laws_plot(entries, ax: Axes | None = None, span: float | None = None,
              title: str | None = None) -> Figure:
    """Several stiffness laws on one axes: per entry (model, parameter values, dof, label)
    the restoring force as continued, each in its own colour and line style, beside the
    linear spring K x of each distinct linear stiffness (grey, dotted). x over +-``span``
    (None: as :func:`law_plot` does for the first entry), in degrees for angles. Title:
    ``title`` (None: none)."""
    from matplotlib import rcParams

    if ax is None:
        ax = _new_figure().add_subplot()
    colours = rcParams["axes.prop_cycle"].by_key()["color"]
    springs: dict[float, str] = {}
    for k, (model, values, dof, label) in enumerate(entries):
        law, declared = model.law_on(dof), model.family.dof(dof)
        coefficients = model.law_values(dof, values)
        stiffness = {**model.defaults(), **values}[declared.stiffness]
        if span is None:
            breakpoints = law.breakpoints(coefficients) if law.breakpoints else ()
            span = (GAP_SPAN * max(abs(b) for b in breakpoints) if breakpoints
                    else np.radians(DEFAULT_SPAN) if declared.unit == "rad"
                    else declared.amplitude)
        x = np.linspace(-span, span, 2001)
        factor, unit = display_unit(declared.unit, True)
        if stiffness not in springs:
            springs[stiffness] = declared.stiffness
            ax.plot(factor * x, stiffness * x, **LINEAR_STYLE,
                    label=f"linear ({declared.stiffness} = {stiffness:g})")
        ax.plot(factor * x, law.force(x, stiffness, coefficients), color=colours[k % len(colours)],
                linestyle=LAW_LINESTYLES[k % len(LAW_LINESTYLES)], linewidth=1.5, label=label)
        stiffness_unit = model.parameter(declared.stiffness).unit
        moment_unit = stiffness_unit.removesuffix(f"/{declared.unit}") or stiffness_unit
        ax.set_xlabel(axis_label(dof, unit))
        ax.set_ylabel(axis_label(f"restoring force on {dof}", moment_unit))
    ax.axhline(0.0, color="black", linewidth=0.5, zorder=0, label="_zero")
    ax.axvline(0.0, color="black", linewidth=0.5, zorder=0, label="_zero")
    ax.legend(fontsize="small")
    if title is not None:
        ax.set_title(title)
    return ax.figure
