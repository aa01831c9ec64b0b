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

from .analysis import global_bifurcations
from .analysis.normal_form import criticality_of, hopf_lyapunov_coefficient
from .auto import runner, toolchain
from .auto.codegen import fortran_source, source_key
from .auto.constants import AMPLITUDE, base_constants, par_layout
from .auto.parse import parse_b, read_branch
from .continuation.branches import amplitude, head, join
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
    step_max: float = 0.005  # DSMAX / range width
    mesh_intervals: int = 40  # NTST
    collocation_points: int = 4  # NCOL
    newton_max_iterations: int = 7  # ITNW
    tolerance: float = 1e-8  # EPSL = EPSU
    timeout: float = 120.0  # s per AUTO run
    max_amplitude: float = 1.5  # rad: branches stop when an angle exceeds it
    orbits_at: tuple[float, ...] = ()  # parameter values with a labelled solution (UZR)

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
                 on_run: Callable[[runner.RunOutcome], None] | None = None) -> None:
        self.model = model
        self.workroot = Path(workroot)
        self.jobs = max(1, jobs)
        self.timeout = timeout
        self.on_run = on_run
        self.executable = toolchain.compile_equations(lambda: fortran_source(model), model.name,
                                                 source_key=source_key(model))
        self.outcomes: dict[str, runner.RunOutcome] = {}

    def run_many(self, specs: Sequence[RunSpec]) -> list[runner.RunOutcome]:
        """Execute ``specs`` (independent of each other) and return outcomes in spec order."""
        with ThreadPoolExecutor(max_workers=self.jobs) as pool:
            outcomes = list(pool.map(self._execute, specs))
        return outcomes

    def _execute(self, spec: RunSpec) -> runner.RunOutcome:
        constants = dict(spec.constants)
        restart_file = None
        if spec.restart is not None:
            source, label = spec.restart
            restart_file = self.outcomes[source].file("s")
            constants["IRS"] = label
        outcome = runner.run(self.executable.path, constants, self.workroot / spec.name,
                           spec.name.replace("/", "."), restart=restart_file,
                           timeout=self.timeout)
        self.outcomes[outcome.name] = outcome
        if self.on_run is not None:
            self.on_run(outcome)
        return outcome

    def run_with_label(self, runs: str, label: int) -> str:
        """Which of the AUTO runs ``runs`` ("a+b+..." for a branch joined from several runs)
        wrote the solution labelled ``label``."""
        for name in reversed(runs.split("+")):  # the latest run of a chain of restarts
            if any(found == label for _, found in self.outcomes[name].labels):
                return name
        raise KeyError(f"label {label} not found in runs {runs}")

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
        "ITMX": 30, "ITNW": numerics.newton_max_iterations, "NWTN": 3,
        "NTST": numerics.mesh_intervals, "NCOL": numerics.collocation_points, "IAD": 3,
        "RL0": lower - 0.05 * width, "RL1": upper + 0.05 * width,
        "UZSTOP": _stops(model, parameter, bounds, numerics.max_amplitude),
    } | ({"UZR": {parameter: [float(v) for v in numerics.orbits_at]}} if numerics.orbits_at
         else {})


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
                  numerics: Numerics, branch_points: bool = True,
                  periodic: bool = False, orbits_at: tuple[float, ...] = ()
                  ) -> ContinuationResult:
    """Equilibria of ``parameter`` over ``bounds`` from ``start``, with branch switching, and
    (``periodic``) the periodic families of every Hopf point. ``orbits_at``: parameter values
    where every branch stores a labelled solution (orbit profiles)."""
    numerics = replace(numerics, orbits_at=tuple(orbits_at))
    branches, points = equilibria(engine, name, parameter, start, bounds, parameters, numerics,
                                  branch_points)
    points = with_lyapunov(engine.model, parameter, parameters, points)
    # a linear model has no limit cycles: at a Hopf point it carries a continuum of neutral
    # orbits of every amplitude, which AUTO reports as folds everywhere
    if periodic and not is_linear(engine.model, parameters):
        families, family_points = periodic_families(engine, name, parameter, bounds, numerics,
                                                     branches, points, parameters)
        branches += families
        points = _with_criticality(points, families, branches, bounds[1] - bounds[0],
                                   np.asarray(engine.model.state_scale, dtype=float)) \
            + family_points
    return ContinuationResult(name, "one-parameter", tuple(branches), tuple(points))


def equilibria(engine: Engine, name: str, parameter: str, start: float,
               bounds: tuple[float, float], parameters: dict[str, float], numerics: Numerics,
               branch_points: bool = True) -> tuple[list[Branch], list[SpecialPoint]]:
    """Equilibrium branches (main, then secondary from every BP) and their special points."""
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
    return branches, unique


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
        message=outcome.message, run=outcome.name)



# ------------------------------------------------------------------------------- periodic
#: A periodic run from a Hopf point first stops once the orbit has grown to this amplitude
#: (AUTO's non-dimensional units, the PVLS ``amplitude``).
GROWN_AMPLITUDE = 2e-3
#: A family that shrinks back below this amplitude has reached a Hopf point.
HOPF_RETURN_AMPLITUDE = 1e-3
#: Periodic runs stop when the period exceeds this multiple of the Hopf period (blow-up).
PERIOD_CAP = 25.0
#: Label an orbit profile (kept in the results) every this many steps.
ORBIT_EVERY = 20
#: A family is continued fold by fold (AUTO stops at each fold of cycles); at most this many.
MAX_SEGMENTS = 24
#: After MX, a family is restarted with a finer mesh and smaller steps at most this often.
MAX_RETRIES = 2


def periodic_constants(model: Model, numerics: Numerics, parameter: str,
                       bounds: tuple[float, float], hopf_period_tau: float) -> dict:
    """Constants for periodic orbits (IPS=2) restarted from a Hopf or an earlier orbit."""
    constants = equilibrium_constants(model, numerics, parameter, bounds, 1)
    constants.update({
        "IPS": 2, "ISW": 1, "ILP": 1, "ISP": 2,
        "ICP": [parameter, "PERIOD", *par_layout(model).measures()],
        "NPR": ORBIT_EVERY,
    })
    constants["UZSTOP"] = dict(constants["UZSTOP"], PERIOD=PERIOD_CAP * hopf_period_tau)
    return constants


@dataclass
class _Family:
    """A periodic family being continued: its Hopf point and the branch pieces so far."""

    index: int
    hopf: SpecialPoint
    spec: RunSpec
    pieces: list[Branch]
    retries: int = 0


def periodic_families(engine: Engine, name: str, parameter: str, bounds: tuple[float, float],
                      numerics: Numerics, equilibria: list[Branch], points: list[SpecialPoint],
                      parameters: dict[str, float]
                      ) -> tuple[list[Branch], list[SpecialPoint]]:
    """The periodic family of every Hopf point, each stored once, with its special points.

    A family starts at its Hopf point and grows to GROWN_AMPLITUDE; it is then continued in
    segments that AUTO ends at each fold of cycles. A fold where the orbit has shrunk onto a
    Hopf point is the family reaching that Hopf point (AUTO would go on round the closed family
    again); there the family ends. Families that reach each other's Hopf points are one family,
    kept once. A family whose period blows up ends there, with a bracketed global bifurcation.
    """
    model = engine.model
    width = bounds[1] - bounds[0]
    scale = np.asarray(model.state_scale, dtype=float)
    hopfs = [p for p in points if p.point_type == PointType.HB]
    runs = {b.name: b.run for b in equilibria}
    families = []
    for k, hopf in enumerate(hopfs, 1):
        constants = periodic_constants(model, numerics, parameter, bounds,
                                       hopf.period * model.time_scale)
        constants["UZSTOP"][AMPLITUDE] = GROWN_AMPLITUDE
        spec = RunSpec(f"{name}/periodic_{k}.0", constants, BranchKind.PERIODIC,
                       f"HB at {parameter} = {hopf.parameters[0]:.6g} on {hopf.branch}",
                       (parameter,), restart=(runs[hopf.branch], hopf.label))
        families.append(_Family(k, hopf, spec, []))

    wave = [(family, family.spec) for family in families]
    while wave:
        outcomes = engine.run_many([spec for _, spec in wave])
        following = []
        for (family, spec), outcome in zip(wave, outcomes, strict=True):
            family.pieces.append(_read(engine, spec, outcome))
            step = _next_segment(family, model, hopfs, width)
            if step is not None:
                following.append((family, step))
        wave = following

    kept: list[Branch] = []
    found: list[SpecialPoint] = []
    homoclinic: list[tuple[int, Branch]] = []  # (row in found, family) to locate with HomCont
    reached: set[int] = set()
    for family in families:
        if family.index - 1 in reached:
            continue  # the same family, already reached from another Hopf point
        whole = _assemble(family, hopfs, width, scale)
        end, returned_to = _periodic_end(whole, model, hopfs, bounds, numerics, family)
        if returned_to is not None:
            reached.add(returned_to)
        global_point = global_bifurcations.analyse(whole, model, parameters, equilibria,
                                                   family.hopf.period, width)
        if global_point is not None:
            end = f"period blow-up: {PointType(global_point.point_type).name.lower()} approach"
            if whole.status == "mx":  # AUTO's expected failure right at the blow-up
                whole = replace(whole, status="ok", message="ended with MX at the period "
                                "blow-up (expected near a global bifurcation)")
            found.append(global_point)
            if global_point.point_type == PointType.HOMOCLINIC:
                homoclinic.append((len(found) - 1, whole))
        kept.append(replace(whole, end=end))
        small = amplitude(whole, model) < HOPF_RETURN_AMPLITUDE
        found += [p for p in special_points(whole, skip_first=True)
                  if not small[p.index] and _hopf_at(whole, p.index, hopfs, width, scale) is None]
    for row, point in zip([row for row, _ in homoclinic], locate_homoclinics(
            engine, name, [(family, found[row]) for row, family in homoclinic], bounds,
            parameters), strict=True):
        found[row] = point
    return kept, found


#: HomCont: a homoclinic orbit counts as located when the principal parameter varies by less
#: than this fraction of the range while the truncation period grows (it converges
#: exponentially in the period).
HOMOCLINIC_SPREAD = 1e-6
#: HomCont run length (steps in the truncation period) and mesh intervals.
HOMOCLINIC_STEPS = 30
HOMOCLINIC_MESH = 100


def homoclinic_constants(model: Model, parameter: str, bounds: tuple[float, float],
                         period_tau: float, n_unstable: int) -> dict:
    """Constants of a HomCont run (IPS=9) from a long-period orbit: the homoclinic orbit to
    an equilibrium (solved for, IEQUIB=1) continued in ``parameter`` and the truncation
    period at fixed other parameters, so the parameter converges to its homoclinic value.
    ISTART=5 phase-shifts the orbit so that it starts and ends at the equilibrium."""
    return base_constants(model) | {
        "IPS": 9, "ISW": 1, "ICP": [parameter, "PERIOD"], "IEQUIB": 1, "ISTART": 5,
        "NUNSTAB": n_unstable, "NSTAB": model.n_states - n_unstable, "ITWIST": 0,
        "ILP": 0, "ISP": 0, "MXBF": 0, "NMX": HOMOCLINIC_STEPS, "NPR": HOMOCLINIC_STEPS,
        "IID": 2, "NTST": HOMOCLINIC_MESH, "NCOL": 4, "IAD": 3,
        "DS": 1e-3 * period_tau, "DSMIN": 1e-9, "DSMAX": 0.02 * period_tau,
        "EPSL": 1e-8, "EPSU": 1e-8, "EPSS": 1e-6, "ITMX": 30, "ITNW": 7, "NWTN": 3,
        "RL0": bounds[0], "RL1": bounds[1],
        "UZSTOP": {"PERIOD": [0.5 * period_tau, 4.0 * period_tau]},
    }


def locate_homoclinics(engine: Engine, name: str, ends: list[tuple[Branch, SpecialPoint]],
                       bounds: tuple[float, float], parameters: dict[str, float]
                       ) -> list[SpecialPoint]:
    """Try to locate the bracketed homoclinic ends of families with AUTO's HomCont (the runs
    in parallel), each restarted from its family's longest labelled orbit. On success a
    point's parameter becomes the HomCont value and its status "located"; otherwise it stays
    bracketed and its note says why."""
    points = [point for _, point in ends]
    runs = []
    for k, (family, point) in enumerate(ends):
        planned = _homoclinic_run(engine, name, family, point, bounds, parameters)
        if isinstance(planned, str):
            points[k] = replace(point, note=_joined(point.note, planned))
        else:
            runs.append((k, planned))
    outcomes = engine.run_many([spec for _, spec in runs])
    for (k, spec), outcome in zip(runs, outcomes, strict=True):
        points[k] = _homoclinic_verdict(outcome, points[k], spec.parameter_names[0], bounds,
                                        engine.model.time_scale)
    return points


def _homoclinic_run(engine: Engine, name: str, family: Branch, point: SpecialPoint,
                    bounds: tuple[float, float], parameters: dict[str, float]
                    ) -> RunSpec | str:
    """The HomCont run for one homoclinic end, or why none is tried. A symmetric orbit passing
    the saddle twice per period (a pair of homoclinic loops of a symmetric model) is not:
    HomCont follows one loop."""
    model = engine.model
    parameter = family.parameter_names[0]
    labelled = [k for k in np.flatnonzero(family.label) if np.isfinite(family.period[k])]
    if not labelled:
        return "HomCont not tried: no stored orbit"
    row = max(labelled, key=lambda k: family.period[k])
    if model.symmetric and np.allclose(family.state_max[row], -family.state_min[row],
                                       rtol=1e-6, atol=1e-9):
        return "HomCont not tried: the orbit is symmetric and passes the saddle twice per period"
    saddle_params = model.parameter_vector({**parameters, parameter: point.parameters[0]})
    n_unstable = int((np.linalg.eigvals(model.jacobian_numpy(point.state, saddle_params)).real
                      > 0).sum())
    if not n_unstable:
        return "HomCont not tried: no saddle"
    label = int(family.label[row])
    period_tau = float(family.period[row]) * model.time_scale
    return RunSpec(f"{name}/{family.name}.homoclinic",
                   homoclinic_constants(model, parameter, bounds, period_tau, n_unstable),
                   "homoclinic", point.note, (parameter,),
                   restart=(engine.run_with_label(family.run, label), label))


def _homoclinic_verdict(outcome: runner.RunOutcome, point: SpecialPoint, parameter: str,
                        bounds: tuple[float, float], time_scale: float) -> SpecialPoint:
    """The special point after a HomCont run: located if the parameter converged."""
    width = bounds[1] - bounds[0]
    values = periods = np.empty(0)
    if outcome.has_output:
        segments = parse_b(outcome.file("b").read_text(errors="replace"))
        if segments:
            values = np.concatenate([s.column(parameter) for s in segments])
            periods = np.concatenate([s.column("PERIOD") for s in segments])
    if len(values) < 5:
        return replace(point, note=_joined(
            point.note, f"HomCont (IPS=9) did not converge ({outcome.status}: "
            f"{outcome.message})"))
    tail = values[len(values) // 2:]
    spread = float(np.ptp(tail))
    if spread > HOMOCLINIC_SPREAD * width:
        return replace(point, note=_joined(
            point.note, f"HomCont (IPS=9): {parameter} did not settle (spread {spread:.2g} "
            f"over {len(tail)} points)"))
    value = float(values[-1])
    span = periods[len(values) // 2:] / time_scale
    return replace(point, parameters=np.array([value]), status="located", note=_joined(
        point.note, f"located by HomCont (IPS=9): {parameter} = {value:.10g}, spread "
        f"{spread:.2g} while the truncation period runs {span.min():.4g}-{span.max():.4g} s"))


def _assemble(family: _Family, hopfs: list[SpecialPoint], width: float,
              scale: np.ndarray) -> Branch:
    """One branch from a family's pieces, cut after the first point beyond the period cap
    (AUTO can step over that stop while it locates a fold there)."""
    whole = family.pieces[0]
    for piece in family.pieces[1:]:
        if len(piece):
            whole = join(whole, piece, whole.name)
    whole = replace(whole, name=f"periodic_{family.index}")
    ends = list(np.flatnonzero(whole.period > PERIOD_CAP * family.hopf.period)[:1])
    returned = _first_return(whole, hopfs, width, scale)
    if returned is not None:
        ends.append(returned)
    if ends and min(ends) + 1 < len(whole):
        whole = head(whole, min(ends) + 1)
    return whole


def _first_return(branch: Branch, hopfs: list[SpecialPoint], width: float,
                  scale: np.ndarray) -> int | None:
    """First row where a grown family has shrunk back onto a Hopf point (AUTO may pass
    through a Hopf point without stopping there and go round the family again)."""
    size = ((branch.state_max - branch.state_min) / 2).max(axis=1)
    grown = np.flatnonzero(size > 0.5 * size.max())
    if not len(grown):
        return None
    for row in range(int(grown[0]), len(branch)):
        if _hopf_at(branch, row, hopfs, width, scale) is not None:
            return row
    return None


def _hopf_at(branch: Branch, row: int, hopfs: list[SpecialPoint], width: float,
             scale: np.ndarray) -> int | None:
    """Index of the Hopf point the orbit at ``row`` has shrunk onto, if any: a small orbit
    (in AUTO's non-dimensional units, ``scale`` = the model's state scale) centred on that Hopf
    point's equilibrium."""
    size = ((branch.state_max - branch.state_min) / (2 * scale)).max(axis=1)
    if size[row] > max(5e-3, 0.05 * size.max()):
        return None
    centre = 0.5 * (branch.state_max[row] + branch.state_min[row]) / scale
    for k, hopf in enumerate(hopfs):
        if abs(hopf.parameters[0] - branch.parameters[row, 0]) < 2e-3 * width and np.allclose(
                hopf.state / scale, centre, rtol=0, atol=2e-3 + 2 * size[row]):
            return k
    return None


def _next_segment(family: _Family, model: Model, hopfs: list[SpecialPoint],
                  width: float) -> RunSpec | None:
    """The run continuing ``family`` after its last piece, or None if the family has ended."""
    piece = family.pieces[-1]
    scale = np.asarray(model.state_scale, dtype=float)
    if piece.status == "mx" and family.retries < MAX_RETRIES:
        return _retry(family, piece)
    if not len(piece) or piece.status != "ok" or len(family.pieces) >= MAX_SEGMENTS:
        return None
    last = PointType(int(piece.point_type[-1]))
    if len(family.pieces) == 1:
        grown = last == PointType.UZ and abs(amplitude(piece, model)[-1] - GROWN_AMPLITUDE) \
            < 1e-3 * GROWN_AMPLITUDE
        if not grown:
            return None
    elif last != PointType.LPC or _first_return(piece, hopfs, width, scale) is not None or \
            _hopf_at(piece, len(piece) - 1, hopfs, width, scale) is not None:
        return None  # an end (range, amplitude, period, steps) or back at a Hopf point
    if global_bifurcations.in_blowup(piece, family.hopf.period) and \
            global_bifurcations.blowup_turns(*_columns(family), family.hopf.period) \
            >= global_bifurcations.BRACKET_TURNS:
        return None
    constants = dict(family.spec.constants, STOP=["LP1"])
    constants["UZSTOP"] = {k: v for k, v in constants["UZSTOP"].items() if k != AMPLITUDE}
    return replace(family.spec, name=f"{family.spec.name.rsplit('.', 1)[0]}."
                   f"{len(family.pieces)}", constants=constants,
                   restart=(piece.run, int(piece.label[-1])))


def _columns(family: _Family) -> tuple[np.ndarray, np.ndarray]:
    """(principal parameter, period) along the family's pieces so far (a restart repeats the
    point it starts from: a zero step, which counts as no turn)."""
    return (np.concatenate([p.parameters[:, 0] for p in family.pieces]),
            np.concatenate([p.period for p in family.pieces]))


def _retry(family: _Family, piece: Branch) -> RunSpec | None:
    """After MX (no convergence): restart from the last good labelled point of the piece with
    twice the mesh intervals and half the largest step; the piece is cut back to that point."""
    labelled = [k for k in np.flatnonzero(piece.label) if piece.point_type[k] != PointType.MX]
    if not labelled or global_bifurcations.in_blowup(piece, family.hopf.period):
        return None
    row = int(labelled[-1])
    family.pieces[-1] = head(piece, row + 1)
    family.retries += 1
    refine = 2 ** family.retries
    constants = dict(family.spec.constants, STOP=["LP1"],
                     NTST=family.spec.constants["NTST"] * refine,
                     DSMAX=family.spec.constants["DSMAX"] / refine)
    constants["UZSTOP"] = {k: v for k, v in constants["UZSTOP"].items() if k != AMPLITUDE}
    return replace(family.spec, name=f"{family.spec.name.rsplit('.', 1)[0]}."
                   f"{len(family.pieces)}r{family.retries}", constants=constants,
                   restart=(piece.run.rsplit("+", 1)[-1], int(piece.label[row])))


def _read(engine: Engine, spec: RunSpec, outcome: runner.RunOutcome) -> Branch:
    if not outcome.has_output:
        return _failed_branch(engine.model, spec, outcome)
    return read_branch(outcome, engine.model, name=spec.name.split("/", 1)[-1], kind=spec.kind,
                       origin=spec.origin, parameter_names=spec.parameter_names)


def _periodic_end(family: Branch, model: Model, hopfs: list[SpecialPoint],
                  bounds: tuple[float, float], numerics: Numerics,
                  state: _Family) -> tuple[str, int | None]:
    """Why a periodic family ends, and the index of the Hopf point it returns to (if so)."""
    if not len(family):
        return f"failed: {family.message}", None
    width = bounds[1] - bounds[0]
    scale = np.asarray(model.state_scale, dtype=float)
    value = family.parameters[-1, 0]
    returned = _hopf_at(family, len(family) - 1, hopfs, width, scale) if len(family) > 3 else None
    if returned is not None:
        hopf = hopfs[returned]
        which = "its own HB" if returned == state.index - 1 else "HB"
        return (f"returns to {which} at {family.parameter_names[0]} = "
                f"{hopf.parameters[0]:.6g} on {hopf.branch}"), returned
    if family.point_type[-1] == PointType.MX:
        return "no convergence (MX)", None
    if family.period[-1] >= 0.999 * PERIOD_CAP * state.hopf.period:
        return "period cap", None
    if min(abs(value - bounds[0]), abs(value - bounds[1])) < 1e-6 * width:
        return "range", None
    angles = [i for i, s in enumerate(model.states) if s.unit == "rad"]
    reach = np.abs(np.concatenate([family.state_max[-1, angles],
                                   family.state_min[-1, angles]])).max()
    if reach >= 0.999 * numerics.max_amplitude:
        return "amplitude bound", None
    if len(state.pieces) >= MAX_SEGMENTS:
        return f"fold limit ({MAX_SEGMENTS} segments)", None
    return "step limit", None


def _with_criticality(points: list[SpecialPoint], families: list[Branch],
                      branches: list[Branch], width: float, scale: np.ndarray
                      ) -> list[SpecialPoint]:
    """Hopf points labelled supercritical or subcritical from the periodic family at them:
    supercritical when the family lies on the side where the Hopf pair is unstable."""
    equilibria = {b.name: b for b in branches}
    hopfs = [p for p in points if p.point_type == PointType.HB]
    sides: dict[int, float] = {}
    for family in families:
        if len(family) < 3:
            continue
        for row, neighbour in ((0, 1), (len(family) - 1, len(family) - 2)):
            k = _hopf_at(family, row, hopfs, width, scale) if row else next(
                (i for i, h in enumerate(hopfs) if family.origin == _origin(h)), None)
            if k is not None and k not in sides:
                sides[k] = float(np.sign(family.parameters[neighbour, 0]
                                         - hopfs[k].parameters[0]))
    labelled = []
    for point in points:
        if point.point_type == PointType.HB:
            k = next(i for i, h in enumerate(hopfs) if h is point)
            growth = _hopf_growth_direction(equilibria[point.branch], point)
            side = sides.get(k, 0.0)
            if side and growth:
                from_family = "supercritical" if side == growth else "subcritical"
                if point.criticality and point.criticality != from_family:
                    point = replace(point, note=_joined(
                        point.note, f"first Lyapunov coefficient says {point.criticality}"))
                point = replace(point, criticality=from_family)
        labelled.append(point)
    return labelled


def with_lyapunov(model: Model, parameter: str, parameters: dict[str, float],
                  points: list[SpecialPoint]) -> list[SpecialPoint]:
    """Hopf points of equilibria with their first Lyapunov coefficient and, from its sign, a
    provisional criticality (a periodic family, when computed, has the last word: see
    :func:`_with_criticality`)."""
    labelled = []
    for point in points:
        if point.point_type == PointType.HB:
            values = model.parameter_vector({**parameters, parameter: point.parameters[0]})
            try:
                l1 = hopf_lyapunov_coefficient(model, point.state, values)
            except (ValueError, np.linalg.LinAlgError):
                l1 = float("nan")
            point = replace(point, lyapunov=l1,
                            criticality=criticality_of(l1, 2 * np.pi / point.period))
        labelled.append(point)
    return labelled


def _joined(*notes: str) -> str:
    return "; ".join(n for n in notes if n)


def _origin(hopf: SpecialPoint) -> str:
    return f"HB at {hopf.parameter_names[0]} = {hopf.parameters[0]:.6g} on {hopf.branch}"


def _hopf_growth_direction(branch: Branch, hopf: SpecialPoint) -> float:
    """Sign of d(Re lambda)/dp of the critical pair at a Hopf point, from the eigenvalues AUTO
    printed at the neighbouring points of the equilibrium branch; 0 (unknown) where AUTO
    printed none there."""
    k = hopf.index
    if k == 0 or k + 1 >= len(branch):
        return 0.0
    omega = 2 * np.pi / hopf.period

    def critical(row: int) -> float:
        values = branch.eigenvalues[row]
        return float(values[np.argmin(np.abs(np.abs(values.imag) - omega))].real)

    slope = (critical(k + 1) - critical(k - 1)) / (branch.parameters[k + 1, 0]
                                                   - branch.parameters[k - 1, 0])
    return float(np.sign(slope)) if np.isfinite(slope) else 0.0


# ------------------------------------------------------------------------------- two-parameter
#: Special point type -> (locus name in studies, branch kind of its locus).
LOCI = {
    PointType.HB: ("hopf", BranchKind.HOPF_LOCUS),
    PointType.BP: ("branch_point", BranchKind.BRANCH_POINT_LOCUS),
    PointType.LP: ("fold", BranchKind.FOLD_LOCUS),
    PointType.LPC: ("fold_of_cycles", BranchKind.FOLD_OF_CYCLES_LOCUS),
}


def locus_constants(model: Model, numerics: Numerics, pair: tuple[str, str],
                    bounds: dict[str, tuple[float, float]], direction: int,
                    kind: PointType) -> dict:
    """Constants of a two-parameter locus (ISW=2) of a special point of type ``kind``.
    Debian's AUTO 0.9.2 overruns a heap buffer on fold-of-cycles loci unless ISP=0."""
    first, second = pair
    constants = equilibrium_constants(model, numerics, first, bounds[first], direction)
    constants.update(ISW=2, ICP=[first, second, "PERIOD", *par_layout(model).measures()])
    constants.pop("UZR", None)
    lower, upper = bounds[second]
    constants["UZSTOP"] = dict(constants["UZSTOP"], **{second: [lower, upper]})
    if kind == PointType.LPC:
        constants.update(IPS=2, ISP=0, ILP=1)
    return constants


def two_parameter(engine: Engine, name: str, pair: tuple[str, str],
                  bounds: dict[str, tuple[float, float]], start: float,
                  slices: tuple[float, ...], loci: tuple[str, ...],
                  parameters: dict[str, float], numerics: Numerics
                  ) -> tuple[ContinuationResult, list[Branch]]:
    """One-parameter runs at every slice of the second parameter, then the loci of their
    special points (both directions, each locus once). Returns the continuation (slice branches
    named ``slice_<k>.<branch>`` and the locus branches) and the locus branches."""
    first, second = pair
    wanted = {kind for kind, (locus, _) in LOCI.items() if locus in loci}
    periodic = PointType.LPC in wanted
    branches: list[Branch] = []
    points: list[SpecialPoint] = []
    starts: list[tuple[SpecialPoint, str]] = []
    for k, value in enumerate(slices):
        result = one_parameter(engine, f"{name}.slice_{k}", first, start, bounds[first],
                               {**parameters, second: value}, numerics, periodic=periodic)
        runs = {b.name: b.run for b in result.branches}
        for branch in result.branches:
            branches.append(replace(branch, name=f"slice_{k}.{branch.name}"))
        for point in result.special_points:
            named = replace(point, branch=f"slice_{k}.{point.branch}", parameter_names=pair,
                            parameters=np.array([point.parameters[0], value]))
            points.append(named)
            width = bounds[first][1] - bounds[first][0]
            if point.point_type in wanted and point.status == "located" and not any(
                    point.point_type == other.point_type and _same_point(named, other, width)
                    for other, _ in starts):
                starts.append((named, runs[point.branch]))
    curves = _loci(engine, name, pair, bounds, numerics, starts)
    for curve in curves:
        points += special_points(curve, skip_first=True)
    return (ContinuationResult(name, "two-parameter", tuple(branches + curves), tuple(points)),
            curves)


def _loci(engine: Engine, name: str, pair: tuple[str, str],
          bounds: dict[str, tuple[float, float]], numerics: Numerics,
          starts: list[tuple[SpecialPoint, str]]) -> list[Branch]:
    """Locus branches from the start points, both directions, each locus once.

    Starts are taken slice by slice: a start lying on a locus of its type already traced
    from an earlier slice is the same locus and is not run again (AUTO's runs, not just the
    results, are saved). Duplicates left (two starts of one slice on one locus) are dropped."""
    width = np.array([bounds[p][1] - bounds[p][0] for p in pair])
    numbered = list(enumerate(starts, 1))
    waves: dict[str, list] = {}
    for k, (point, runs) in numbered:
        waves.setdefault(point.branch.split(".", 1)[0], []).append((k, point, runs))
    curves: list[tuple[int, Branch]] = []
    for wave in waves.values():
        todo = [(k, point, runs) for k, point, runs in wave if not any(
            kind == point.point_type and _near_polyline(point.parameters[:2], curve.parameters,
                                                        width)
            for kind, curve in curves)]
        curves += _trace(engine, name, pair, bounds, numerics, todo)
    kept: list[Branch] = []
    for _, curve in sorted(curves, key=lambda c: c[1].name):
        curve = _closed(curve, width)
        if len(curve) and not any(_on_curve(curve.parameters[0], other.parameters, width)
                                  and _on_curve(curve.parameters[-1], other.parameters, width)
                                  for other in kept):
            kept.append(curve)
    codim2 = [p for c in kept for p in special_points(c, skip_first=True)
              if PointType(p.point_type) in CODIM2]
    return [_locus_end(c, codim2, bounds, width) for c in kept]


def _trace(engine: Engine, name: str, pair: tuple[str, str],
           bounds: dict[str, tuple[float, float]], numerics: Numerics,
           starts: list[tuple[int, SpecialPoint, str]]) -> list[tuple[int, Branch]]:
    """(point type, locus branch) of every start, both directions, run in parallel."""
    model = engine.model
    specs = []
    for k, point, runs in starts:
        kind = PointType(point.point_type)
        locus, branch_kind = LOCI[kind]
        source = engine.run_with_label(runs, point.label)
        origin = f"{kind.name} at {pair[0]} = {point.parameters[0]:.6g} on {point.branch}"
        for direction, tag in ((1, "a"), (-1, "b")):
            constants = locus_constants(model, numerics, pair, bounds, direction, kind)
            if kind == PointType.LPC:  # stage 1: AUTO builds the extended system (NMX 5)
                constants["NMX"] = 5
            specs.append((kind, RunSpec(f"{name}/{locus}_{k}{tag}", constants, branch_kind,
                                        origin, pair, restart=(source, point.label))))
    outcomes = engine.run_many([spec for _, spec in specs])
    second_stage = []
    final: list[tuple[int, RunSpec, runner.RunOutcome]] = []
    for (kind, spec), outcome in zip(specs, outcomes, strict=True):
        if kind == PointType.LPC and outcome.has_output:
            constants = dict(spec.constants, NMX=min(LOCUS_CHUNK, numerics.max_steps))
            second_stage.append((kind, replace(spec, name=spec.name + "2", constants=constants,
                                               restart=(outcome.name, outcome.labels[-1][1]))))
        else:
            final.append((kind, spec, outcome))
    final += [(kind, spec, outcome) for (kind, spec), outcome in zip(
        second_stage, engine.run_many([spec for _, spec in second_stage]), strict=True)]
    curves = [_read(engine, spec, outcome) for _, spec, outcome in final]
    width = np.array([bounds[p][1] - bounds[p][0] for p in pair])
    curves = _extended(engine, [spec for _, spec, _ in final], curves, numerics, bounds, width)
    curves = _retried(engine, [spec for _, spec, _ in final], curves)
    return [(kind, curve) for (kind, _, _), curve in zip(final, curves, strict=True)]


#: Locus runs go LOCUS_CHUNK steps at a time: a closed locus is recognised after the chunk
#: that closes it instead of being traced round and round up to the step limit.
LOCUS_CHUNK = 400


def _extended(engine: Engine, specs: list[RunSpec], curves: list[Branch], numerics: Numerics,
              bounds: dict[str, tuple[float, float]], width: np.ndarray) -> list[Branch]:
    """Loci that used up a chunk of steps without closing or reaching the range, continued
    chunk by chunk from their last point (up to ``numerics.max_steps`` in all)."""
    done = list(curves)
    chunk = 1
    while True:
        again, where = [], []
        for k, (spec, curve) in enumerate(zip(specs, done, strict=True)):
            if spec.constants.get("NMX") != LOCUS_CHUNK or not _chunk_used(curve, width,
                                                                          bounds):
                continue
            if len(curve) >= numerics.max_steps or not curve.label[-1]:
                continue
            again.append(replace(spec, name=f"{spec.name}c{chunk}",
                                 restart=(curve.run.rsplit("+", 1)[-1], int(curve.label[-1]))))
            where.append(k)
        if not again:
            return done
        for spec, k, outcome in zip(again, where, engine.run_many(again), strict=True):
            extra = _read(engine, spec, outcome)
            if len(extra) > 1:
                done[k] = join(done[k], extra, done[k].name)
        chunk += 1


def _chunk_used(curve: Branch, width: np.ndarray, bounds: dict[str, tuple[float, float]]
                ) -> bool:
    """True if a locus run stopped only because its chunk of steps was used up: it ended
    with status ok on a plain end point, not closed, not at the range edge."""
    if curve.status != "ok" or len(curve) < 2 or curve.point_type[-1] != PointType.EP:
        return False
    return len(_closed(curve, width)) == len(curve) and not _at_range_edge(curve, bounds, width)


def _at_range_edge(curve: Branch, bounds: dict[str, tuple[float, float]], width: np.ndarray
                   ) -> bool:
    """True if the locus ends on the edge of the study's range (where UZSTOP stops it)."""
    last = curve.parameters[-1, :2]
    edges = np.array([bounds[p] for p in curve.parameter_names[:2]])
    return bool(np.any(np.abs(last[:, None] - edges) < 1e-6 * width[:, None]))


def _near_polyline(point: np.ndarray, curve: np.ndarray, width: np.ndarray,
                   tolerance: float = 1e-3) -> bool:
    """True if ``point`` lies within ``tolerance`` of the polyline ``curve`` (K, >= 2), in
    axes scaled by the ranges ``width`` (Euclidean distance to the nearest segment)."""
    if len(curve) == 0:
        return False
    scaled = curve[:, :2] / width
    target = np.asarray(point[:2]) / width
    if len(scaled) == 1:
        return bool(np.linalg.norm(scaled[0] - target) < tolerance)
    start, step = scaled[:-1], np.diff(scaled, axis=0)
    length = np.einsum("ij,ij->i", step, step)
    along = np.clip(np.einsum("ij,ij->i", target - start, step) / np.where(length > 0, length, 1),
                    0.0, 1.0)
    nearest = start + along[:, None] * step
    return bool(np.linalg.norm(nearest - target, axis=1).min() < tolerance)


#: Codimension-2 points where loci may end (Bogdanov-Takens, cusp, zero-Hopf, Bautin, ...).
CODIM2 = {PointType.BT, PointType.CP, PointType.ZH, PointType.GH, PointType.R1, PointType.R2,
          PointType.R3, PointType.R4}


def _retried(engine: Engine, specs: list[RunSpec], curves: list[Branch]) -> list[Branch]:
    """Loci that ended in MX continued once more from their last good labelled point with
    twice the mesh and half the largest step, joined to what they had."""
    again, where = [], []
    for k, (spec, curve) in enumerate(zip(specs, curves, strict=True)):
        labelled = [r for r in np.flatnonzero(curve.label) if curve.point_type[r] != PointType.MX]
        if curve.status != "mx" or not labelled or labelled[-1] == 0:
            continue
        row = int(labelled[-1])
        constants = dict(spec.constants, NTST=spec.constants["NTST"] * 2,
                         DSMAX=spec.constants["DSMAX"] / 2)
        again.append(replace(spec, name=spec.name + "r", constants=constants,
                             restart=(engine.run_with_label(curve.run, int(curve.label[row])),
                                      int(curve.label[row]))))
        where.append((k, row))
    done = list(curves)
    for spec, (k, row), outcome in zip(again, where, engine.run_many(again), strict=True):
        extra = _read(engine, spec, outcome)
        if len(extra):
            done[k] = join(head(curves[k], row + 1), extra, curves[k].name)
    return done


def _locus_end(curve: Branch, codim2: list[SpecialPoint], bounds: dict[str, tuple[float, float]],
               width: np.ndarray) -> Branch:
    """The locus with its end classified: range edge, closed, or a codimension-2 point (where
    AUTO typically stops with MX: that is the locus' natural end, not a failure)."""
    last = curve.parameters[-1, :2]
    if _at_range_edge(curve, bounds, width):
        return replace(curve, end="range")
    if len(curve) > 2 and np.abs((last - curve.parameters[0, :2]) / width).max() < 0.005:
        return replace(curve, end="closed")
    near = [p for p in codim2 if np.abs((p.parameters[:2] - last) / width).max() < 0.01]
    if near:
        point = near[0]
        where = ", ".join(f"{v:.5g}" for v in point.parameters[:2])
        message = "ok" if curve.status == "ok" else \
            "AUTO stopped with MX at the codimension-2 point (the locus ends there)"
        return replace(curve, end=f"{point.type_name} at ({where})", status="ok",
                       message=message)
    return replace(curve, end="no convergence (MX)" if curve.status == "mx" else "step limit")


def _on_curve(point: np.ndarray, curve: np.ndarray, width: np.ndarray) -> bool:
    """True if ``point`` lies on the polyline ``curve`` (within 1e-3 of the ranges)."""
    return bool(len(curve)) and float(np.min(np.abs((curve - point) / width).max(axis=1))) < 1e-3


def _closed(curve: Branch, width: np.ndarray) -> Branch:
    """A locus cut where it first returns to its start (AUTO goes round a closed locus until
    its step limit)."""
    if len(curve) < 10:
        return curve
    distance = np.abs((curve.parameters - curve.parameters[0]) / width).max(axis=1)
    away = np.flatnonzero(distance > 0.02)
    if not len(away):
        return curve
    back = np.flatnonzero((distance < 0.005) & (np.arange(len(curve)) > away[0]))
    return head(curve, int(back[0]) + 1) if len(back) else curve
