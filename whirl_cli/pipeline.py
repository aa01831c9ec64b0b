"""A whole study, end to end: Study -> model -> AUTO runs + linear analysis -> StudyResult.

``run_study`` is what ``whirl run`` calls; it does not write files other than AUTO's working
directories under ``workroot`` (the caller stores the result with :mod:`whirl_cli.store`).
"""

from __future__ import annotations

import subprocess
from collections.abc import Callable
from dataclasses import replace
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from . import __version__, linear, simulate
from .auto import RunOutcome, auto_version
from .recipes import Engine, Numerics, one_parameter
from .results import ContinuationResult, StudyResult
from .study import Study


def provenance(study: Study) -> dict[str, str]:
    """Root attributes of a result file: versions, the study text and its hash."""
    attributes = {
        "whirl_version": __version__,
        "auto_version": auto_version(),
        "study_yaml": study.source,
        "study_sha256": study.sha256,
        "created": datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
    }
    try:
        described = subprocess.run(["git", "describe", "--always", "--dirty"],
                                   cwd=Path(__file__).parent, capture_output=True, text=True,
                                   timeout=5, check=False)
        if described.returncode == 0 and described.stdout.strip():
            attributes["git_describe"] = described.stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        pass
    return attributes


def run_study(study: Study, workroot: Path, jobs: int = 1,
              on_run: Callable[[RunOutcome], None] | None = None) -> StudyResult:
    """Run every continuation and linear sweep of ``study``; AUTO works under ``workroot``."""
    model = study.variant()
    parameters = study.parameter_values()
    numerics = Numerics.from_settings(study.auto)
    continuations: list[ContinuationResult] = []
    engine = None
    if study.continuations:
        engine = Engine(model, workroot, jobs=jobs, timeout=numerics.timeout, on_run=on_run)
    for spec in study.continuations:
        assert engine is not None
        continuations.append(one_parameter(
            engine, spec.name, spec.parameter, spec.start, tuple(spec.range), parameters,
            numerics, branch_points=spec.branch_points, periodic=spec.periodic,
            orbits_at=spec.orbits_at))
    if study.cross_check:
        continuations = [replace(c, cross_checks=simulate.cross_check(model, parameters,
                                                                      c.branches))
                         for c in continuations]
    sweeps = []
    if study.linear is not None:
        for sweep in study.linear.sweeps:
            values = np.linspace(sweep.range[0], sweep.range[1], sweep.points)
            sweeps.append(linear.sweep(model, parameters, sweep.parameter, values))
    return StudyResult(
        study_name=study.name, model=model.name, continuations=tuple(continuations),
        linear_sweeps=tuple(sweeps), runs=engine.records() if engine else (),
        attributes=provenance(study))
