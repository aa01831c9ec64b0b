"""A whole study, end to end: Study -> model -> AUTO runs + linear analysis + simulations ->
StudyResult.

``run_study`` is what ``whirl run`` calls; it does not write files other than AUTO's working
directories under ``workroot`` (the caller stores the result with :mod:`whirl_cli.output.store`).
"""

from __future__ import annotations

import importlib
import itertools
from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import Any, NamedTuple, TypeVar

import numpy as np

from .analysis import boundaries, freeplay, linear, motion, seeds, simulate
from .auto.runner import RunOutcome, interruptible
from .continuation import persistence, shrinking
from .continuation.engine import Engine, Numerics
from .continuation.loci import two_parameter
from .continuation.one_parameter import one_parameter
from .continuation.periodic import OrbitStart
from .output.provenance import provenance, resolved_parameters
from .results import (
    Boundary,
    BoundaryMethod,
    ContinuationResult,
    Exploration,
    MotionKind,
    Origin,
    SeedKind,
    SeedOutcome,
    Simulation,
    StudyResult,
    on_slice,
    slice_branch,
)
from .runtime import Standby, forked_map, preload, preloaded, thread_map
from .study import Study
from .study import continuations as continuation_types

T = TypeVar("T")


class Stage(NamedTuple):
    """What a continuation type's recipe runs with: the engine (AUTO; None in a study without
    continuations), the study, its model variant and parameter values, AUTO's numerics, the
    jobs, and the modules to import in the background once its AUTO runs start
    (``preload(*later)``)."""

    engine: Engine | None
    study: Study
    model: Any
    parameters: dict[str, float]
    numerics: Numerics
    jobs: int
    later: tuple[str, ...]


def run_study(study: Study, workroot: Path, jobs: int = 1,
              on_run: Callable[[RunOutcome], None] | None = None,
              preload: tuple[str, ...] = (),
              on_slow: Callable[[str, float], None] | None = None,
              on_plan: Callable[[int], None] | None = None) -> StudyResult:
    """Run every continuation, linear sweep and simulation of ``study``; AUTO works under
    ``workroot`` (a study without continuations needs no AUTO). ``preload``: modules the
    caller needs afterwards (e.g. :data:`whirl_cli.plots.MODULES` to draw), imported in the
    background once AUTO starts (:func:`whirl_cli.runtime.preload`). Only modules nothing
    imports while AUTO runs: two threads importing parts of one package at once can meet in
    its circular imports (Python then raises its import-deadlock error in one of them): scipy's
    integrators are added only where the cross-checks are the first to use scipy and run
    here (:func:`_only_checks_simulate`, ``jobs`` 1; see :func:`run_and_draw`), and the
    stages after the continuations join the import before they start. ``on_run`` is called
    with each AUTO run's outcome as it ends, ``on_slow`` with a run's name and seconds when it
    is still running after 10 s, 20 s, 40 s ... (:func:`whirl_cli.auto.runner.run`),
    ``on_plan`` with the number of AUTO runs about to start whenever more are (the runs
    planned so far: a recipe decides its next runs from the last ones' results).

    In the main thread, SIGINT and SIGTERM kill the running AUTO processes at once and raise
    :class:`whirl_cli.runtime.Interrupted` (a KeyboardInterrupt), see
    :func:`whirl_cli.auto.runner.interruptible`.
    """
    return run_and_draw(study, workroot, None, jobs, on_run, preload, on_slow, on_plan)[0]


def run_and_draw(study: Study, workroot: Path, draw: Callable[[StudyResult], T] | None,
                 jobs: int = 1, on_run: Callable[[RunOutcome], None] | None = None,
                 preload: tuple[str, ...] = (),
                 on_slow: Callable[[str, float], None] | None = None,
                 on_plan: Callable[[int], None] | None = None
                 ) -> tuple[StudyResult, T | None]:
    """:func:`run_study`, and ``draw(result)`` (None without ``draw``): work that needs
    everything but the cross-checks, such as rendering the plots
    (:func:`whirl_cli.publish.drawn_plots`). With ``jobs`` > 1 the cross-checks do
    not hold it up: a worker forked before AUTO starts (:class:`whirl_cli.runtime.Standby`)
    imports scipy's integrators meanwhile, on another core (in a short study that import,
    behind matplotlib's in one background thread, was the last thing to end), and checks the
    continuations as soon as they are done, while the linear analysis, the simulations and
    ``draw`` run here. The same result and drawings for any ``jobs``."""
    with interruptible():
        return _run_study(study, workroot, jobs, partial(Engine, jobs=jobs, on_run=on_run,
                                                         on_slow=on_slow, on_plan=on_plan),
                          preload, draw)


def _run_study(study: Study, workroot: Path, jobs: int, engine: Callable[..., Engine],
               later: tuple[str, ...],
               draw: Callable[[StudyResult], T] | None) -> tuple[StudyResult, T | None]:
    model = study.variant()
    parameters = study.parameter_values()
    with ExitStack() as stack:
        checker = None
        if study.cross_check and study.continuations and jobs > 1:  # checks beside the rest
            checker = stack.enter_context(Standby(
                partial(_cross_checks, model, parameters), simulate.MODULES))
        elif _only_checks_simulate(study, model):  # scipy too, while AUTO runs
            later = (*later, *simulate.MODULES)
        return _stages(study, model, parameters, workroot, jobs, engine, later, draw, checker)


def _stages(study: Study, model, parameters: dict[str, float], workroot: Path, jobs: int,
            new_engine: Callable[..., Engine], later: tuple[str, ...],
            draw: Callable[[StudyResult], T] | None, checker: Standby | None
            ) -> tuple[StudyResult, T | None]:
    """The stages of :func:`run_and_draw`; AUTO by ``new_engine(model, workroot,
    timeout=...)`` (an :class:`Engine` with the caller's jobs and callbacks); the cross-checks
    by ``checker`` if given."""
    numerics = Numerics.from_settings(study.auto)
    continuations: list[ContinuationResult] = []
    engine = None
    if study.continuations:
        engine = new_engine(model, workroot, timeout=numerics.timeout)
    stage = Stage(engine, study, model, parameters, numerics, jobs, later)
    found_boundaries = []
    for spec in study.continuations:
        continuation, boundary = continuation_types.of(spec).recipe(stage, spec)
        continuations.append(continuation)
        if boundary is not None:
            found_boundaries.append(boundary)
    preloaded()  # the stages below import scipy and draw: not beside a background import
    branches = tuple(c.branches for c in continuations)
    if checker is not None:  # checked while the stages below run
        checker.submit(branches)
    sweeps = []
    if study.linear is not None:
        for sweep in study.linear.sweeps:
            datum = model.parameter(model.canonical(sweep.parameter)).default
            values = np.linspace(sweep.range[0], sweep.range[1], sweep.points)
            if sweep.multiples:  # the range in multiples of the datum: absolute values
                values = values * datum
            found = linear.sweep(model, parameters, sweep.parameter, values)
            sweeps.append(replace(found, multiples=sweep.multiples))
    grid = None
    if study.linear is not None and study.linear.grid is not None:
        x, y = study.linear.grid.x, study.linear.grid.y
        grid = linear.grid(model, parameters, x.parameter, np.linspace(*x.range, x.points),
                           y.parameter, np.linspace(*y.range, y.points))
    result = StudyResult(
        study_name=study.name, model=model.name, continuations=tuple(continuations),
        linear_sweeps=tuple(sweeps), runs=engine.records() if engine else (),
        provenance=provenance(study), boundaries=tuple(found_boundaries), linear_grid=grid,
        parameters=resolved_parameters(model, parameters),
        simulations=tuple(simulations(study, model, jobs)))
    drawn = draw(result) if draw is not None else None
    if not study.cross_check:
        return result, drawn
    checks = checker.result() if checker is not None else \
        _cross_checks(model, parameters, branches, jobs)
    return replace(result, continuations=tuple(
        replace(c, cross_checks=found)
        for c, found in zip(result.continuations, checks, strict=True))), drawn


def _cross_checks(model, parameters: dict[str, float], branches: Sequence[tuple],
                  jobs: int = 1) -> list[tuple]:
    """The cross-checks by time simulation of each continuation's ``branches``
    (:func:`whirl_cli.analysis.simulate.cross_check`), in order."""
    return [simulate.cross_check(model, parameters, found, jobs=jobs) for found in branches]


def _only_checks_simulate(study: Study, model) -> bool:
    """True if the cross-checks are the first stage of ``study`` to import scipy: they are
    asked for, and no freeplay amplitudes or explorations follow a continuation (those import
    scipy in this thread while the next continuation's AUTO runs; two threads importing parts
    of one package at once can meet in its circular imports)."""
    return bool(study.cross_check and study.continuations
                and not freeplay.freeplay_dofs(model)
                and not any(getattr(spec, "explore", None) for spec in study.continuations))


def persisted(engine: Engine, base: ContinuationResult, continued: Callable, spec,
              parameters: dict[str, float], numerics: Numerics) -> ContinuationResult:
    """``base`` (a continuation of a model that smooths a law) with its special points
    recomputed as the smoothing shrinks (:mod:`whirl_cli.continuation.persistence`): by short
    runs near each point of a type they recompute (folds, Hopf and branch points:
    :func:`whirl_cli.continuation.shrinking.recompute`), and, only if one is left that they
    did not recompute (another type, such as a period blow-up, or one they did not confirm),
    by the continuation ``continued`` repeated at every factor (runs ``<name>_eps<k>``),
    which then gives those points' values. Points the short runs confirm keep their values:
    a repetition may miss a fold its branch does not reach at a smaller width (it would call
    it an artefact) or pick another point of the type nearby."""
    smoothing = engine.model.smoothing_parameters
    bounds = tuple(spec.range)
    recomputed = shrinking.recompute(
        engine, spec.name, base, parameters, smoothing, persistence.FACTORS,
        persistence.CHECKED, bounds, numerics,
        reach=persistence.TOLERANCE * (bounds[1] - bounds[0]))
    refined = repeated(continued, spec.name, parameters, smoothing) \
        if persistence.needs_repetition(base, recomputed) else []
    return persistence.annotate(base, refined, bounds[1] - bounds[0], recomputed=recomputed)


def repeated(continued: Callable, name: str, parameters: dict[str, float],
             smoothing: tuple[str, ...]) -> list[ContinuationResult]:
    """``continued`` with every smoothing width (``smoothing``) times each of
    :data:`persistence.FACTORS` (runs ``<name>_eps<k>``, ``k`` from 1): side by side (they
    share nothing but the compiled program)."""
    def one(k: int) -> ContinuationResult:
        return continued(f"{name}_eps{k + 1}", persistence.refined_parameters(
            parameters, smoothing, persistence.FACTORS[k]))

    return thread_map(one, range(len(persistence.FACTORS)), len(persistence.FACTORS))


def _import_integrators() -> None:
    """Import scipy's integrators (:data:`whirl_cli.analysis.simulate.MODULES`) here, once,
    before workers fork: they inherit them instead of each importing them."""
    for module in simulate.MODULES:
        importlib.import_module(module)


def simulations(study: Study, model, jobs: int = 1) -> list[Simulation]:
    """The study's ``simulations:``, each from its initial state (degrees -> SI) with its
    overrides on top of the study's parameters (scipy; a failure is in the result), ``jobs``
    at a time in forked processes (:func:`whirl_cli.runtime.forked_map`: each is
    independent of the others, so the results are identical for any ``jobs``, in the study's
    order)."""
    specs = study.simulations
    if not specs:
        return []
    _import_integrators()

    def simulated(k: int) -> Simulation:
        spec = specs[k]
        return simulate.simulation(
            model, model.parameter_vector(study.simulation_values(spec)),
            seeds.seed_state(model, spec.initial), spec.duration, spec.samples, spec.law,
            str(spec.name), study.simulation_overrides(spec))

    return forked_map(simulated, len(specs), jobs)


def explorations(model, overrides: dict[str, float], spec,
                 jobs: int = 1) -> tuple[Exploration, ...]:
    """The settled motion at each ``explore`` value of a one-parameter continuation, by
    simulation (:func:`whirl_cli.analysis.motion.classify_model`) at the study's parameters
    with the continuation parameter at that value, from ``explore_initial`` (default: the
    first dof at :data:`whirl_cli.study.continuations.one_parameter.EXPLORE_OFFSET`, deg
    for an angle), after ``explore_transient`` whirl periods, on the section where
    ``explore_section`` (default: the first dof's rate, i.e. at that dof's minima) crosses
    its mean upwards.

    ``jobs`` values at a time in forked processes (:func:`whirl_cli.runtime.forked_map`:
    each value's simulation is independent of the others, so the results are identical for
    any ``jobs``, in the order of ``explore``). A failure is the result ``diverged`` with its
    message, never raised."""
    from .study.continuations.one_parameter import EXPLORE_OFFSET

    parameter = model.parameter(model.canonical(spec.parameter))
    first = model.state_names[model.positions[0]]  # the first dof (or first-order state)
    given = spec.explore_initial if spec.explore_initial is not None else {
        first: EXPLORE_OFFSET}
    y0 = seeds.seed_state(model, given)
    names = tuple(s.name for s in model.states)
    units = tuple(s.unit for s in model.states)
    section = names.index(spec.explore_section if spec.explore_section is not None
                          else model.dofs[0].rate if model.dofs else first)

    def one(k: int) -> Exploration:
        value = spec.explore[k]
        try:
            motion_class = motion.classify_model(
                model, {**overrides, parameter.name: float(value)}, y0,
                transient_periods=spec.explore_transient, section_state=section)
        except Exception as error:  # noqa: BLE001 - reported in the result, never raised
            motion_class = motion.MotionClass(
                MotionKind.DIVERGED, np.nan, np.nan, (), np.zeros((0, len(names))), np.nan, 0, (),
                np.nan, f"diverged: the classification failed ({type(error).__name__}: "
                f"{error})")
        return Exploration(
            float(value), parameter.name, parameter.unit, names, units, y0.copy(),
            motion_class.kind, float(motion_class.lyapunov),
            float(motion_class.lyapunov_error),
            np.asarray(motion_class.frequencies, dtype=float),
            np.asarray(motion_class.section, dtype=float).reshape(-1, len(names)),
            float(motion_class.section_dimension), int(motion_class.multiplicity),
            np.asarray(motion_class.peaks, dtype=float), float(motion_class.broadband),
            motion_class.evidence)

    return tuple(forked_map(one, len(spec.explore), jobs))


def seeded_orbits(model, overrides: dict[str, float], parameter: str, start: float, given,
                  jobs: int = 1) -> tuple[tuple[OrbitStart, ...], tuple[np.ndarray, ...],
                                          tuple[SeedOutcome, ...]]:
    """A continuation's seeds (``given``: ``auto`` or state mappings) simulated with
    ``parameter`` at ``start``, ``jobs`` at a time (forked processes): one orbit start per
    distinct limit cycle they settle on, the states where seeds came to rest (SI), and what
    became of every seed."""
    if not given:
        return (), (), ()
    values = {**overrides, parameter: float(start)}
    params = model.parameter_vector(values)
    if given == "auto":
        initial = seeds.auto_seeds(model, values)
    else:
        initial = [seeds.seed_state(model, state) for state in given]
    _import_integrators()
    settled = forked_map(lambda k: seeds.settle(model, params, initial[k]), len(initial),
                         jobs)
    kept = seeds.distinct(settled)
    families = {k: f"periodic_o{n}" for n, k in enumerate(kept, 1)}
    starts = tuple(OrbitStart(replace(settled[k].orbit, parameters=np.array([start])),
                              float(start), Origin(f"seed {k + 1} settled by time simulation"))
                   for k in kept)
    outcomes = tuple(
        SeedOutcome(k + 1, s.seed, s.kind, s.orbit.period if s.orbit else float("nan"),
                    families.get(seeds.same_as(settled, k, kept), ""),
                    s.message)
        for k, s in enumerate(settled))
    rests = tuple(s.state for s in settled if s.kind == SeedKind.EQUILIBRIUM)
    return starts, rests, outcomes


def slice_seeds(model, overrides: dict[str, float], spec, jobs: int = 1
                ) -> tuple[tuple[tuple[OrbitStart, ...], ...], tuple[SeedOutcome, ...]]:
    """A two-parameter continuation's seeds simulated at ``start`` on every slice: the orbit
    starts of each slice, and every seed's outcome (numbered across the slices, families
    named ``slice_<k>.periodic_o<n>`` as the slice branches are)."""
    first, second = spec.parameters
    if not spec.seeds:
        return (), ()
    per_slice, outcomes = [], []
    for k, value in enumerate(spec.slice_values):
        starts, _, found = seeded_orbits(model, {**overrides, second: value}, first,
                                         spec.start, spec.seeds, jobs)
        per_slice.append(starts)
        outcomes += [replace(o, index=len(outcomes) + n + 1,
                             branch=o.branch and slice_branch(k, o.branch))
                     for n, o in enumerate(found)]
    return tuple(per_slice), tuple(outcomes)


def continue_two_parameter(stage: Stage, spec) -> tuple[ContinuationResult, Boundary]:
    """Loci and the unsafe region of a two-parameter continuation (the two-parameter type's
    recipe)."""
    engine, study, parameters, numerics = stage.engine, stage.study, stage.parameters, \
        stage.numerics
    assert engine is not None
    preload(*stage.later)  # imported while AUTO runs
    model = engine.model
    pair = tuple(spec.parameters)
    bounds = spec.bounds(study.names())
    orbits, outcomes = slice_seeds(model, parameters, spec, engine.jobs)
    continuation, curves = two_parameter(engine, spec.name, pair, bounds, spec.start,
                                         spec.slice_values, tuple(spec.loci), parameters,
                                         numerics, slice_orbits=orbits,
                                         snaking_folds=spec.snaking_folds)
    continuation = replace(continuation, seeds=outcomes)
    per_slice = [tuple(b for b in continuation.branches if on_slice(b.name, k) is not None)
                 for k in range(len(spec.slices))]
    added = itertools.count(1)

    def more_slices(values: list[float]) -> list[tuple]:
        """The branches of extra slices at ``values`` (not stored: they only judge folds)."""
        def run(named: tuple[str, float]) -> tuple:
            return one_parameter(engine, named[0], pair[0], spec.start, bounds[pair[0]],
                                 {**parameters, pair[1]: named[1]}, numerics,
                                 periodic=True).branches
        named = [(f"{spec.name}.extra_{next(added)}", value) for value in values]
        return thread_map(run, named, len(named))

    found = boundaries.boundary(spec.name, model, parameters, pair, bounds,
                                BoundaryMethod(spec.method), spec.slice_values,
                                spec.resolution, curves, per_slice, more_slices)
    return continuation, found


def continue_one_parameter(stage: Stage, spec) -> tuple[ContinuationResult, None]:
    """Equilibria in one parameter and what hangs off them (the one-parameter type's recipe):
    seeds simulated first, special points recomputed as a smoothing shrinks, freeplay
    amplitudes, explored values."""
    engine, model, parameters, numerics = stage.engine, stage.model, stage.parameters, \
        stage.numerics
    assert engine is not None
    starts, rests, outcomes = seeded_orbits(model, parameters, spec.parameter, spec.start,
                                            spec.seeds, stage.jobs)
    preload(*stage.later)  # imported while AUTO runs (after the seeds' fork)

    def continued(name: str, values: dict[str, float]) -> ContinuationResult:
        return one_parameter(
            engine, name, spec.parameter, spec.start, tuple(spec.range), values, numerics,
            branch_points=spec.branch_points, periodic=spec.periodic,
            orbits_at=spec.orbits_at, start_orbits=starts,
            period_doubling=spec.period_doubling,
            start_state=None if spec.start_state is None
            else seeds.seed_state(model, spec.start_state), resting=rests,
            spread=spec.spread_equilibria)

    continuation = replace(continued(spec.name, parameters), seeds=outcomes)
    if model.smoothing_parameters:
        continuation = persisted(engine, continuation, continued, spec, parameters, numerics)
    if freeplay.freeplay_dofs(model):  # amplitudes / delta, describing function
        continuation = replace(continuation, freeplay=freeplay.freeplay_amplitudes(
            model, parameters, continuation, tuple(spec.range)))
    if spec.explore:
        continuation = replace(continuation, explorations=explorations(
            model, parameters, spec, stage.jobs))
    return continuation, None
