"""Special points recomputed at a reduced smoothing by short AUTO runs near them: the fast path
of the persistence check (:mod:`whirl_cli.continuation.persistence`), instead of repeating the
whole continuation at every factor of :data:`persistence.FACTORS`.

Two ways, tried in this order for each special point of a type AUTO detects:

1. **restart**: the run that found the point is restarted from its labelled point before the
   special point, with every smoothing width times the factor (the other constants as that
   run's, so the same direction, mesh and steps), up to the first point of the same type
   (AUTO's ``STOP``; at most twice the steps the original run took between the two labels,
   plus :data:`SPARE_STEPS`). Starting before the point lets the run pass through it wherever
   the smaller smoothing moved it along the family (restarting at the point itself lands on
   either side of a fold that moved, and the run never meets it). A point AUTO finds from the
   Floquet multipliers (period doubling) is recomputed on :data:`MULTIPLIER_MESH` times the
   mesh, at the study's width too, where it is located again (its multipliers on the study's
   mesh can err by more than a shallow pair of period doublings dips below -1); a run
   starts before the first of such points in a row and stops at the one it recomputes.
2. **epsilon locus** (folds of cycles, one smoothing width): the fold continued in the
   principal parameter and the smoothing width (AUTO's two-parameter LPC locus,
   :func:`whirl_cli.continuation.loci.locus_constants`, on twice the mesh of the run that
   found it, at most four times the study's; steps scaled to the width), both ways from the
   fold, with user points (UZ) at the reduced widths: the principal parameter where the locus
   crosses each of them.

A point for which neither gives a value at every factor, each within the persistence
tolerance of the one before, is left to the repetition (the caller repeats the continuation if
any such point is left, and takes only their values from it): the short runs confirm that a
point persists, the repetition judges the others (missing, or moved: artefacts). The values
agree with the repetition's to the persistence tolerance (``tests/auto/test_seeds.py``, which
makes the repetition too).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..results import BranchKind, ContinuationResult, Origin, PointType, SpecialPoint
from .branches import special_points
from .engine import Engine, Numerics, RunSpec, read_run
from .loci import locus_constants
from .persistence import Recomputed

#: AUTO's STOP code for the first point of each type a restart looks for.
STOP_CODES = {PointType.LP: "LP", PointType.LPC: "LP", PointType.HB: "HB", PointType.BP: "BP",
              PointType.BPC: "BP", PointType.PD: "PD", PointType.TR: "TR"}
#: Steps a restart may take beyond twice the steps between its start and the point.
SPARE_STEPS = 10
#: The epsilon locus: its first and largest steps, in smoothing widths (the locus moves mostly
#: in the width, which changes by 3/4 of itself), its step limit, and its mesh as a multiple
#: of the mesh of the run that found the fold (on that mesh it fails to reach epsilon/4 on
#: studies/freeplay/pitch_airspeed.yaml's upper fold)...
LOCUS_STEP, LOCUS_STEP_MAX, LOCUS_STEPS, LOCUS_MESH = 0.02, 0.5, 200, 2
#: ... but at most this multiple of the study's mesh (a fold found by a refined retry).
LOCUS_MESH_CAP = 4
#: A user point on the locus is at a reduced width if within this fraction of it (AUTO locates
#: user points to EPSS, set to a thousandth of the smallest width on the locus).
WIDTH_MATCH = 1e-2
#: Types AUTO finds from the Floquet multipliers, whose error on the study's mesh can exceed
#: how far a multiplier passes -1 (a shallow period-doubling pair near a homoclinic orbit:
#: found about 1e-2 m/s off the smoothed law's own in studies/freeplay/pitch_offset_cycles.yaml),
#: and the multiple of the mesh of the run that found them they are recomputed on (on twice
#: the mesh that study's pair still comes out doubled at epsilon / 4).
MULTIPLIER_TYPES, MULTIPLIER_MESH = frozenset({PointType.PD}), 4
#: How each point was recomputed (``SpecialPoint.refined_by``).
RESTART, LOCUS, REPETITION = "restart", "epsilon locus", "repetition"


def recompute(engine: Engine, name: str, continuation: ContinuationResult,
              parameters: dict[str, float], smoothing: tuple[str, ...],
              factors: tuple[float, ...], checked: frozenset[int], bounds: tuple[float, float],
              numerics: Numerics, reach: float) -> dict[int, Recomputed]:
    """The special points of ``continuation`` (by index) of the ``checked`` types recomputed
    at every smoothing width (``smoothing``: their names; ``parameters``: the study's values,
    the widths among them or the model's datums) times each of ``factors``; points neither
    way recomputes within ``reach`` (of the principal parameter) of the point at every factor,
    each factor's value within ``reach`` of the one before, are absent: the short runs only
    confirm that a point persists (a point they find elsewhere may be another one of its
    type: the repetition, which looks at all of them, decides). Runs
    ``<name>/shrink_<k>_eps<j>`` (point ``k``, ``j``-th factor) and
    ``<name>/shrink_<k>_locus<side>`` (``a``, ``b``; ``...2`` after the first 5 steps)."""
    widths = _widths(engine, parameters, smoothing)
    runs = {b.name: b.runs for b in continuation.branches}
    todo = {k: p for k, p in enumerate(continuation.special_points)
            if p.point_type in checked and p.label and p.branch in runs}
    shared = _same_solution(todo, runs)
    todo = {k: p for k, p in todo.items() if k not in shared}
    found = _close(_restarted(engine, name, todo, runs, widths, factors, numerics), todo,
                   reach)
    folds = {k: p for k, p in todo.items() if k not in found and p.point_type == PointType.LPC}
    if len(widths) == 1 and folds:
        found |= _close(_by_locus(engine, name, folds, runs, widths, factors, bounds,
                                  numerics), todo, reach)
    return found | {k: found[j] for k, j in shared.items() if j in found}


def _same_solution(points: dict[int, SpecialPoint], runs: dict[str, tuple[str, ...]]
                   ) -> dict[int, int]:
    """{k: j} for every point k (by index) of the type and label of an earlier point j in the
    same AUTO runs: both would restart from one solution (a mirror family mapped from another
    holds its runs, and its points are the images of the other's: of one parameter value)."""
    first: dict[tuple, int] = {}
    shared: dict[int, int] = {}
    for k, point in points.items():
        key = (runs[point.branch], point.label, point.point_type)
        if key in first:
            shared[k] = first[key]
        else:
            first[key] = k
    return shared


def _close(found: dict[int, Recomputed], points: dict[int, SpecialPoint],
           reach: float) -> dict[int, Recomputed]:
    """``found`` without the points whose values stray: NaN, or a step of more than
    ``reach`` from the point (where it was located again, if it was) to its first value or
    between values."""
    return {k: r for k, r in found.items() if np.all(np.abs(np.diff(np.concatenate(
        [(r.located or points[k]).parameters[:1], r.values]))) <= reach)}


def _widths(engine: Engine, parameters: dict[str, float],
            smoothing: tuple[str, ...]) -> dict[str, float]:
    """The smoothing widths as the study runs them, by name."""
    values = engine.model.parameter_vector(parameters)
    names = [p.name for p in engine.model.parameters]
    return {width: float(values[names.index(width)]) for width in smoothing}


def _source(engine: Engine, runs: dict[str, tuple[str, ...]], point: SpecialPoint) -> str | None:
    """The AUTO run that wrote ``point``'s label, or None."""
    try:
        return engine.run_with_label(runs[point.branch], point.label)
    except KeyError:
        return None


def _restart_spec(engine: Engine, name: str, k: int, j: int, point: SpecialPoint,
                  source: str, widths: dict[str, float], factor: float,
                  mesh: int | None = None) -> tuple[RunSpec, int] | None:
    """The short run from the label before ``point`` in ``source`` at ``factor`` times the
    smoothing (on ``mesh`` intervals if given) and which point of its type it stops at, or
    None (no label to start from)."""
    spec = engine.specs[source]
    start = (_multiplier_start if mesh else _label_before)(
        read_run(engine, spec, engine.outcomes[source]), point, source, spec.restart)
    if start is None:
        return None
    restart, steps, count = start
    constants = {key: value for key, value in spec.constants.items() if key not in ("PAR", "LAB")}
    constants.update(PAR={w: v * factor for w, v in widths.items()},
                     STOP=[f"{STOP_CODES[PointType(point.point_type)]}{count}"],
                     NMX=2 * steps + SPARE_STEPS, **({"NTST": mesh} if mesh else {}))
    return RunSpec(f"{name}/shrink_{k}_eps{j}", constants, spec.kind,
                   Origin.at(point, f"smoothing x {factor:g}"),
                   spec.parameter_names, restart=restart, data=None), count


def _label_before(run, point: SpecialPoint, source: str,
                  _start) -> tuple[tuple[str, int], int, int] | None:
    """(restart, steps to ``point``, 1): from the label before ``point`` in its run ``run``
    (AUTO's name ``source``), or None."""
    rows = np.flatnonzero(run.label == point.label)
    labelled = [r for r in np.flatnonzero(run.label) if rows.size and r < rows[0]]
    if not labelled:
        return None
    return (source, int(run.label[labelled[-1]])), int(rows[0] - labelled[-1]), 1


def _multiplier_start(run, point: SpecialPoint, source: str,
                      start: tuple[str, int] | None) -> tuple[tuple[str, int], int, int] | None:
    """(restart, steps to ``point``, which point of its type after the restart it is) for a
    point found from the Floquet multipliers: from the label before the first of the points
    of its type that lead up to it with no other special point between (a finer mesh may
    move each of a close pair, but keeps their order), else from where ``run`` (AUTO's name
    ``source``) itself started (``start``); None if another special point comes first."""
    rows = np.flatnonzero(run.label == point.label)
    if not rows.size:
        return None
    row, count, before = int(rows[0]), 1, None
    for r in np.flatnonzero(run.label[:row])[::-1]:  # the labels before it, nearest first
        kind = PointType(int(run.point_type[r]))
        if kind == point.point_type:
            count, before = count + 1, None
        elif kind.is_special:
            return None if before is None else ((source, int(run.label[before])),
                                                row - before, count)
        elif before is None:
            before = int(r)
    if before is not None:
        return (source, int(run.label[before])), row - before, count
    return None if start is None else (start, row, count)


def _restarted(engine: Engine, name: str, points: dict[int, SpecialPoint],
               runs: dict[str, str], widths: dict[str, float],
               factors: tuple[float, ...], numerics: Numerics) -> dict[int, Recomputed]:
    """Path 1 (module docstring) for every point of a type AUTO can stop at, side by side;
    a point AUTO finds from its Floquet multipliers on :data:`MULTIPLIER_MESH` times the
    mesh, at the study's width too (its location there: ``Recomputed.located``)."""
    specs: list[tuple[int, float, RunSpec, int]] = []
    for k, point in points.items():
        source = _source(engine, runs, point)
        if PointType(point.point_type) not in STOP_CODES or source is None:
            continue
        mesh = _multiplier_mesh(engine, source, point, numerics)
        wanted = ((1.0,) if mesh else ()) + factors  # (run 0: the study's width)
        made = [_restart_spec(engine, name, k, j, point, source, widths, f, mesh)
                for j, f in enumerate(wanted, 0 if mesh else 1)]
        if all(made):
            specs += [(k, f, spec, count) for f, (spec, count) in zip(wanted, made, strict=True)]
    values: dict[int, list[float]] = {}
    located: dict[int, SpecialPoint | None] = {}
    for (k, factor, spec, count), outcome in zip(
            specs, engine.run_many([spec for _, _, spec, _ in specs]), strict=True):
        same = [p for p in special_points(read_run(engine, spec, outcome), skip_first=True)
                if p.point_type == points[k].point_type][count - 1:count]
        if factor == 1.0:
            located[k] = same[0] if same else None
        else:
            values.setdefault(k, []).append(float(same[0].parameters[0]) if same
                                            else float("nan"))
    return {k: Recomputed(np.array(v), RESTART, located.get(k)) for k, v in values.items()
            if np.all(np.isfinite(v)) and (k not in located or located[k] is not None)}


def _multiplier_mesh(engine: Engine, source: str, point: SpecialPoint,
                     numerics: Numerics) -> int | None:
    """The finer mesh (intervals) to recompute ``point`` on if AUTO finds its type from the
    Floquet multipliers, else None."""
    if point.point_type not in MULTIPLIER_TYPES:
        return None
    return min(MULTIPLIER_MESH * engine.specs[source].constants["NTST"],
               LOCUS_MESH_CAP * numerics.mesh_intervals)


def _by_locus(engine: Engine, name: str, folds: dict[int, SpecialPoint],
              runs: dict[str, tuple[str, ...]],
              widths: dict[str, float], factors: tuple[float, ...],
              bounds: tuple[float, float], numerics: Numerics) -> dict[int, Recomputed]:
    """Path 2 (module docstring) for every fold of cycles, both ways side by side: AUTO
    builds the extended system in a first run of 5 steps, the locus follows from its end."""
    model = engine.model
    ((width, value),) = widths.items()
    first: list[tuple[int, RunSpec]] = []
    for k, point in folds.items():
        source = _source(engine, runs, point)
        if source is None:
            continue
        pair = (point.parameter_names[0], width)
        mesh = min(LOCUS_MESH * engine.specs[source].constants["NTST"],
                   LOCUS_MESH_CAP * numerics.mesh_intervals)
        for direction, side in ((1, "a"), (-1, "b")):
            constants = locus_constants(model, numerics, pair, {
                pair[0]: bounds, width: (0.8 * value * min(factors), 1.25 * value)},
                direction, PointType.LPC)
            constants.update(NMX=5, NTST=mesh, DS=direction * LOCUS_STEP * value,
                             DSMAX=LOCUS_STEP_MAX * value, DSMIN=1e-6 * value,
                             EPSS=1e-3 * value * min(factors))
            first.append((k, RunSpec(
                f"{name}/shrink_{k}_locus{side}", constants, BranchKind.FOLD_OF_CYCLES_LOCUS,
                Origin(point=PointType.LPC, parameter=pair[0], value=float(point.parameters[0]),
                       branch=point.branch), pair,
                restart=(source, point.label))))
    second = [(k, replace(spec, name=spec.name + "2", restart=(outcome.name,
                                                               outcome.labels[-1][1]),
                          constants=dict(spec.constants, NMX=LOCUS_STEPS,
                                         UZR={width: [value * f for f in factors]})))
              for (k, spec), outcome in zip(first, engine.run_many([s for _, s in first]),
                                            strict=True)
              if outcome.has_output and outcome.labels]
    values: dict[int, np.ndarray] = {}
    for (k, spec), outcome in zip(second, engine.run_many([s for _, s in second]),
                                  strict=True):
        crossed = _crossings(read_run(engine, spec, outcome), value, factors)
        known = values.get(k, crossed)
        values[k] = np.where(np.isnan(known), crossed, known)  # either side's crossings
    return {k: Recomputed(v, LOCUS) for k, v in values.items() if np.all(np.isfinite(v))}


def _crossings(locus, value: float, factors: tuple[float, ...]) -> np.ndarray:
    """The principal parameter at the first user point of ``locus`` at each reduced width
    ``value * factor`` (NaN where none)."""
    found = []
    for factor in factors:
        rows = [r for r in range(len(locus)) if locus.point_type[r] == PointType.UZ
                and abs(locus.parameters[r, 1] - value * factor) <= WIDTH_MATCH * value * factor]
        found.append(float(locus.parameters[rows[0], 0]) if rows else float("nan"))
    return np.array(found)
