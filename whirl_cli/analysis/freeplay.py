"""Periodic branches in the units of a freeplay law, and the describing-function estimate.

With freeplay on a dof, every amplitude is proportional to the half-gap delta (exactly for
K_in = 0 with epsilon/delta fixed), so amplitudes are reported as A/delta, A the dof's half
peak-to-peak value over an orbit. The one-harmonic estimate of a limit cycle of amplitude A:
the deadband acts as the stiffness K_eq(A)
(:func:`whirl_cli.models.laws.freeplay.equivalent_stiffness`), so an LCO of amplitude A is
expected where the linear model with that stiffness has a Hopf point. Generic: any model,
any dof with the freeplay law; the linear model is the family with linear springs (its other
dofs keep their study stiffnesses).
"""

from __future__ import annotations

import numpy as np

from ..kinds import LocusKind
from ..models import Model, get_model
from ..models.laws.freeplay import FREEPLAY, equivalent_stiffness
from ..results import Branch, ContinuationResult, FreeplayAmplitudes
from .linear import critical_points

#: A/delta values of the estimate: from 1 (the gap) to this factor beyond the branch's largest.
ESTIMATE_REACH = 1.1


def freeplay_dofs(model: Model) -> tuple[str, ...]:
    """The dofs of ``model`` carrying the freeplay law."""
    return tuple(d for d, law in zip(model.family.dof_names, model.law_objects, strict=True)
                 if law is FREEPLAY)


def amplitude_ratio(model: Model, overrides: dict[str, float], branch: Branch,
                    dof: str) -> np.ndarray:
    """(N,) A/delta of ``dof`` along ``branch`` (delta per row: it may be continued)."""
    k = branch.state_names.index(dof)
    amplitude = (branch.state_max[:, k] - branch.state_min[:, k]) / 2
    name = model.coefficient_names(dof)["delta"]
    if name in branch.parameter_names:
        delta = branch.parameters[:, branch.parameter_names.index(name)]
    else:
        delta = np.full(len(branch), model.law_values(dof, overrides)["delta"])
    return amplitude / delta


def linear_onsets(model: Model, overrides: dict[str, float], dof: str, parameter: str,
                  bounds: tuple[float, float]) -> np.ndarray:
    """The Hopf points (values of ``parameter`` in ``bounds``) of the linear model with the
    stiffness of ``dof`` at the law's K_out: where linear analysis puts the flutter onset,
    which freeplay cycles undercut."""
    law = model.law_values(dof, overrides)
    linear = get_model(model.family)
    known = set(linear.parameter_names)
    fixed = {k: v for k, v in overrides.items() if k in known}
    stiffness = model.family.dof(dof).stiffness
    return np.array([p.value for p in critical_points(
        linear, {**fixed, stiffness: law["K_out"]}, parameter, *bounds, points=401)
        if p.kind == LocusKind.HOPF], dtype=float)


def describing_estimate(model: Model, overrides: dict[str, float], dof: str, parameter: str,
                        bounds: tuple[float, float], ratios: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(A/delta, K_eq, parameter value) of every Hopf point of the linear model with the
    stiffness of ``dof`` set to K_eq(A), for A/delta in ``ratios``, ``parameter`` in
    ``bounds`` (sorted by A/delta; rows repeat an A/delta with several Hopf points)."""
    law = model.law_values(dof, overrides)
    linear = get_model(model.family)
    stiffness = model.family.dof(dof).stiffness
    known = set(linear.parameter_names)
    fixed = {k: v for k, v in overrides.items() if k in known}
    rows = []
    for ratio in ratios:
        k_eq = float(equivalent_stiffness(ratio * law["delta"], law["delta"], law["K_in"],
                                          law["K_out"]))
        for point in critical_points(linear, {**fixed, stiffness: k_eq}, parameter, *bounds,
                                     points=201):
            if point.kind == LocusKind.HOPF:
                rows.append((float(ratio), k_eq, point.value))
    table = np.array(rows, dtype=float).reshape(-1, 3)
    return table[:, 0], table[:, 1], table[:, 2]


def freeplay_amplitudes(model: Model, overrides: dict[str, float],
                        continuation: ContinuationResult, bounds: tuple[float, float],
                        points: int = 40) -> tuple[FreeplayAmplitudes, ...]:
    """:class:`FreeplayAmplitudes` of every periodic branch of a one-parameter
    ``continuation`` and every freeplay dof of ``model`` (``overrides``: the study's parameter
    values by canonical name; ``bounds``: the continuation's range). The estimate spans A/delta
    from 1 to :data:`ESTIMATE_REACH` times the branch's largest, ``points`` values."""
    found = []
    linear_names = set(get_model(model.family).parameter_names)
    for dof in freeplay_dofs(model):
        own = set(model.coefficient_names(dof).values())
        for branch in continuation.branches:
            if not branch.is_periodic or not len(branch):
                continue
            ratio = amplitude_ratio(model, overrides, branch, dof)
            parameter = branch.parameter_names[0]
            top = float(np.nanmax(ratio)) * ESTIMATE_REACH if np.isfinite(ratio).any() else 0
            if parameter in own or parameter not in linear_names or top <= 1.0:
                estimate = (np.empty(0),) * 3
            else:
                estimate = describing_estimate(model, overrides, dof, parameter, bounds,
                                               np.linspace(1.0, top, points))
            stiffness = next(d.stiffness for d in model.dofs if d.name == dof)
            onset = np.empty(0) if parameter in own or parameter not in linear_names else \
                linear_onsets(model, overrides, dof, parameter, bounds)
            found.append(FreeplayAmplitudes(branch.name, dof, ratio, *estimate,
                                            stiffness_unit=model.parameter(stiffness).unit,
                                            parameter_unit=branch.parameter_units[0],
                                            onset=onset))
    return tuple(found)
