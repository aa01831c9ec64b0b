"""A continuation type's whole recipe as a study runs it: the one-parameter type's seeds
simulated first, its continuation, special points recomputed as a smoothing shrinks, freeplay
amplitudes and explored values; the two-parameter type's seeds on every slice, its loci and the
unsafe region. The study's continuation types (:mod:`whirl_cli.study.continuations`) call these;
:mod:`whirl_cli.pipeline` runs them in the study's order.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import replace
from typing import Any, NamedTuple

import numpy as np

from ..analysis import boundaries, freeplay, motion, seeds, simulate
from ..results import (
    Boundary,
    BoundaryMethod,
    ContinuationResult,
    Exploration,
    MotionKind,
    Origin,
    SeedKind,
    SeedOutcome,
    on_slice,
    slice_branch,
)
from ..runtime import forked_map, preload, thread_map
from . import persistence, shrinking
from .engine import Engine, Numerics
from .loci import two_parameter
from .one_parameter import one_parameter
from .periodic import OrbitStart


class Stage(NamedTuple):
    """What a continuation type's recipe runs with: the engine (AUTO; None in a study without
    continuations), the study, its model variant and parameter values, AUTO's numerics, the
    jobs, and the modules to import in the background once its AUTO runs start
    (``preload(*later)``)."""

    engine: Engine | None
    study: Any  # the Study (whirl_cli.study.Study)
    model: Any
    parameters: dict[str, float]
    numerics: Numerics
    jobs: int
    later: tuple[str, ...]


def persisted(engine: Engine, base: ContinuationResult, continued: Callable, spec,
              parameters: dict[str, float], numerics: Numerics) -> ContinuationResult:
    """``base`` (a continuation of a model that smooths a law) with its special points
    recomputed as the smoothing shrinks (:mod:`whirl_cli.continuation.persistence`): by short
    runs near each point of a type they recompute (folds, Hopf and branch points:
    :func:`whirl_cli.continuation.shrinking.recompute`; a snaking global point from the
    folds that bracket it), and, only if one is left that they did not recompute (another
    type, such as a period blow-up, or one they did not confirm), by the continuation
    ``continued`` repeated at every factor (runs ``<name>_eps<k>``), which then gives those
    points' values. Points the short runs confirm keep their values:
    a repetition may miss a fold its branch does not reach at a smaller width (it would call
    it an artefact) or pick another point of the type nearby."""
    smoothing = engine.model.smoothing_parameters
    bounds = tuple(spec.range)
    recomputed = shrinking.recompute(
        engine, spec.name, base, parameters, smoothing, persistence.FACTORS,
        persistence.CHECKED, bounds, numerics,
        reach=persistence.TOLERANCE * (bounds[1] - bounds[0]))
    recomputed |= persistence.snaking_recomputed(base, recomputed)
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


def explorations(model, overrides: dict[str, float], spec,
                 jobs: int = 1) -> tuple[Exploration, ...]:
    """The settled motion at each ``explore`` value of a one-parameter continuation, by
    simulation (:func:`whirl_cli.analysis.motion.classify_model`) at the study's parameters
    with the continuation parameter at that value, from the spec's ``explore_start`` (its
    ``explore_initial``, or the first dof a little off zero), after ``explore_transient``
    whirl periods, on the section where ``explore_section`` (default: the first dof's rate,
    i.e. at that dof's minima) crosses its mean upwards.

    ``jobs`` values at a time in forked processes (:func:`whirl_cli.runtime.forked_map`:
    each value's simulation is independent of the others, so the results are identical for
    any ``jobs``, in the order of ``explore``). A failure is the result ``diverged`` with its
    message, never raised."""
    parameter = model.parameter(model.canonical(spec.parameter))
    first = model.state_names[model.positions[0]]  # the first dof (or first-order state)
    y0 = seeds.seed_state(model, spec.explore_start(first))
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
    simulate.import_integrators()
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
        """The branches of extra slices at ``values`` (not stored: they only judge folds, by
        the stable cycles of each fold's own family, so no family branching off is run)."""
        def run(named: tuple[str, float]) -> tuple:
            return one_parameter(engine, named[0], pair[0], spec.start, bounds[pair[0]],
                                 {**parameters, pair[1]: named[1]}, numerics,
                                 periodic=True, cycle_branching=False).branches
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
