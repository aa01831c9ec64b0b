"""A whole study, end to end: Study -> model -> AUTO runs + linear analysis + simulations ->
StudyResult.

``run_study`` is what ``whirl run`` calls; it does not write files other than AUTO's working
directories under ``workroot`` (the caller stores the result with :mod:`whirl_cli.output.store`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import TypeVar

from .analysis import freeplay, linear, seeds, simulate
from .auto.runner import RunOutcome, interruptible
from .continuation.engine import Engine, Numerics
from .continuation.recipes import Stage
from .output.provenance import provenance, resolved_parameters
from .results import ContinuationResult, Simulation, StudyResult
from .runtime import Standby, forked_map, preloaded
from .study import Study
from .study import continuations as continuation_types

T = TypeVar("T")


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
            values = linear.samples(*sweep.range, sweep.points, sweep.spacing)
            if sweep.multiples:  # the range in multiples of the datum: absolute values
                values = values * datum
            found = linear.sweep(model, parameters, sweep.parameter, values)
            sweeps.append(replace(found, multiples=sweep.multiples, spacing=sweep.spacing))
    grid = None
    if study.linear is not None and study.linear.grid is not None:
        x, y = study.linear.grid.x, study.linear.grid.y
        grid = replace(linear.grid(model, parameters,
                                   x.parameter, linear.samples(*x.range, x.points, x.spacing),
                                   y.parameter, linear.samples(*y.range, y.points, y.spacing)),
                       x_spacing=x.spacing, y_spacing=y.spacing)
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


def simulations(study: Study, model, jobs: int = 1) -> list[Simulation]:
    """The study's ``simulations:``, each from its initial state (degrees -> SI) with its
    overrides on top of the study's parameters (scipy; a failure is in the result), ``jobs``
    at a time in forked processes (:func:`whirl_cli.runtime.forked_map`: each is
    independent of the others, so the results are identical for any ``jobs``, in the study's
    order)."""
    specs = study.simulations
    if not specs:
        return []
    simulate.import_integrators()

    def simulated(k: int) -> Simulation:
        spec = specs[k]
        return simulate.simulation(
            model, model.parameter_vector(study.simulation_values(spec)),
            seeds.seed_state(model, spec.initial), spec.duration, spec.samples, spec.law,
            str(spec.name), study.simulation_overrides(spec))

    return forked_map(simulated, len(specs), jobs)
