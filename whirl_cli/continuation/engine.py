"""The engine under every recipe: AUTO numerics, run specifications, runs made in parallel.

An :class:`Engine` compiles a model's equations once and makes :class:`RunSpec` runs, each in
its own directory, ``jobs`` at a time; :func:`run_branches` and :func:`read_run` read the branches
they wrote (an empty branch with the run's status and message where a run failed).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..auto import runner, toolchain
from ..auto.codegen import fortran_source, source_key
from ..auto.parse import parse_s, read_branch
from ..models import Model
from ..results import (
    STEP_LIMIT,
    Branch,
    BranchKind,
    Origin,
    PointType,
    RunRecord,
    RunStatus,
    SpecialPoint,
)
from ..runtime import thread_map
from .branches import special_points
from .numerics import Numerics as Numerics  # re-exported: the recipes take it from here

#: whirl's log (``whirl -v`` shows its DEBUG lines: each run as it starts).
_LOG = logging.getLogger("whirl")

@dataclass(frozen=True)
class RunSpec:
    """One AUTO run to make, named ``<continuation>/<branch>``.

    ``restart``: (AUTO name of an earlier run, i.e. its name with "/" -> ".", label to restart
    from). ``data``: instead, the text of an AUTO data file to start from (IRS=0; see
    :func:`whirl_cli.auto.runner.run`). ``start_state``: the starting state of an equilibrium
    run that does not start at U = 0 (a line of AUTO's U).
    """

    name: str
    constants: dict
    kind: BranchKind
    origin: Origin
    parameter_names: tuple[str, ...]
    restart: tuple[str, int] | None = None
    data: str | None = None
    start_state: str | None = None


class _Slots:
    """At most ``jobs`` holders at a time; a background request waits while any foreground
    one does (background work fills a core the foreground leaves idle, never delays it)."""

    def __init__(self, jobs: int) -> None:
        self._free = jobs
        self._waiting = 0  # foreground requests waiting
        self._changed = threading.Condition()

    @contextmanager
    def held(self, background: bool = False) -> Iterator[None]:
        with self._changed:
            self._waiting += not background
            try:
                self._changed.wait_for(lambda: self._free > 0
                                       and not (background and self._waiting))
            finally:
                self._waiting -= not background
            self._free -= 1
        try:
            yield
        finally:
            with self._changed:
                self._free += 1
                self._changed.notify_all()


class Engine:
    """Runs AUTO jobs of one model: compiles once, one directory per run, at most ``jobs`` at
    a time however many threads ask (independent stages of a recipe may run side by side;
    background runs only on slots no foreground run waits for)."""

    def __init__(self, model: Model, workroot: Path, jobs: int = 1, timeout: float = 120.0,
                 on_run: Callable[[runner.RunOutcome], None] | None = None,
                 on_slow: Callable[[str, float], None] | None = None,
                 on_plan: Callable[[int], None] | None = None) -> None:
        self.model = model
        self.workroot = Path(workroot)
        self.jobs = max(1, jobs)
        self.timeout = timeout
        self.on_run = on_run
        self.on_slow = on_slow
        self.on_plan = on_plan
        self.executable = toolchain.compile_equations(lambda: fortran_source(model), model.name,
                                                 source_key=source_key(model))
        self.outcomes: dict[str, runner.RunOutcome] = {}
        self._slots = _Slots(self.jobs)
        #: the specification of every run made, by AUTO name (as ``outcomes``)
        self.specs: dict[str, RunSpec] = {}

    def run_many(self, specs: Sequence[RunSpec], background: bool = False
                 ) -> list[runner.RunOutcome]:
        """Execute ``specs`` (independent of each other) and return outcomes in spec order;
        every run has ended when this returns or raises. ``background``: each run waits
        while a foreground run waits for a slot (work ahead of need)."""
        if self.on_plan is not None:
            self.on_plan(len(specs))
        return thread_map(lambda spec: self._execute(spec, background), specs, self.jobs)

    def _execute(self, spec: RunSpec, background: bool = False) -> runner.RunOutcome:
        constants = dict(spec.constants)
        restart_file = None
        if spec.restart is not None:
            source, label = spec.restart
            restart_file = self.outcomes[source].file("s")
            constants["IRS"] = label
        with self._slots.held(background):
            _LOG.debug(f"  {spec.name.replace('/', '.'):<32} start in {self.workroot / spec.name}")
            outcome = runner.run(self.executable.path, constants, self.workroot / spec.name,
                                 spec.name.replace("/", "."), restart=restart_file,
                                 timeout=self.timeout, data=spec.data, on_slow=self.on_slow,
                                 start_state=spec.start_state)
        self.outcomes[outcome.name] = outcome
        self.specs[outcome.name] = spec
        if self.on_run is not None:
            self.on_run(outcome)
        return outcome

    def run_with_label(self, runs: tuple[str, ...], label: int) -> str:
        """Which of the AUTO runs ``runs`` (a branch's, several for one joined from several
        runs) wrote the solution labelled ``label``."""
        for name in reversed(runs):  # the latest run of a chain of restarts
            if any(found == label for _, found in self.outcomes[name].labels):
                return name
        for name in reversed(runs):  # a regular (NPR) point: no type on stdout
            outcome = self.outcomes[name]
            if outcome.has_output and any(solution.lab == label for solution in parse_s(
                    outcome.file("s").read_text(errors="replace"))):
                return name
        raise KeyError(f"label {label} not found in runs {'+'.join(runs)}")

    def records(self) -> tuple[RunRecord, ...]:
        return tuple(
            RunRecord(o.name, o.status, o.message, o.constants,
                      -1 if o.returncode is None else o.returncode, o.wall_seconds, o.n_points)
            for o in sorted(self.outcomes.values(), key=lambda o: str(o.workdir)))


def run_branches(engine: Engine, specs: list[RunSpec], branches: list[Branch],
                  points: list[SpecialPoint], skip_first: bool) -> list[SpecialPoint]:
    """Run ``specs``, append their branches and special points; return the new points."""
    new_points: list[SpecialPoint] = []
    for spec, outcome in zip(specs, engine.run_many(specs), strict=True):
        branch = read_run(engine, spec, outcome)
        branches.append(branch)
        found = special_points(branch, skip_first=skip_first)
        points.extend(found)
        new_points.extend(found)
    return new_points


def _failed_branch(model: Model, spec: RunSpec, outcome: runner.RunOutcome) -> Branch:
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
        message=outcome.message, runs=(outcome.name,),
        torus_angle=np.empty(0) if spec.kind == BranchKind.TORUS_LOCUS else None)


def read_run(engine: Engine, spec: RunSpec, outcome: runner.RunOutcome) -> Branch:
    """The branch of one run, with why it ends (:func:`run_end`; recipes that know more, such
    as the periodic one, say more)."""
    if not outcome.has_output:
        branch = _failed_branch(engine.model, spec, outcome)
    else:
        branch = read_branch(outcome, engine.model, name=spec.name.split("/", 1)[-1],
                             kind=spec.kind, origin=spec.origin,
                             parameter_names=spec.parameter_names)
    return replace(branch, end=branch.end or run_end(branch, spec.constants, engine.model))


def run_end(branch: Branch, constants: dict, model: Model) -> str:
    """Why an AUTO run's branch ends, from the stops it ran with: "failed: ..." (no output),
    "no convergence (MX)", "range" (a parameter at a UZSTOP bound), "amplitude bound" (a dof
    at its UZSTOP amplitude, in typical amplitudes), "period cap" (each a UZ stop: a branch
    only starting at a bound has not reached it), :data:`STEP_LIMIT` (NMX points) or "AUTO
    end point" (another stop, e.g. a locus meeting a degenerate point)."""
    if not len(branch):
        return f"failed: {branch.message}"
    if branch.status == RunStatus.MX or branch.point_type[-1] == PointType.MX:
        return "no convergence (MX)"
    if branch.status != RunStatus.OK:
        return f"{branch.status}: {branch.message}"
    dofs = {model.state_names[k]: k for k in model.positions}
    amplitudes = model.typical_amplitudes
    stops = constants.get("UZSTOP", {}) if branch.point_type[-1] == PointType.UZ else {}
    for name, limit in stops.items():
        limits = limit if isinstance(limit, list | tuple) else [limit]
        if name in branch.parameter_names:
            value = branch.parameters[-1, branch.parameter_names.index(name)]
            width = max(abs(limits[-1] - limits[0]), abs(limits[0]), 1e-12)
            if any(abs(value - v) <= 1e-6 * width for v in limits):
                return "range"
        elif name == "PERIOD" and branch.period[-1] >= 0.999 * limits[0] / model.time_scale:
            return "period cap"
        elif name[:4] in ("max_", "min_") and name[4:] in dofs:
            k = dofs[name[4:]]
            reach = max(abs(branch.state_max[-1, k]), abs(branch.state_min[-1, k])) \
                / amplitudes[k]
            if reach >= 0.999 * abs(limits[0]):
                return "amplitude bound"
    if len(branch) >= constants.get("NMX", np.inf):
        return STEP_LIMIT
    return "AUTO end point"

