"""Continuation recipes: which AUTO runs to make, in what order, with which constants.

A recipe turns one continuation of a study into AUTO runs (:class:`RunSpec`), executes them
through an :class:`Engine` (independent runs in parallel) and collects the branches and special
points into a :class:`~whirl_cli.results.ContinuationResult`.

One-parameter equilibria (:func:`one_parameter`):
1. the main branch from the start value, both directions, to the ends of the range;
2. at every branch point (BP) found, branch switching (ISW=-1) in both directions to the
   secondary (static-divergence) equilibria, recursively for branch points on those branches
   (each point once).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

from . import auto
from .branches import read_branch
from .codegen import base_constants, fortran_source, par_layout, source_key
from .models import Model
from .results import Branch, BranchKind, ContinuationResult, PointType, RunRecord, SpecialPoint

#: How deep branch switching recurses (main -> secondary -> tertiary).
MAX_SWITCH_DEPTH = 3


@dataclass(frozen=True)
class Numerics:
    """Resolved AUTO numerics under readable names (study ``auto:`` keys override them).

    Step sizes are fractions of the width of the continuation range, so one set of defaults
    serves every parameter (the model's time is non-dimensional, see ``models/base.py``).
    """

    max_steps: int = 2000  # NMX
    step_initial: float = 0.002  # |DS| / range width
    step_min: float = 1e-7  # DSMIN / range width
    step_max: float = 0.02  # DSMAX / range width
    mesh_intervals: int = 40  # NTST
    collocation_points: int = 4  # NCOL
    newton_max_iterations: int = 7  # ITNW
    tolerance: float = 1e-8  # EPSL = EPSU
    timeout: float = 120.0  # s per AUTO run
    max_amplitude: float = 1.5  # rad: branches stop when an angle exceeds it

    @classmethod
    def from_settings(cls, settings: object | None) -> Numerics:
        """Defaults overridden by the non-None attributes of a study's ``auto`` settings."""
        if settings is None:
            return cls()
        chosen = {f.name: getattr(settings, f.name) for f in fields(cls)
                  if getattr(settings, f.name, None) is not None}
        return replace(cls(), **chosen)


@dataclass(frozen=True)
class RunSpec:
    """One AUTO run to make, named ``<continuation>/<branch>``.

    ``restart``: (AUTO name of an earlier run, i.e. its name with "/" -> ".", label to restart
    from).
    """

    name: str
    constants: dict
    kind: str
    origin: str
    parameter_names: tuple[str, ...]
    restart: tuple[str, int] | None = None


class Engine:
    """Runs AUTO jobs of one model: compiles once, one directory per run, ``jobs`` in parallel."""

    def __init__(self, model: Model, workroot: Path, jobs: int = 1, timeout: float = 120.0,
                 on_run: Callable[[auto.RunOutcome], None] | None = None) -> None:
        self.model = model
        self.workroot = Path(workroot)
        self.jobs = max(1, jobs)
        self.timeout = timeout
        self.on_run = on_run
        self.executable = auto.compile_equations(lambda: fortran_source(model), model.name,
                                                 source_key=source_key(model))
        self.outcomes: dict[str, auto.RunOutcome] = {}

    def run_many(self, specs: Sequence[RunSpec]) -> list[auto.RunOutcome]:
        """Execute ``specs`` (independent of each other) and return outcomes in spec order."""
        with ThreadPoolExecutor(max_workers=self.jobs) as pool:
            outcomes = list(pool.map(self._execute, specs))
        return outcomes

    def _execute(self, spec: RunSpec) -> auto.RunOutcome:
        constants = dict(spec.constants)
        restart_file = None
        if spec.restart is not None:
            source, label = spec.restart
            restart_file = self.outcomes[source].file("s")
            constants["IRS"] = label
        outcome = auto.run(self.executable.path, constants, self.workroot / spec.name,
                           spec.name.replace("/", "."), restart=restart_file,
                           timeout=self.timeout)
        self.outcomes[outcome.name] = outcome
        if self.on_run is not None:
            self.on_run(outcome)
        return outcome

    def records(self) -> tuple[RunRecord, ...]:
        return tuple(
            RunRecord(o.name, o.status, o.message, o.constants,
                      -1 if o.returncode is None else o.returncode, o.wall_seconds, o.n_points)
            for o in sorted(self.outcomes.values(), key=lambda o: str(o.workdir)))


# ------------------------------------------------------------------------------- constants
def _stops(model: Model, parameter: str, bounds: tuple[float, float], amplitude: float) -> dict:
    stops: dict = {parameter: [float(bounds[0]), float(bounds[1])]}
    for state in model.states:
        if state.unit == "rad":
            stops[f"max_{state.name}"] = amplitude
            stops[f"min_{state.name}"] = -amplitude
    return stops


def equilibrium_constants(model: Model, numerics: Numerics, parameter: str,
                          bounds: tuple[float, float], direction: int) -> dict:
    """Constants for a one-parameter continuation of equilibria (IPS=1) of ``parameter``."""
    lower, upper = bounds
    width = upper - lower
    return base_constants(model) | {
        "IPS": 1, "ISW": 1, "IRS": 0, "ILP": 1, "ISP": 2, "MXBF": 0,
        "ICP": [parameter, *par_layout(model).measures()],
        "NMX": numerics.max_steps, "NPR": 0, "IID": 2,
        "DS": direction * numerics.step_initial * width,
        "DSMIN": numerics.step_min * width, "DSMAX": numerics.step_max * width,
        "EPSL": numerics.tolerance, "EPSU": numerics.tolerance, "EPSS": 1e-6,
        "ITMX": 9, "ITNW": numerics.newton_max_iterations, "NWTN": 3,
        "NTST": numerics.mesh_intervals, "NCOL": numerics.collocation_points, "IAD": 3,
        "RL0": lower - 0.05 * width, "RL1": upper + 0.05 * width,
        "UZSTOP": _stops(model, parameter, bounds, numerics.max_amplitude),
    }


# ------------------------------------------------------------------------------- recipes
def special_points(branch: Branch, skip_first: bool = False) -> list[SpecialPoint]:
    """The bifurcations on ``branch`` (HB, BP, LP, LPC, PD, TR, codim-2 ...)."""
    found = []
    for index in range(len(branch)):
        kind = PointType(int(branch.point_type[index]))
        if not kind.is_special or (skip_first and index == 0):
            continue
        found.append(SpecialPoint(
            branch=branch.name, index=index, point_type=int(kind),
            parameter_names=branch.parameter_names, parameters=branch.parameters[index].copy(),
            state=branch.state_max[index].copy(), period=float(branch.period[index]),
            stable=bool(branch.stable[index]), label=int(branch.label[index])))
    return found


def _same_point(a: SpecialPoint, b: SpecialPoint, width: float) -> bool:
    return (abs(a.parameters[0] - b.parameters[0]) <= 1e-5 * width
            and np.allclose(a.state, b.state, atol=1e-5, rtol=1e-4))


def one_parameter(engine: Engine, name: str, parameter: str, start: float,
                  bounds: tuple[float, float], parameters: dict[str, float],
                  numerics: Numerics, branch_points: bool = True) -> ContinuationResult:
    """Equilibria of ``parameter`` over ``bounds`` from ``start``, with branch switching."""
    model = engine.model
    lower, upper = bounds
    width = upper - lower
    start_parameters = {**parameters, parameter: float(start)}
    specs = []
    for direction, label in ((-1, "down"), (1, "up")):
        if (direction < 0 and start > lower) or (direction > 0 and start < upper):
            constants = equilibrium_constants(model, numerics, parameter, bounds, direction)
            constants["PAR"] = start_parameters
            specs.append(RunSpec(f"{name}/main_{label}", constants, BranchKind.EQUILIBRIUM,
                                 f"start at {parameter} = {start:g}", (parameter,)))
    branches: list[Branch] = []
    points: list[SpecialPoint] = []
    frontier = _run_branches(engine, specs, branches, points, skip_first=False)

    # In a linear model a branch point carries a straight line of equilibria at a fixed
    # parameter value; AUTO's fold test fires all along it, so fold detection is switched off.
    neutral = is_linear(model, parameters)
    switched: list[SpecialPoint] = []
    depth = 0
    while branch_points and frontier and depth < MAX_SWITCH_DEPTH:
        depth += 1
        todo = []
        for point in frontier:
            if point.point_type != PointType.BP or any(
                    _same_point(point, done, width) for done in switched):
                continue
            switched.append(point)
            source = _run_of(branches, point.branch)
            for direction, label in ((1, "a"), (-1, "b")):
                constants = equilibrium_constants(model, numerics, parameter, bounds, direction)
                constants["ISW"] = -1
                if neutral:
                    constants["ILP"] = 0
                todo.append(RunSpec(
                    f"{name}/secondary_{len(switched)}{label}", constants,
                    BranchKind.EQUILIBRIUM,
                    f"BP at {parameter} = {point.parameters[0]:.6g} on {point.branch}",
                    (parameter,), restart=(source, point.label)))
        frontier = [p for p in _run_branches(engine, todo, branches, points, skip_first=True)
                    if not any(_same_point(p, q, width) for q in switched)]

    unique: list[SpecialPoint] = []
    for point in points:
        if not any(point.point_type == q.point_type and _same_point(point, q, width)
                   for q in unique):
            unique.append(point)
    return ContinuationResult(name, "one-parameter", tuple(branches), tuple(unique))


def is_linear(model: Model, parameters: dict[str, float]) -> bool:
    """True if the right-hand side is linear in the states at these parameter values."""
    values = model.parameter_vector(parameters)
    probe = np.random.default_rng(0).standard_normal(model.n_states) * 0.3
    rhs = model.rhs_numpy(probe, values)
    linearised = model.jacobian_numpy(np.zeros(model.n_states), values) @ probe
    return bool(np.allclose(rhs, linearised, rtol=1e-10, atol=1e-12 * np.abs(rhs).max()))


def _run_of(branches: list[Branch], branch_name: str) -> str:
    return next(b.run for b in branches if b.name == branch_name)


def _run_branches(engine: Engine, specs: list[RunSpec], branches: list[Branch],
                  points: list[SpecialPoint], skip_first: bool) -> list[SpecialPoint]:
    """Run ``specs``, append their branches and special points; return the new points."""
    new_points: list[SpecialPoint] = []
    for spec, outcome in zip(specs, engine.run_many(specs), strict=True):
        if not outcome.has_output:
            branches.append(_failed_branch(engine.model, spec, outcome))
            continue
        branch = read_branch(outcome, engine.model, name=spec.name.split("/", 1)[-1],
                             kind=spec.kind, origin=spec.origin,
                             parameter_names=spec.parameter_names)
        branches.append(branch)
        found = special_points(branch, skip_first=skip_first)
        points.extend(found)
        new_points.extend(found)
    return new_points


def _failed_branch(model: Model, spec: RunSpec, outcome: auto.RunOutcome) -> Branch:
    """An empty branch that records a failed run (status and message kept for the HDF5)."""
    n, p = model.n_states, len(spec.parameter_names)
    return Branch(
        name=spec.name.split("/", 1)[-1], kind=spec.kind, origin=spec.origin,
        parameter_names=spec.parameter_names,
        parameter_units=tuple(model.parameter(x).unit for x in spec.parameter_names),
        state_names=model.state_names, state_units=tuple(s.unit for s in model.states),
        parameters=np.empty((0, p)), state_max=np.empty((0, n)), state_min=np.empty((0, n)),
        l2_norm=np.empty(0), period=np.empty(0), stable=np.empty(0, dtype=bool),
        point_type=np.empty(0, dtype=np.int64), label=np.empty(0, dtype=np.int64),
        eigenvalues=np.empty((0, n), dtype=complex), status=outcome.status,
        message=outcome.message, run=outcome.name)

