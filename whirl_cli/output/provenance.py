"""Provenance of a result: which whirl, which AUTO, which study text made it, and what of the
study its figures name (:class:`~whirl_cli.results.Provenance`).

:func:`code_sha256` fingerprints whirl's own source code, so that a result counts as up to
date (``whirl sweep``) only while the code that produced it is unchanged: the version number
alone stays the same through commits that change results.
"""

from __future__ import annotations

import hashlib
import subprocess
from dataclasses import replace
from datetime import UTC, datetime
from functools import cache
from pathlib import Path

import numpy as np

from .. import __version__
from ..models import file_key
from ..results import (
    FixedParameter,
    LawCurve,
    ParameterValue,
    Provenance,
    SliceLabel,
    StudyResult,
)

PACKAGE = Path(__file__).resolve().parent.parent
#: A law with breakpoints is drawn over +-4 times its outermost breakpoint, else an angle
#: over +-20 deg (other dofs: their typical amplitude), in this many points.
GAP_SPAN, DEFAULT_SPAN, CURVE_POINTS = 4.0, 20.0, 2001


@cache
def code_sha256() -> str:
    """sha256 over the package's Python sources (path and text of every ``*.py`` file under
    ``whirl_cli/``, in sorted order)."""
    digest = hashlib.sha256()
    for path in sorted(PACKAGE.rglob("*.py")):
        digest.update(path.relative_to(PACKAGE).as_posix().encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()


def provenance(study) -> Provenance:
    """The provenance of a result of ``study`` made now: versions, the code fingerprint, the
    study text and its hash, the model file, the time of creation (UTC), ``git describe``
    where available, and what the study sets (:func:`study_parts`)."""
    from ..auto.toolchain import auto_version

    family = study.variant().family
    found = Provenance(
        whirl_version=__version__, whirl_code_sha256=code_sha256(),
        git_describe=_git_describe(), auto_version=auto_version(),
        created=datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        study_yaml=study.source, study_sha256=study.sha256,
        first_order_states=",".join(x.name for x in family.first_order))
    if file_key(study.model):  # a model file: the equations that made the result, their hash
        found = replace(found, model_file=study.model, model_file_yaml=family.source,
                        model_file_sha256=hashlib.sha256(family.source.encode()).hexdigest(),
                        model_key=family.key)
    return study_parts(found, study)


def _git_describe() -> str:
    try:
        described = subprocess.run(["git", "describe", "--always", "--dirty"], cwd=PACKAGE,
                                   capture_output=True, text=True, timeout=5, check=False)
    except (OSError, subprocess.TimeoutExpired):
        return ""
    return described.stdout.strip() if described.returncode == 0 else ""


def study_parts(found: Provenance, study) -> Provenance:
    """``found`` with what ``study`` sets: its fixed parameters (canonical names, in the order
    written), the labels of its slices, the law on every dof, its ``plot_state``, the dofs."""
    names, model = study.names(), study.variant()
    values = study.parameter_values()
    fixed = tuple(FixedParameter(names.canonical(key), float(value), names.parameter(key).unit)
                  for key, value in study.parameters.items())
    slices = tuple(SliceLabel(c.name, k, label) for c in study.continuations
                   for k, label in enumerate(c.slice_labels))
    laws = tuple(law_curve(model, values, dof) for dof in model.family.dof_names)
    return replace(found, fixed=fixed, slices=slices, laws=laws,
                   plot_state=study.plot_state or "", dofs=tuple(model.family.dof_names),
                   family=study.model)


def stored_model(result: StudyResult, label: str = "<stored model>"):
    """The model variant that made ``result``, from its provenance: the family it names (the
    model file stored with it for a model file; messages name it ``label``) with the law of
    each dof. WhirlError if the provenance does not record them."""
    from ..errors import WhirlError
    from ..models import get_model, is_known, register_model_text

    found = result.provenance
    if not found.laws or not found.family:
        raise WhirlError(f"{label}: the result records no model (a file of an older whirl "
                         "whose stored study no longer validates)")
    if found.model_file_yaml and not is_known(found.family):
        register_model_text(found.family, found.model_file_yaml, label)
    return get_model(found.family, tuple(law.law for law in found.laws))


def law_curve(model, values: dict[str, float], dof: str) -> LawCurve:
    """The law on ``dof`` of ``model`` at parameter ``values`` (canonical names; unset ones at
    their datum), its restoring force sampled where it is not linear: over +-4 times its
    outermost breakpoint (the breakpoints themselves included), else +-20 deg for an angle
    and the dof's typical amplitude otherwise."""
    law, declared = model.law_on(dof), model.family.dof(dof)
    coefficients = model.law_values(dof, values)
    k = float({**model.defaults(), **values}[declared.stiffness])
    linear = bool(law.is_linear(coefficients))
    breakpoints = tuple(float(b) for b in law.breakpoints(coefficients)) \
        if law.breakpoints else ()
    unit = model.parameter(declared.stiffness).unit
    x = force = np.empty(0)
    exact = None
    if not linear:
        span = (GAP_SPAN * max(abs(b) for b in breakpoints) if breakpoints
                else np.radians(DEFAULT_SPAN) if declared.unit == "rad" else declared.amplitude)
        x = np.linspace(-span, span, CURVE_POINTS)
        if breakpoints:
            x = np.unique(np.concatenate([x, breakpoints]))  # the corners drawn exactly
        force = np.asarray(law.force(x, k, coefficients), dtype=float)
        if law.exact is not None:
            exact = np.asarray(law.exact_force(x, k, coefficients), dtype=float)
    return LawCurve(dof, law.name, tuple(coefficients), tuple(map(float,
                    coefficients.values())), linear, declared.stiffness, k,
                    unit.removesuffix(f"/{declared.unit}") or unit, declared.unit, breakpoints,
                    x, force, exact)


def resolved_parameters(model, overrides: dict[str, float]) -> tuple[ParameterValue, ...]:
    """Every parameter of ``model`` as the study runs it: its value (``overrides``, by any
    spelling, else the datum), datum and unit."""
    values = model.parameter_vector(overrides)
    return tuple(ParameterValue(p.name, float(v), float(p.default), p.unit)
                 for p, v in zip(model.parameters, values, strict=True))


def upgraded(result: StudyResult) -> StudyResult:
    """``result`` as read from a file written before whirl stored its provenance group, with
    what newer files hold read off the study stored with it: the provenance's fixed
    parameters, slice labels and laws, the parameter set (schema 1 files have none),
    canonical parameter names (older files may use the study's aliases, K1 for K_theta) and
    each linear sweep's datum. As it is if that study no longer validates."""
    from ..errors import WhirlError
    from ..study import stored_study

    try:
        study = stored_study(result.provenance)
    except WhirlError:
        return result
    names = study.names()
    parameters = result.parameters or resolved_parameters(study.variant(),
                                                          study.parameter_values())
    datums = {p.name: p.datum for p in parameters}
    canonical = _canonical_names(names)
    return replace(
        result, provenance=study_parts(result.provenance, study), parameters=parameters,
        continuations=tuple(replace(
            c, branches=tuple(replace(b, parameter_names=canonical(b.parameter_names))
                              for b in c.branches),
            special_points=tuple(replace(p, parameter_names=canonical(p.parameter_names))
                                 for p in c.special_points))
            for c in result.continuations),
        linear_sweeps=tuple(replace(s, parameter=canonical((s.parameter,))[0],
                                    datum=s.datum if s.datum is not None
                                    else datums.get(canonical((s.parameter,))[0]))
                            for s in result.linear_sweeps))


def _canonical_names(names):
    """A function from parameter names to their canonical names under the study's ``names``
    (a name it does not know kept as it is)."""
    known = set(names.known_parameter_names())
    return lambda found: tuple(names.canonical(n) if n in known else n for n in found)
