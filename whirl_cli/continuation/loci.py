"""The two-parameter recipe: one-parameter runs at every slice, then the loci of their special
points (Hopf, branch point, fold, fold of cycles), each traced once, chunk by chunk.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from functools import partial

import numpy as np

from ..auto import runner
from ..auto.constants import TORUS_ANGLE_INDEX, par_layout
from ..kinds import LocusKind
from ..models import Model
from ..results import (
    STEP_LIMIT,
    Branch,
    BranchKind,
    ContinuationKind,
    ContinuationResult,
    LocateStatus,
    Origin,
    PointType,
    RunStatus,
    SpecialPoint,
    slice_branch,
)
from ..runtime import thread_map
from .branches import head, join, last_good_label, same_point, special_points, typical_amplitudes
from .criticality import with_bautin_verdict
from .engine import Engine, Numerics, RunSpec, read_run
from .equilibria import equilibrium_constants
from .geometry import (
    at_range_edge,
    chunk_used,
    cut_closed,
    extreme_scale,
    has_merged,
    locus_coordinates,
    near_polyline,
    on_paths,
)
from .one_parameter import one_parameter
from .periodic import OrbitStart

#: Special point type -> (locus name in studies, branch kind of its locus).
LOCI = {
    PointType.HB: (LocusKind.HOPF, BranchKind.HOPF_LOCUS),
    PointType.BP: (LocusKind.BRANCH_POINT, BranchKind.BRANCH_POINT_LOCUS),
    PointType.LP: (LocusKind.FOLD, BranchKind.FOLD_LOCUS),
    PointType.LPC: (LocusKind.FOLD_OF_CYCLES, BranchKind.FOLD_OF_CYCLES_LOCUS),
    PointType.TR: (LocusKind.TORUS, BranchKind.TORUS_LOCUS),
}

#: Loci of bifurcations of cycles: AUTO starts them in two stages (see :func:`_trace`).
CYCLE_LOCI = (PointType.LPC, PointType.TR)


def locus_constants(model: Model, numerics: Numerics, pair: tuple[str, str],
                    bounds: dict[str, tuple[float, float]], direction: int,
                    kind: PointType) -> dict:
    """Constants of a two-parameter locus (ISW=2) of a special point of type ``kind``.
    Debian's AUTO 0.9.2 overruns a heap buffer on fold-of-cycles loci unless ISP=0. A torus
    locus is continued with ISP=0 and ILP=0 (AUTO's demo ``tor``) and has four free
    parameters: the pair, the period PAR(11) and the torus angle PAR(12). AUTO (INITPS in
    periodic.f90) frees the last two itself only when ICP has fewer than four entries; ICP
    lists the PVLS outputs after them, so both are named here (else the angle stays frozen
    and a PVLS output takes its place: a locus that does not move)."""
    first, second = pair
    constants = equilibrium_constants(model, numerics, first, bounds[first], direction)
    angle = [TORUS_ANGLE_INDEX] if kind == PointType.TR else []
    constants.update(ISW=2, ICP=[first, second, "PERIOD", *angle,
                                 *par_layout(model).measures()])
    constants.pop("UZR", None)
    lower, upper = bounds[second]
    constants["UZSTOP"] = dict(constants["UZSTOP"], **{second: [lower, upper]})
    if kind == PointType.LPC:
        constants.update(IPS=2, ISP=0, ILP=1)
    elif kind == PointType.TR:
        constants.update(IPS=2, ISP=0, ILP=0)
    return constants


def two_parameter(engine: Engine, name: str, pair: tuple[str, str],
                  bounds: dict[str, tuple[float, float]], start: float,
                  slices: tuple[float, ...], loci: tuple[str, ...],
                  parameters: dict[str, float], numerics: Numerics,
                  slice_orbits: tuple[tuple[OrbitStart, ...], ...] = (),
                  snaking_folds: str = "outermost") -> tuple[ContinuationResult, list[Branch]]:
    """One-parameter runs at every slice of the second parameter, then the loci of their
    special points (both directions, each locus once). Returns the continuation (slice branches
    named ``slice_<k>.<branch>`` and the locus branches) and the locus branches.
    ``slice_orbits``: per slice, orbits (e.g. settled seeds) whose periodic families that
    slice's run continues too (their folds of cycles start loci as a Hopf family's do; those
    of the families branching off at branch points of cycles start none: they stay on the
    slices).
    ``snaking_folds``: "all", or "outermost" (:func:`_outermost_folds`)."""
    first, second = pair
    wanted = {kind for kind, (locus, _) in LOCI.items() if locus in loci}
    periodic = any(kind in wanted for kind in CYCLE_LOCI)
    amplitudes = typical_amplitudes(engine.model)
    branches: list[Branch] = []
    points: list[SpecialPoint] = []
    starts: list[tuple[SpecialPoint, str]] = []

    def run_slice(k: int) -> ContinuationResult:
        return one_parameter(engine, f"{name}.slice_{k}", first, start, bounds[first],
                             {**parameters, second: slices[k]}, numerics, periodic=periodic,
                             start_orbits=slice_orbits[k] if slice_orbits else ())

    # the slices are independent: side by side (the engine runs at most its jobs of AUTO)
    results = thread_map(run_slice, range(len(slices)), len(slices))
    for k, (value, result) in enumerate(zip(slices, results, strict=True)):
        runs = {b.name: b.runs for b in result.branches}
        switched = {b.name for b in result.branches if b.origin.point == PointType.BPC}
        for branch in result.branches:
            branches.append(replace(branch, name=slice_branch(k, branch.name)))
        for point in result.special_points:
            named = replace(point, branch=slice_branch(k, point.branch), parameter_names=pair,
                            parameters=np.array([point.parameters[0], value]))
            points.append(named)
            width = bounds[first][1] - bounds[first][0]
            if point.point_type in wanted and point.branch not in switched and \
                    _starts_locus(point) and not any(
                    point.point_type == other.point_type
                    and same_point(named, other, width, amplitudes)
                    for other, _ in starts):
                starts.append((named, runs[point.branch]))
    traced = _loci(engine, name, pair, bounds, numerics, starts,
                   partial(locus_points, engine.model, pair=pair, parameters=parameters),
                   outermost=snaking_folds == "outermost")
    curves = [curve for curve, _ in traced]
    points += [point for _, found in traced for point in found]
    return (ContinuationResult(name, ContinuationKind.TWO_PARAMETER, tuple(branches + curves),
                               tuple(points)), curves)


def locus_points(model: Model, curve: Branch, pair: tuple[str, str],
                 parameters: dict[str, float]) -> list[SpecialPoint]:
    """The special points of a locus after its start, the GH points of a Hopf locus with
    their verdict (:func:`.criticality.with_bautin_verdict`)."""
    points = special_points(curve, skip_first=True)
    if curve.kind != BranchKind.HOPF_LOCUS:
        return points
    return [with_bautin_verdict(model, curve, p, pair, parameters) for p in points]


def _starts_locus(point: SpecialPoint) -> bool:
    """True if the located special ``point`` starts a locus: a torus point only with its
    pair of Floquet multipliers on the unit circle (a finite ``torus_angle``; AUTO's test
    function also changes sign at a neutral saddle, a real pair with product 1, which is no
    torus bifurcation, and a TR point without multipliers cannot be told apart)."""
    if point.status != LocateStatus.LOCATED:
        return False
    return point.point_type != PointType.TR or bool(np.isfinite(point.torus_angle))


def _loci(engine: Engine, name: str, pair: tuple[str, str],
          bounds: dict[str, tuple[float, float]], numerics: Numerics,
          starts: list[tuple[SpecialPoint, str]],
          checked: Callable[[Branch], list[SpecialPoint]] | None = None,
          outermost: bool = False) -> list[tuple[Branch, list[SpecialPoint]]]:
    """Locus branches from the start points, both directions, each locus once (``outermost``:
    of the folds of cycles of a snaking family only the outermost, :func:`_outermost_folds`),
    each with its special points after its start as ``checked`` gives them (with their
    verdicts, :func:`locus_points`, computed once per locus; their located codimension-2
    points may end a locus, and a locus ending at one is not retried).

    Starts are taken slice by slice (a wave per slice): a start lying on a locus of its type
    already traced from an earlier slice is the same locus and is not run again, nor is a
    start with the same type, parameters and period as another (a symmetric twin: its locus
    is the same curve in the parameter plane). Loci grow chunk by chunk,
    and after every chunk those that repeat others are dropped, those that closed are cut
    and those that ran onto another stop (:func:`_grown`), so a duplicate or a loop costs one
    chunk beyond where it is recognised; only kept loci ending
    in MX are retried (AUTO's runs, not just the results, are saved); duplicates left after
    the retries are dropped. While a wave grows, the first chunks of the next wave's starts
    not on the loci known before it (nor on its own first chunks) are traced on the cores it
    leaves idle; those then found on its loci are set aside (the others are traced then), so
    the loci are those of tracing wave after wave."""
    width = np.array([bounds[p][1] - bounds[p][0] for p in pair])
    checked = _once(checked or partial(special_points, skip_first=True))
    numbered = list(enumerate(starts, 1))
    waves: dict[str, list] = {}
    for k, (point, runs) in numbered:
        waves.setdefault(point.branch.split(".", 1)[0], []).append((k, point, runs))
    curves: list[tuple[int, Branch]] = []

    def todo(wave: list, also: list[tuple[int, Branch]] = ()
             ) -> list[tuple[int, SpecialPoint, str]]:
        distinct = _without_twins([(k, point, runs) for k, point, runs in wave if not any(
            kind == point.point_type and near_polyline(point.parameters[:2], curve.parameters,
                                                        width)
            for kind, curve in [*curves, *also])], width)
        return _outermost_folds(distinct, width) if outermost else distinct

    def following(waves: list[list]) -> tuple[list | None, list]:
        """The next wave with starts still to trace (one without any stays so: more loci
        only set more aside), and those after it."""
        for j, wave in enumerate(waves):
            if todo(wave):
                return wave, waves[j + 1:]
        return None, []

    now, later = following(list(waves.values()))
    ahead = _trace(engine, name, pair, bounds, numerics, todo(now)) if now else []
    while now is not None:
        wanted = todo(now)
        done_ahead = {k for k, *_ in ahead}
        late = [start for start in wanted if start[0] not in done_ahead]
        if late:  # a twin set aside ahead, whose other has since been set aside
            ahead += _trace(engine, name, pair, bounds, numerics, late)
        position = {k: j for j, (k, _, _) in enumerate(wanted)}
        # in the order of tracing them now: equilibria's loci and cycles' first stages
        # (those that ended there), then cycles' second stages; start by start, a then b
        traced = dict(enumerate((kind, spec, branch) for _, kind, spec, branch in sorted(
            (row for row in ahead if row[0] in position),
            key=lambda row: (row[2].name.endswith("2"), position[row[0]], row[2].name))))
        tasks = [partial(_wave, engine, pair, bounds, numerics, traced, list(curves), width,
                         checked)]
        now, later = following(later)
        if now is not None:  # not those on this wave's first chunks either
            tasks.append(partial(_trace, engine, name, pair, bounds, numerics, todo(
                now, [(kind, curve) for kind, _, curve in traced.values()]), background=True))
        done = thread_map(lambda task: task(), tasks, len(tasks))
        curves += done[0]
        ahead = done[1] if now is not None else []
    kept = [curve for _, _, curve in _distinct(
        {k: (kind, None, curve) for k, (kind, curve) in enumerate(
            sorted(curves, key=lambda c: c[1].name))}, [], width)[0].values()]
    found = [(curve, checked(curve)) for curve in kept]
    codim2 = _codim2(kept, checked)
    points = tuple(point for point, _ in starts)
    return [(_locus_end(c, codim2, bounds, width, points, numerics.max_steps), on_it)
            for c, on_it in found]


def _wave(engine: Engine, pair: tuple[str, str], bounds: dict[str, tuple[float, float]],
          numerics: Numerics, traced: dict[int, tuple[int, RunSpec, Branch]],
          curves: list[tuple[int, Branch]], width: np.ndarray,
          checked: Callable[[Branch], list[SpecialPoint]]) -> list[tuple[int, Branch]]:
    """(point type, locus) of every one of the loci ``traced`` (their first chunks, by
    index), grown chunk by chunk side by side beside the ``curves`` known (:func:`_grown`);
    those ending in MX away from a located codimension-2 point of the known loci (as
    ``checked`` judges their points) retried once (:func:`_retried`)."""
    fresh, uncut = _grown(engine, traced, curves, numerics, bounds, width)
    ends = _codim2([c for _, c in curves] + [c for _, _, c in fresh.values()], checked)
    unclosed = {k: fresh[k] for k in uncut
                if not _ending_at(fresh[k][2].parameters[-1, :2], ends, width)}
    retried = _retried(engine, unclosed, numerics)
    others = curves + [(kind, c) for k, (kind, _, c) in fresh.items() if k not in retried]
    again, _ = _grown(engine, retried, others, numerics, bounds, width)
    fresh.update({k: again.get(k, fresh[k]) for k in retried})
    return [(kind, curve) for kind, _, curve in fresh.values()]


def _codim2(curves: list[Branch], checked: Callable[[Branch], list[SpecialPoint]]
            ) -> list[SpecialPoint]:
    """The located codimension-2 points of ``curves``, as ``checked`` gives their special
    points (a GH point whose first Lyapunov coefficient does not change sign is rejected)."""
    return [p for c in curves for p in checked(c)
            if p.point_type in CODIM2 and p.status == LocateStatus.LOCATED]


def _once(checked: Callable[[Branch], list[SpecialPoint]]
          ) -> Callable[[Branch], list[SpecialPoint]]:
    """``checked`` computed once per locus (loci are frozen: by identity, each kept)."""
    seen: dict[int, tuple[Branch, list[SpecialPoint]]] = {}

    def points(curve: Branch) -> list[SpecialPoint]:
        if id(curve) not in seen:
            seen[id(curve)] = (curve, checked(curve))
        return seen[id(curve)][1]
    return points


def _ending_at(last: np.ndarray, codim2: list[SpecialPoint], width: np.ndarray
               ) -> SpecialPoint | None:
    """The codimension-2 point within 1 % of the ranges of a locus's end ``last``, if any
    (where a locus naturally ends: AUTO stops there with MX and a retry cannot pass it)."""
    return next((p for p in codim2 if np.abs((p.parameters[:2] - last) / width).max() < 0.01),
                None)


def _without_twins(starts: list[tuple[int, SpecialPoint, str]], width: np.ndarray
                   ) -> list[tuple[int, SpecialPoint, str]]:
    """``starts`` without those of the same type, parameters (to 1e-7 of the ranges) and
    period (1e-5 relative) as an earlier one: mirror images under a symmetry of the model,
    whose loci are one curve in the parameter plane (two different points agreeing so is
    not generic)."""
    kept: list[tuple[int, SpecialPoint, str]] = []
    for k, point, runs in starts:
        if not any(point.point_type == other.point_type
                   and np.all(np.abs(point.parameters[:2] - other.parameters[:2]) <= 1e-7 * width)
                   and abs(point.period - other.period) <= 1e-5 * abs(point.period)
                   for _, other, _ in kept):
            kept.append((k, point, runs))
    return kept


def _outermost_folds(starts: list[tuple[int, SpecialPoint, str]], width: np.ndarray
                     ) -> list[tuple[int, SpecialPoint, str]]:
    """``starts`` without the inner folds of cycles of every bundle: three or more folds of
    cycles of one family (branch) within 1e-3 of the ranges of the bundle's first, as the folds
    of a family snaking toward a homoclinic orbit are (nearly the same parameters, periods
    growing along it); of those only the lowest- and highest-period ones are kept. Their loci
    run along the homoclinic locus and the inner ones' lie along theirs."""
    bundles: list[list[tuple[int, SpecialPoint, str]]] = []
    for start in starts:
        point = start[1]
        if point.point_type != PointType.LPC:
            continue
        bundle = next((b for b in bundles if b[0][1].branch == point.branch
                       and np.all(np.abs(point.parameters[:2] - b[0][1].parameters[:2])
                                  <= 1e-3 * width)), None)
        if bundle is None:
            bundles.append([start])
        else:
            bundle.append(start)
    inner = {k for bundle in bundles if len(bundle) >= 3
             for k, _, _ in sorted(bundle, key=lambda start: start[1].period)[1:-1]}
    return [start for start in starts if start[0] not in inner]


def _distinct(curves: dict[int, tuple[int, RunSpec | None, Branch]],
              known: list[tuple[int, Branch]], width: np.ndarray
              ) -> tuple[dict[int, tuple[int, RunSpec | None, Branch]], set[int]]:
    """The (point type, last run, locus) of ``curves``, each cut where it closes, without
    those lying wholly (every point within 1e-3 of the ranges) on the ``known`` loci and the
    other kept ones of their type, later ones dropped first (a mirror image, or a locus drawn
    within a line's width of others, adds nothing to the picture); and the indices of the
    kept loci that have run onto another of their type (:func:`has_merged`, where orbits are
    compared too: continued, they would retrace it)."""
    closed = {k: (kind, spec, cut_closed(curve, width)) for k, (kind, spec, curve) in curves.items()
              if len(curve)}
    kept = set(closed)

    def others(k: int, points: dict[int, np.ndarray], fixed) -> list[np.ndarray]:
        kind = closed[k][0]
        return [p for other, p in fixed if other == kind] + [
            points[j] for j in kept if j != k and closed[j][0] == kind]

    plane = {k: c.parameters[:, :2] / width for k, (_, _, c) in closed.items()}
    known_plane = [(kind, c.parameters[:, :2] / width) for kind, c in known if len(c)]
    for k in sorted(closed, reverse=True):
        if on_paths(plane[k], others(k, plane, known_plane)).all():
            kept.discard(k)
    merged = set()
    for kind in {closed[k][0] for k in kept}:
        group = [closed[k][2] for k in kept if closed[k][0] == kind] + [
            c for other, c in known if other == kind and len(c)]
        scale = extreme_scale(group)
        full = {k: locus_coordinates(closed[k][2], width, scale) for k in kept
                if closed[k][0] == kind}
        known_full = [(kind, locus_coordinates(c, width, scale)) for other, c in known
                      if other == kind and len(c)]
        merged |= {k for k in full if has_merged(full[k], others(k, full, known_full))}
    return {k: closed[k] for k in sorted(kept)}, merged


def _trace(engine: Engine, name: str, pair: tuple[str, str],
           bounds: dict[str, tuple[float, float]], numerics: Numerics,
           starts: list[tuple[int, SpecialPoint, tuple[str, ...]]], background: bool = False
           ) -> list[tuple[int, int, RunSpec, Branch]]:
    """(start number, point type, last run, locus branch) of every start, both directions,
    run in parallel (``background``: see :meth:`Engine.run_many`): the first chunk of steps
    of each (not yet continued, nor retried); loci of equilibria first, then those of
    cycles (their second stage)."""
    model = engine.model
    specs = []
    for k, point, runs in starts:
        kind = PointType(point.point_type)
        locus, branch_kind = LOCI[kind]
        source = engine.run_with_label(runs, point.label)
        origin = Origin.at(point)
        for direction, tag in ((1, "a"), (-1, "b")):
            constants = locus_constants(model, numerics, pair, bounds, direction, kind)
            if kind in CYCLE_LOCI:  # stage 1: AUTO builds the extended system (NMX 5)
                constants["NMX"] = 5
            specs.append((k, kind, RunSpec(f"{name}/{locus}_{k}{tag}", constants, branch_kind,
                                           origin, pair, restart=(source, point.label))))
    outcomes = engine.run_many([spec for _, _, spec in specs], background)
    second_stage = []
    final: list[tuple[int, int, RunSpec, runner.RunOutcome]] = []
    for (k, kind, spec), outcome in zip(specs, outcomes, strict=True):
        if kind in CYCLE_LOCI and outcome.has_output:
            constants = dict(spec.constants, NMX=min(FIRST_CHUNK, numerics.max_steps))
            second_stage.append((k, kind, replace(
                spec, name=spec.name + "2", constants=constants,
                restart=(outcome.name, outcome.labels[-1][1]))))
        else:
            final.append((k, kind, spec, outcome))
    final += [(k, kind, spec, outcome) for (k, kind, spec), outcome in zip(
        second_stage, engine.run_many([spec for _, _, spec in second_stage], background),
        strict=True)]
    return [(k, kind, spec, read_run(engine, spec, outcome)) for k, kind, spec, outcome in final]


#: Loci of cycles (fold of cycles, torus) go FIRST_CHUNK steps, then LOCUS_CHUNK steps at a
#: time: a closed locus, or one repeating another, is recognised after the chunk where it does so
#: instead of being traced up to the step limit (most closed loci of the chapter-3 boundaries
#: take under 100 steps round). Later chunks are longer: every restart begins again at the
#: initial step DS, a hazard in a difficult stretch (a restart there has ended in MX).
FIRST_CHUNK = 100
LOCUS_CHUNK = 400
CHUNKED = {BranchKind.FOLD_OF_CYCLES_LOCUS, BranchKind.TORUS_LOCUS}


def _grown(engine: Engine, traced: dict[int, tuple[int, RunSpec, Branch]],
           known: list[tuple[int, Branch]], numerics: Numerics,
           bounds: dict[str, tuple[float, float]], width: np.ndarray
           ) -> tuple[dict[int, tuple[int, RunSpec, Branch]], set[int]]:
    """The loci ``traced`` (point type, last run, branch by index) continued chunk by chunk
    from their last point while they use up their chunk of steps (up to
    ``numerics.max_steps`` in all); after each chunk, those repeating a ``known`` locus or
    one before them are dropped and those that closed are cut (:func:`_distinct`). Returns
    the kept loci and the indices of those not cut (that ended of themselves)."""
    grown = dict(traced)
    cut: set[int] = set()
    # not continued again: a restart that made no step, or a chunk drawn over the locus's
    # own path (in the parameter plane: it wanders to and fro over what it has drawn)
    stalled: set[int] = set()
    chunk = 1
    while True:
        kept, merged = _distinct(grown, known, width)
        cut |= merged | {k for k, (_, _, curve) in kept.items() if len(curve) < len(grown[k][2])}
        again = {k: replace(spec, name=f"{spec.name}c{chunk}",
                            constants=dict(spec.constants, NMX=min(
                                LOCUS_CHUNK, numerics.max_steps - len(curve) + 1)),
                            restart=(curve.runs[-1], int(curve.label[-1])))
                 for k, (_, spec, curve) in kept.items()
                 if k not in cut | stalled and spec.kind in CHUNKED
                 and chunk_used(curve, width, bounds) and len(curve) < numerics.max_steps
                 and curve.label[-1]}
        if not again:
            return kept, set(kept) - cut
        grown = dict(kept)
        for (k, spec), outcome in zip(again.items(), engine.run_many(list(again.values())),
                                      strict=True):
            extra = read_run(engine, spec, outcome)
            kind, last, curve = kept[k]
            if len(extra) > 1:
                grown[k] = (kind, last, join(curve, extra, curve.name))
            if len(extra) <= 1 or on_paths(extra.parameters[1:, :2] / width,
                                            [curve.parameters[:, :2] / width]).all():
                stalled.add(k)
        chunk += 1


#: Codimension-2 points where loci may end (Bogdanov-Takens, cusp, zero-Hopf, Bautin, ...).
CODIM2 = {PointType.BT, PointType.CP, PointType.ZH, PointType.GH, PointType.R1, PointType.R2,
          PointType.R3, PointType.R4}


def _retried(engine: Engine, loci: dict[int, tuple[int, RunSpec, Branch]], numerics: Numerics
             ) -> dict[int, tuple[int, RunSpec, Branch]]:
    """Loci (point type, last run, branch by index) that ended in MX continued once more from
    their last good labelled point (:func:`_retry_from`) with twice the mesh and half the
    largest step, joined to what they had: (point type, retry run, locus) by index, for those
    retried."""
    again, where = [], []
    for k, (_, spec, curve) in loci.items():
        start = _retry_from(engine, spec, curve) if curve.status == RunStatus.MX else None
        if start is None:
            continue
        row, restart = start
        constants = dict(spec.constants, NTST=spec.constants["NTST"] * 2,
                         DSMAX=spec.constants["DSMAX"] / 2)
        if spec.kind in CHUNKED:
            constants["NMX"] = min(LOCUS_CHUNK, numerics.max_steps - row)
        again.append(replace(spec, name=spec.name + "r", constants=constants, restart=restart))
        where.append((k, row))
    done: dict[int, tuple[int, RunSpec, Branch]] = {}
    for spec, (k, row), outcome in zip(again, where, engine.run_many(again), strict=True):
        extra = read_run(engine, spec, outcome)
        kind, _, curve = loci[k]
        if len(extra):
            done[k] = (kind, spec, join(head(curve, row + 1), extra, curve.name))
    return done


def _retry_from(engine: Engine, spec: RunSpec, curve: Branch
                ) -> tuple[int, tuple[str, int]] | None:
    """(row, AUTO restart) of a locus's last good labelled point: its last labelled row
    other than the MX, or, for a locus of one run that AUTO labelled nowhere else (a locus of
    cycles ending in MX within its first chunk: only the MX is labelled), the point its run
    started from (its first row); None if neither."""
    row = last_good_label(curve)
    if row:
        label = int(curve.label[row])
        return row, (engine.run_with_label(curve.runs, label), label)
    if len(curve.runs) == 1 and len(curve) > 1 and spec.restart is not None:
        return 0, spec.restart
    return None


def _period_tolerance(curve: Branch) -> float:
    """Three times what the period of a locus changes in a step at either end (NaN without
    a period there)."""
    period = np.asarray(curve.period, dtype=float)
    return 3 * max(abs(period[-1] - period[-2]), abs(period[1] - period[0]))


def _other_orbit(curve: Branch) -> bool:
    """True if a locus back at its start's parameters has another orbit there: its period
    differs from its first by more than :func:`_period_tolerance` (a closing locus differs by
    about one step's change)."""
    if len(curve) < 3 or not np.all(np.isfinite(curve.period[[0, 1, -2, -1]])):
        return False
    return bool(abs(curve.period[-1] - curve.period[0]) > _period_tolerance(curve))


def _reached(curve: Branch, starts: tuple[SpecialPoint, ...], width: np.ndarray
             ) -> SpecialPoint | None:
    """The start point of the locus's type, other than its own, at the end of a locus back
    at its start's parameters with another orbit: within 0.005 of the ranges of the end, its
    period within :func:`_period_tolerance` of the end's (None if there is none)."""
    first, last, tolerance = curve.period[0], curve.period[-1], _period_tolerance(curve)
    kind = {locus_kind: point_type for point_type, (_, locus_kind) in LOCI.items()}[curve.kind]
    near = [p for p in starts if p.point_type == kind and np.isfinite(p.period)
            and np.abs((p.parameters[:2] - curve.parameters[-1, :2]) / width).max() < 0.005
            and abs(p.period - last) <= tolerance and abs(p.period - first) > tolerance]
    return min(near, key=lambda p: abs(last - p.period), default=None)


def _locus_end(curve: Branch, codim2: list[SpecialPoint], bounds: dict[str, tuple[float, float]],
               width: np.ndarray, starts: tuple[SpecialPoint, ...] = (),
               max_steps: int = Numerics.max_steps) -> Branch:
    """The locus with its end classified: range edge, closed (back at its start's
    parameters after leaving them; or there with another orbit: at another of the
    ``starts`` of its type, if one is there), a codimension-2 point (where AUTO typically
    stops with MX: that is the locus' natural end, not a failure), its study's step limit
    (``max_steps`` points), or a chunk of steps after which whirl did not continue it
    (:func:`_grown`)."""
    last = curve.parameters[-1, :2]
    if at_range_edge(curve, bounds, width):
        return replace(curve, end="range")
    from_start = np.abs((curve.parameters[:, :2] - curve.parameters[0, :2]) / width).max(axis=1)
    # back within 0.005 of the ranges of a start it had left by more than 0.02 (as
    # cut_closed): a locus that stopped a few steps from its start has not closed
    if len(curve) > 2 and from_start[-1] < 0.005 and from_start.max() > 0.02:
        if not _other_orbit(curve):
            return replace(curve, end="closed")
        # e.g. the folds of cycles of a family snaking toward a homoclinic orbit: the locus
        # of one leads to the next, whose own locus goes on
        reached = _reached(curve, starts, width)
        if reached is not None:
            return replace(curve, end=(
                f"at the {reached.type_name} of {reached.branch} at {curve.parameter_names[0]}"
                f" = {reached.parameters[0]:.6g} (period {reached.period:.4g} s)"))
        return replace(curve, end=(f"back at its start's parameters with another orbit (period"
                                   f" {curve.period[-1]:.4g} s; {curve.period[0]:.4g} s at "
                                   "its start)"))
    point = _ending_at(last, codim2, width)
    if point is not None:
        where = ", ".join(f"{v:.5g}" for v in point.parameters[:2])
        message = "ok" if curve.status == RunStatus.OK else \
            "AUTO stopped with MX at the codimension-2 point (the locus ends there)"
        return replace(curve, end=f"{point.type_name} at ({where})", status=RunStatus.OK,
                       message=message)
    if curve.status == RunStatus.MX:
        return replace(curve, end="no convergence (MX)")
    return replace(curve, end=STEP_LIMIT if len(curve) >= max_steps else "not continued after "
                   "its last chunk of steps")

