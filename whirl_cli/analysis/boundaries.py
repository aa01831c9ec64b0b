"""Stability boundaries in two parameters and the unsafe (overhang) region.

The *unsafe* region holds the parameters where linear analysis calls the undeflected
equilibrium stable, yet whirl flutter (a limit-cycle family with a stable part) or static
divergence (secondary equilibria) exists. Along a slice (the second parameter fixed) it is:

* flutter: between a fold of cycles (LPC) where stable cycles begin and the Hopf point its
  family leans over from (a fold between two unstable sides bounds nothing),
* divergence: between a fold of the secondary equilibria (LP) and the pitchfork (BP),

each intersected with the linearly stable part of the slice. Two ways to get it:

* ``loci``: cross the Hopf, LPC, BP and LP loci (two-parameter continuation) with each row;
  a fold-of-cycles locus counts only along its stretches where the slices' periodic families
  (Floquet stability) find stable cycles beside its folds; where two slices disagree, extra
  slices place the edge;
* ``slices`` (the thesis' method): from one-parameter runs with periodic branches per slice.

Polygons of the region are assembled from the intervals of consecutive slices.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..kinds import BoundaryMethod, LocusKind, UnsafeCause
from ..models import Model
from ..results import Boundary, Branch, BranchKind, PointType, UnsafeInterval
from . import linear

Interval = tuple[float, float]


def stable_intervals(model: Model, overrides: dict[str, float], first: str, second: str,
                     values: list[float], bounds: Interval, points: int = 4001,
                     within: list[list[Interval]] | None = None, xtol: float = 1e-12
                     ) -> list[list[Interval]]:
    """Intervals of ``first`` where y = 0 is linearly stable, one list per value of ``second``
    in ``values``: the largest real part of the eigenvalues on a grid of ``points`` across
    ``bounds``, each change of sign then bisected to ``xtol`` (every row at once: one batched
    eigenvalue computation per step). ``within`` (per row): only the grid cells meeting these
    intervals are examined (the stable parts inside them are the same; outside, partial)."""
    grid = np.linspace(bounds[0], bounds[1], points)
    values = np.asarray(values, dtype=float)

    def stable_at(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        params = linear.plane_matrix(model, overrides, first, x, second, y)
        eigenvalues = linear.batched_eigenvalues(np.ascontiguousarray(
            linear.jacobians(model, params)))
        return eigenvalues.real.max(axis=1) < 0

    examined = np.array([_cells(grid, None if within is None else within[r])
                         for r in range(len(values))]).reshape(len(values), points)
    stable = np.zeros(examined.shape, dtype=bool)
    row, column = np.nonzero(examined)
    stable[row, column] = stable_at(grid[column], values[row])
    row, k = np.nonzero(examined[:, :-1] & examined[:, 1:] & (stable[:, :-1] != stable[:, 1:]))
    lower, upper, lower_stable = grid[k], grid[k + 1], stable[row, k]
    while len(k) and np.max(upper - lower) > xtol:
        middle = 0.5 * (lower + upper)
        same = stable_at(middle, values[row]) == lower_stable
        lower, upper = np.where(same, middle, lower), np.where(same, upper, middle)
    crossing = {(int(r), int(c)): float(0.5 * (a + b))
                for r, c, a, b in zip(row, k, lower, upper, strict=True)}
    found = []
    for r in range(len(values)):
        intervals = []
        for lo, hi in _runs(grid, stable[r]):
            lo_cell = int(np.searchsorted(grid, lo)) - 1
            hi_cell = int(np.searchsorted(grid, hi)) - 1
            intervals.append((crossing.get((r, lo_cell), lo), crossing.get((r, hi_cell), hi)))
        found.append(intervals)
    return found


def _cells(grid: np.ndarray, within: list[Interval] | None) -> np.ndarray:
    """(K,) which points of ``grid`` bound a cell meeting one of the intervals ``within``
    (all of them for None)."""
    if within is None:
        return np.ones(len(grid), dtype=bool)
    examined = np.zeros(len(grid), dtype=bool)
    for lo, hi in within:
        first = max(int(np.searchsorted(grid, lo, side="right")) - 1, 0)
        last = min(int(np.searchsorted(grid, hi, side="left")), len(grid) - 1)
        examined[first:last + 1] = True
    return examined


def _runs(grid: np.ndarray, flag: np.ndarray) -> list[Interval]:
    """Maximal intervals of ``grid`` where ``flag`` holds (ends at the mid-points)."""
    intervals = []
    edges = np.flatnonzero(np.diff(flag.astype(int))) + 1
    for part in np.split(np.arange(len(grid)), edges):
        if flag[part[0]]:
            lo = grid[part[0]] if part[0] == 0 else 0.5 * (grid[part[0] - 1] + grid[part[0]])
            hi = grid[part[-1]] if part[-1] == len(grid) - 1 else 0.5 * (
                grid[part[-1]] + grid[part[-1] + 1])
            intervals.append((float(lo), float(hi)))
    return intervals


def intersect(intervals: list[Interval], allowed: list[Interval],
              minimum: float = 0.0) -> list[Interval]:
    """The parts of ``intervals`` inside ``allowed`` (both lists of (lo, hi)), dropping pieces
    not longer than ``minimum``."""
    out = []
    for lo, hi in intervals:
        for a, b in allowed:
            left, right = max(lo, a), min(hi, b)
            if right - left > minimum:
                out.append((left, right))
    return merge(out)


def merge(intervals: list[Interval]) -> list[Interval]:
    """Union of intervals, sorted."""
    out: list[list[float]] = []
    for lo, hi in sorted(intervals):
        if out and lo <= out[-1][1]:
            out[-1][1] = max(out[-1][1], hi)
        else:
            out.append([lo, hi])
    return [(a, b) for a, b in out]


def crossings(curve: np.ndarray, value: float) -> list[float]:
    """First-coordinate values where the polyline ``curve`` (K, 2) crosses second = value."""
    return [x for _, _, x in _segment_crossings(curve, value)]


def _paired(folds: list[float], anchors: list[float]) -> list[Interval]:
    """Each fold with the nearest anchor (Hopf or pitchfork) as an interval."""
    if not anchors:
        return []
    return [tuple(sorted((f, min(anchors, key=lambda a: abs(a - f))))) for f in folds]


def slice_folds(branches: tuple[Branch, ...], hopfs: list[float], stable: list[Interval]
                ) -> list[tuple[float, bool]]:
    """The folds of cycles of one slice's periodic families, each with the verdict whether
    stable cycles (by their Floquet multipliers) lie beside it: its family's run of stable
    cycles beside the fold covers 90 % of the way to one of ``hopfs`` (the slice's Hopf
    points), or the family has stable cycles between the fold and the Hopf point nearest it
    where the undeflected equilibrium is linearly stable (``stable``: the slice's stable
    intervals; such cycles may lie beyond a torus point, the fold's own sides unstable)."""
    found = []
    for branch in branches:
        if branch.kind != BranchKind.PERIODIC:
            continue
        cycles = branch.parameters[branch.stable & branch.stability_known, 0]
        for k in np.flatnonzero(branch.point_type == PointType.LPC):
            fold = float(branch.parameters[k, 0])
            run = branch.parameters[_stable_run_beside(branch, int(k)), 0]
            beside = bool(len(run)) and any(
                _covered(run, fold, hopf) >= 0.9 * abs(hopf - fold) for hopf in hopfs)
            found.append((fold, beside or bool(hopfs) and _any_between(
                cycles, fold, min(hopfs, key=lambda h: abs(h - fold)), stable)))
    return found


def _covered(run: np.ndarray, a: float, b: float) -> float:
    """How much of the interval between ``a`` and ``b`` the extent of ``run`` covers."""
    lo, hi = min(a, b), max(a, b)
    return max(0.0, min(float(run.max()), hi) - max(float(run.min()), lo))


def _stable_run_beside(branch: Branch, index: int) -> np.ndarray:
    """Rows of the runs of known stable points of ``branch`` next to row ``index``."""
    stable = branch.stable & branch.stability_known
    rows = []
    for step in (-1, 1):
        k = index + step
        while 0 <= k < len(branch) and stable[k]:
            rows.append(k)
            k += step
    return np.array(sorted(rows), dtype=int)


def _any_between(values: np.ndarray, a: float, b: float, allowed: list[Interval]) -> bool:
    """Whether one of ``values`` lies strictly between ``a`` and ``b`` inside ``allowed``."""
    lo, hi = min(a, b), max(a, b)
    return any(np.any((values > max(lo, p)) & (values < min(hi, q))) for p, q in allowed)


def stable_fold_stretches(curve: np.ndarray, folds: dict[float, list[tuple[float, bool]]],
                          tolerance: float) -> list[np.ndarray]:
    """The stretches of the fold-of-cycles locus ``curve`` (K, 2) that bound stable cycles.

    Where the locus crosses a slice (second parameter = a key of ``folds``), the slice's
    fold within ``tolerance`` of the crossing says whether stable cycles lie beside it. The
    locus counts between two yes verdicts and from a yes to the locus's end; between a yes and
    a no it counts up to the middle of their slices (the edge is not known closer than that:
    :func:`refined_folds` narrows it); a locus that meets no slice fold is kept whole."""
    verdicts = _fold_verdicts(curve, folds, tolerance)
    if not verdicts:
        return [curve]
    ends = [(0.0, 0.0, None), *verdicts, (float(len(curve) - 1), 0.0, None)]
    pieces: list[list[float]] = []
    for (a, value_a, yes_a), (b, value_b, yes_b) in zip(ends[:-1], ends[1:], strict=True):
        if b <= a or not (yes_a or yes_b):
            continue
        if False in (yes_a, yes_b):
            edge = _crossing_within(curve, a, b, 0.5 * (value_a + value_b))
            a, b = (edge, b) if yes_a is False else (a, edge)
        if pieces and pieces[-1][1] == a:
            pieces[-1][1] = b
        else:
            pieces.append([a, b])
    return [_between(curve, lo, hi) for lo, hi in pieces]


def disagreeing(curve: np.ndarray, folds: dict[float, list[tuple[float, bool]]],
                tolerance: float) -> list[Interval]:
    """Pairs of slice values (second parameter) between which the verdicts of ``folds`` on the
    fold-of-cycles locus ``curve`` change, in order along the locus."""
    verdicts = _fold_verdicts(curve, folds, tolerance)
    return [(a, b) for (_, a, yes_a), (_, b, yes_b) in zip(verdicts[:-1], verdicts[1:],
                                                              strict=True) if yes_a != yes_b]


def refined_folds(folds: dict[float, list[tuple[float, bool]]], curves: list[np.ndarray],
                  tolerance: float, step: float,
                  judge: Callable[[list[float]], dict[float, list[tuple[float, bool]]]]
                  ) -> dict[float, list[tuple[float, bool]]]:
    """``folds`` (slice value -> its folds with verdicts) with more slices, bisecting every pair
    of slices between which a locus of ``curves`` changes verdict until the two lie within
    ``step``; ``judge(values)`` gives the folds of new slices at ``values`` (by value)."""
    folds = dict(folds)
    while True:
        values = sorted({0.5 * (a + b) for curve in curves
                         for a, b in disagreeing(curve, folds, tolerance)
                         if abs(b - a) > step} - set(folds))
        if not values:
            return folds
        folds.update(judge(values))


def bounding_ends(curve: np.ndarray, folds: dict[float, list[tuple[float, bool]]],
                  tolerance: float) -> tuple[bool, bool]:
    """Whether the first and the last point of the fold-of-cycles locus ``curve`` lie on
    stretches that bound stable cycles (see :func:`stable_fold_stretches`)."""
    verdicts = _fold_verdicts(curve, folds, tolerance)
    return (verdicts[0][2], verdicts[-1][2]) if verdicts else (True, True)


def _fold_verdicts(curve: np.ndarray, folds: dict[float, list[tuple[float, bool]]],
                   tolerance: float) -> list[tuple[float, float, bool]]:
    """(position along ``curve`` in point indices, slice value, verdict) at each crossing of a
    slice of ``folds`` where the slice has a fold within ``tolerance``, in order along the
    curve."""
    return sorted((k + w, value, stable) for value, found in folds.items()
                  for k, w, x in _segment_crossings(curve, value)
                  for stable in _matched(found, x, tolerance))


def _crossing_within(curve: np.ndarray, a: float, b: float, value: float) -> float:
    """The first position between ``a`` and ``b`` where ``curve`` crosses second = ``value``
    (their middle if none)."""
    inside = [k + w for k, w, _ in _segment_crossings(curve, value) if a <= k + w <= b]
    return inside[0] if inside else 0.5 * (a + b)


def _between(curve: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """The polyline ``curve`` from position ``lo`` to ``hi`` (fractional point indices)."""
    def at(position: float) -> np.ndarray:
        k = min(int(position), len(curve) - 2)
        return curve[k] + (position - k) * (curve[k + 1] - curve[k])

    inner = curve[int(np.floor(lo)) + 1:int(np.ceil(hi))]
    return np.vstack([at(lo), inner, at(hi)])


def _segment_crossings(curve: np.ndarray, value: float) -> list[tuple[int, float, float]]:
    """(segment k, fraction w along it, first coordinate) where the polyline ``curve`` crosses
    second = ``value``."""
    y = curve[:, 1] - value
    found = []
    for k in np.flatnonzero(y[:-1] * y[1:] <= 0):
        if y[k] == y[k + 1]:
            continue
        w = float(y[k] / (y[k] - y[k + 1]))
        found.append((int(k), w, float(curve[k, 0] + w * (curve[k + 1, 0] - curve[k, 0]))))
    return found


def _matched(found: list[tuple[float, bool]], x: float, tolerance: float) -> list[bool]:
    """The verdict of the fold in ``found`` nearest ``x`` if within ``tolerance`` (else none)."""
    near = [(abs(at - x), stable) for at, stable in found if abs(at - x) <= tolerance]
    return [min(near)[1]] if near else []


def loci_candidates(loci: dict[str, list[np.ndarray]], value: float
                    ) -> dict[str, list[Interval]]:
    """Where the slice second = ``value`` may be unsafe, from the locus curves (keys: hopf,
    fold_of_cycles, branch_point, fold), by cause: every fold-of-cycles crossing with the
    nearest Hopf crossing (flutter), every fold crossing with the nearest pitchfork crossing
    (divergence), before intersecting with the linearly stable part."""
    def at(kind: LocusKind) -> list[float]:
        return [x for curve in loci.get(kind, []) for x in crossings(curve, value)]

    return {UnsafeCause.FLUTTER: _paired(at(LocusKind.FOLD_OF_CYCLES), at(LocusKind.HOPF)),
            UnsafeCause.DIVERGENCE: _paired(at(LocusKind.FOLD), at(LocusKind.BRANCH_POINT))}


def unsafe_from_loci(loci: dict[str, list[np.ndarray]], stable: list[Interval], value: float,
                     minimum: float = 0.0) -> list[UnsafeInterval]:
    """Unsafe intervals of the slice second = ``value`` from the locus curves
    (:func:`loci_candidates` inside the ``stable`` intervals)."""
    return _unsafe(loci_candidates(loci, value), stable, value, minimum)


def branch_candidates(branches: tuple[Branch, ...]) -> dict[str, list[Interval]]:
    """Where one slice may be unsafe, from its one-parameter branches, by cause: the extent of
    every periodic family with a stable part (flutter) and of every secondary equilibrium
    branch with a fold (divergence)."""
    found: dict[UnsafeCause, list[Interval]] = {cause: [] for cause in UnsafeCause}
    for branch in branches:
        if not len(branch):
            continue
        extent = (float(branch.parameters[:, 0].min()), float(branch.parameters[:, 0].max()))
        if branch.kind == BranchKind.PERIODIC and (branch.stable
                                                   & branch.stability_known)[1:-1].any():
            found[UnsafeCause.FLUTTER].append(extent)
        elif (branch.kind == BranchKind.EQUILIBRIUM and branch.origin.point == PointType.BP
              and np.any(branch.point_type == 2)):
            found[UnsafeCause.DIVERGENCE].append(extent)
    return found


def unsafe_from_branches(branches: tuple[Branch, ...], stable: list[Interval], value: float,
                         minimum: float = 0.0) -> list[UnsafeInterval]:
    """Unsafe intervals of one slice from its one-parameter branches
    (:func:`branch_candidates` inside the ``stable`` intervals)."""
    return _unsafe(branch_candidates(branches), stable, value, minimum)


def _unsafe(candidates: dict[str, list[Interval]], stable: list[Interval], value: float,
            minimum: float) -> list[UnsafeInterval]:
    """The ``candidates`` (cause -> intervals) inside the ``stable`` intervals, pieces longer
    than ``minimum``, flutter first."""
    return [UnsafeInterval(value, lo, hi, cause) for cause in UnsafeCause
            for lo, hi in intersect(candidates[cause], stable, minimum)]


def polygons(intervals: list[UnsafeInterval], values: list[float],
             tolerance: float = 0.0) -> list[np.ndarray]:
    """Closed polygons (K, 2) in (first, second) covering the unsafe intervals of the rows
    ``values`` (every row examined, also those without intervals): intervals of neighbouring
    rows that overlap are joined into one polygon; an interval with no partner on a
    neighbouring row becomes a flat outline."""
    values = sorted(values)
    rows = {v: merge([(i.lower, i.upper) for i in intervals if i.slice_value == v])
            for v in values}
    chains: list[list[tuple[float, Interval]]] = []
    open_chains: list[list[tuple[float, Interval]]] = []
    for value in values:
        following = []
        for interval in rows[value]:
            chain = next((c for c in open_chains if c[-1][1][0] <= interval[1] + tolerance
                          and interval[0] <= c[-1][1][1] + tolerance and c not in following),
                         None)
            if chain is None:
                chain = []
                chains.append(chain)
            chain.append((value, interval))
            following.append(chain)
        open_chains = following
    shapes = []
    for chain in chains:
        left = [(lo, v) for v, (lo, _) in chain]
        right = [(hi, v) for v, (_, hi) in reversed(chain)]
        if len(chain) == 1:
            (v, (lo, hi)), = chain
            shape = [(lo, v), (hi, v), (hi, v), (lo, v)]
        else:
            shape = left + right
        shape.append(shape[0])
        shapes.append(np.array(shape, dtype=float))
    return shapes


#: Locus branch kinds -> the names used in ``unsafe_from_loci``.
LOCUS_NAMES = {
    BranchKind.HOPF_LOCUS: LocusKind.HOPF,
    BranchKind.FOLD_OF_CYCLES_LOCUS: LocusKind.FOLD_OF_CYCLES,
    BranchKind.BRANCH_POINT_LOCUS: LocusKind.BRANCH_POINT,
    BranchKind.FOLD_LOCUS: LocusKind.FOLD,
    BranchKind.TORUS_LOCUS: LocusKind.TORUS,  # drawn, not used by the unsafe region
}


def loci_curves(curves: list[Branch], amplitudes: np.ndarray | float = 1.0
                ) -> dict[str, list[np.ndarray]]:
    """Locus curves by name. Hopf and fold-of-cycles loci count only where they concern the
    undeflected equilibrium and its flutter (orbits centred on y = 0 within 2 % of their size
    and 1e-6 ``amplitudes``, each state's typical amplitude): other stretches (the secondary
    equilibria, asymmetric cycles) are cut out."""
    found: dict[str, list[np.ndarray]] = {}
    for curve in curves:
        name = LOCUS_NAMES[curve.kind]
        keep = np.ones(len(curve), dtype=bool)
        # centred within 2 % of the orbit's size
        if name in (LocusKind.HOPF, LocusKind.FOLD_OF_CYCLES):
            centre = np.abs(0.5 * (curve.state_max + curve.state_min))
            size = 0.5 * (curve.state_max - curve.state_min)
            keep = np.all(centre <= 0.02 * size + 1e-6 * np.asarray(amplitudes), axis=1)
        cuts = np.flatnonzero(np.diff(keep.astype(int))) + 1
        for part in np.split(np.arange(len(curve)), cuts):
            if keep[part[0]] and len(part) >= 2:
                found.setdefault(name, []).append(curve.parameters[part, :2])
    return found


def boundary(name: str, model: Model, overrides: dict[str, float], pair: tuple[str, str],
             bounds: dict[str, Interval], method: BoundaryMethod, slices: tuple[float, ...],
             resolution: int, curves: list[Branch], slice_branches: list[tuple[Branch, ...]],
             more_slices: Callable[[list[float]], list[tuple[Branch, ...]]] | None = None
             ) -> Boundary:
    """The unsafe region of a two-parameter continuation, by ``method`` ("loci": on
    ``resolution`` rows across the second parameter's range plus the slices; "slices": on the
    slices, from their one-parameter branches). ``more_slices(values)``: the branches of
    slices at ``values``, run where two slices disagree whether a fold-of-cycles locus bounds
    stable cycles, until the edge is known to a quarter of a row's spacing (without: to
    the middle of the two)."""
    first, second = pair
    minimum = 1e-3 * (bounds[first][1] - bounds[first][0])  # narrower pieces are round-off
    curves_by_name = loci_curves(curves, np.array(model.typical_amplitudes))
    hopfs = curves_by_name.get(LocusKind.HOPF, [])

    def judged(values: list[float], branches: list[tuple[Branch, ...]]
               ) -> dict[float, list[tuple[float, bool]]]:
        stable = stable_intervals(model, overrides, first, second, values, bounds[first])
        return {value: slice_folds(found, [x for curve in hopfs for x in crossings(curve, value)],
                                   part)
                for value, found, part in zip(values, branches, stable, strict=True)}

    folds = judged(list(slices), slice_branches)
    if method == BoundaryMethod.LOCI:
        fold_curves = curves_by_name.get(LocusKind.FOLD_OF_CYCLES, [])
        if more_slices is not None:
            step = 0.25 * (bounds[second][1] - bounds[second][0]) / max(resolution - 1, 1)
            folds = refined_folds(folds, fold_curves, 10 * minimum, step,
                                  lambda values: judged(values, more_slices(values)))
        curves_by_name[LocusKind.FOLD_OF_CYCLES] = [
            stretch for curve in fold_curves
            for stretch in stable_fold_stretches(curve, folds, 10 * minimum)]
        rows = sorted(set(np.linspace(*bounds[second], resolution).tolist()) | set(slices))
        candidates = [loci_candidates(curves_by_name, value) for value in rows]
    else:
        rows = list(slices)
        candidates = [branch_candidates(tuple(
            b for b in branches if b.kind != BranchKind.PERIODIC
            or b.origin.branch in ("main_down", "main_up"))) for branches in slice_branches]
    # the stable part of each row, examined only where a candidate lies
    where = [merge([i for found in row.values() for i in found]) for row in candidates]
    stable = stable_intervals(model, overrides, first, second, rows, bounds[first], 4001,
                              within=where)
    intervals = [interval for value, row, part in zip(rows, candidates, stable, strict=True)
                 for interval in _unsafe(row, part, value, minimum)]
    loci = {c.name: (LOCUS_NAMES[c.kind], c.parameters[:, :2]) for c in curves}
    ends = {c.name: bounding_ends(c.parameters[:, :2], folds, 10 * minimum) for c in curves
            if c.kind == BranchKind.FOLD_OF_CYCLES_LOCUS and len(c)}
    return Boundary(name, pair, tuple(model.parameter(p).unit for p in pair), method, loci,
                    tuple(intervals), tuple(polygons(intervals, rows)), tuple(slices),
                    tuple(map(float, bounds[first])), tuple(map(float, bounds[second])), ends)
