"""Pure geometry helpers of the two-parameter recipe (no AUTO)."""

from __future__ import annotations

import dataclasses

import numpy as np

from whirl_cli.continuation.geometry import near_polyline

from .locus_data import make_locus


def test_point_between_vertices_is_on_the_polyline():
    curve = np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.2]])
    width = np.array([1.0, 1.0])
    assert near_polyline(np.array([0.05, 0.0005]), curve, width)  # mid-segment, 5e-4 off
    assert near_polyline(np.array([0.1003, 0.1]), curve, width)
    assert not near_polyline(np.array([0.05, 0.002]), curve, width)
    assert not near_polyline(np.array([0.2, 0.2]), curve, width)


def test_distance_is_measured_in_axes_scaled_by_the_ranges():
    curve = np.array([[0.0, 0.0], [1.0, 0.0]])
    point = np.array([0.5, 0.05])
    assert not near_polyline(point, curve, np.array([1.0, 1.0]))
    assert near_polyline(point, curve, np.array([1.0, 100.0]))  # 0.05 of a 100-wide axis


def test_degenerate_curves():
    width = np.array([1.0, 1.0])
    assert not near_polyline(np.zeros(2), np.empty((0, 2)), width)
    assert near_polyline(np.zeros(2), np.zeros((1, 2)), width)


def _circle(turns: float, points_per_turn: int = 200, centre=(0.5, 0.5)) -> np.ndarray:
    angle = np.linspace(0, 2 * np.pi * turns, int(points_per_turn * turns) + 1)
    return np.column_stack([centre[0] + 0.2 * np.cos(angle), centre[1] + 0.2 * np.sin(angle)])


def test_a_locus_is_cut_where_it_returns_to_its_start():
    from whirl_cli.continuation.geometry import cut_closed

    width = np.ones(2)
    cut = cut_closed(make_locus(_circle(2.5)), width)
    assert 200 <= len(cut) <= 202  # one turn and the point that closes it


def test_a_locus_that_runs_onto_a_closed_loop_is_cut_after_one_turn_of_it():
    """AUTO can switch onto a closed locus and go round it to its step limit, never back at
    the start: the curve is cut where it retraces its own path the same way."""
    from whirl_cli.continuation.geometry import cut_closed

    lead = np.column_stack([np.linspace(0.9, 0.7, 41), np.full(41, 0.5)])[:-1]
    curve = np.vstack([lead, _circle(3.0, centre=(0.5, 0.5))])
    cut = cut_closed(make_locus(curve), np.ones(2))
    assert len(lead) + 200 <= len(cut) <= len(lead) + 210


def test_a_locus_round_a_loop_whose_sampled_extremes_jitter_is_cut_after_one_lap():
    """The extremes are maxima over AUTO's mesh: round a closed locus they differ by a few per
    cent from lap to lap (the gimballed hub's rates), so the extremes never match; the period
    does. Cut where the second lap begins, once it has retraced the whole first one. A loop
    whose period changes from lap to lap (another orbit each time) goes on."""
    from dataclasses import replace

    from whirl_cli.continuation.geometry import cut_closed

    lead = np.column_stack([np.linspace(0.9, 0.7, 41), np.full(41, 0.5)])[:-1]
    curve = np.vstack([lead, _circle(4.0, centre=(0.5, 0.5))])
    jitter = 0.1 * (1 + 0.03 * np.sin(np.arange(len(curve)) * 2.7))  # 3 %, no lap alike
    locus = make_locus(curve, jitter)
    cut = cut_closed(replace(locus, period=np.full(len(curve), 0.5)), np.ones(2))
    assert len(lead) + 200 <= len(cut) <= len(lead) + 210
    growing = np.linspace(0.5, 0.9, len(curve))  # 0.1 of its spread per lap
    assert len(cut_closed(replace(locus, period=growing), np.ones(2))) == len(curve)


def test_a_hairpin_or_a_crossing_of_the_projection_is_not_cut():
    """At a cusp a locus comes back along itself the other way; elsewhere its projection on
    the parameters may pass over an earlier stretch where the orbit differs: neither is a
    retrace (the end of such a locus would be lost)."""
    from whirl_cli.continuation.geometry import cut_closed

    width = np.ones(2)
    out = np.column_stack([np.linspace(0.1, 0.6, 101), np.full(101, 0.3)])
    hairpin = np.vstack([out, out[::-1][1:] + [0.0, 0.002], [[0.1, 0.5]]])
    assert len(cut_closed(make_locus(np.vstack([[0.05, 0.3], hairpin])), width)) == len(hairpin) + 1
    # down, back up, down again over the same parameters with a larger orbit
    path = np.vstack([[0.05, 0.25], out, out[::-1][1:], out[1:]])
    extremes = np.concatenate([np.full(102, 0.1), np.linspace(0.1, 0.3, 100),
                               np.full(100, 0.3)])
    assert len(cut_closed(make_locus(path, extremes), width)) == len(path)


def test_mirror_image_starts_are_traced_once():
    """Two starts of one type at the same parameters with the same period (a symmetric pair
    of cycles) trace one curve in the parameter plane; a different period is another locus."""
    from whirl_cli.continuation.loci import _without_twins
    from whirl_cli.results import PointType, SpecialPoint

    def start(k1: float, period: float, sign: float) -> SpecialPoint:
        return SpecialPoint("slice_0.periodic_1", 3, int(PointType.LPC), ("K1", "K_psi"),
                            np.array([k1, 0.2]), np.array([sign * 0.1, 0.0]), period, False)

    starts = [(1, start(-0.0815, 0.82048, 1.0), "r1"),
              (2, start(-0.0815, 0.8204811, -1.0), "r2"),
              (3, start(-0.0815, 0.9137, 1.0), "r1"),
              (4, start(-0.0815 + 1e-4, 0.82048, 1.0), "r1")]
    kept = _without_twins(starts, np.array([0.8, 0.5]))
    assert [k for k, _, _ in kept] == [1, 3, 4]


def test_of_a_snaking_familys_folds_only_the_outermost_start_loci():
    """Three or more folds of cycles of one family at one point of a slice (to 1e-3 of the
    ranges; periods growing along a family snaking toward a homoclinic orbit): only the lowest-
    and highest-period ones start loci. Two folds, another family's, a fold elsewhere on the
    slice and other point types are kept."""
    from whirl_cli.continuation.loci import _outermost_folds
    from whirl_cli.results import PointType, SpecialPoint

    def start(kind: PointType, branch: str, k1: float, period: float) -> SpecialPoint:
        return SpecialPoint(branch, 3, int(kind), ("K1", "K_psi"), np.array([k1, 0.2]),
                            np.array([0.1, 0.0]), period, False)

    snake, other = "slice_2.periodic_1", "slice_2.periodic_2"
    starts = [(1, start(PointType.LPC, snake, -0.0813, 0.75), "r1"),
              (2, start(PointType.LPC, snake, -0.0807, 1.64), "r1"),   # 6e-4 away (width 0.8)
              (3, start(PointType.LPC, snake, -0.0817, 1.08), "r1"),
              (4, start(PointType.LPC, snake, -0.0815, 0.87), "r1"),
              (5, start(PointType.LPC, snake, -0.0408, 0.33), "r1"),   # elsewhere on it
              (6, start(PointType.LPC, other, -0.0815, 0.38), "r2"),   # two of another family
              (7, start(PointType.LPC, other, -0.0816, 0.44), "r2"),
              (8, start(PointType.HB, snake, -0.0814, 0.26), "r1"),
              (9, start(PointType.HB, snake, -0.0814, 0.27), "r1"),
              (10, start(PointType.HB, snake, -0.0814, 0.28), "r1")]
    kept = _outermost_folds(starts, np.array([0.8, 0.5]))
    assert [k for k, _, _ in kept] == [1, 2, 5, 6, 7, 8, 9, 10]


def test_a_locus_that_passed_the_range_edge_ends_there_and_is_not_continued():
    """AUTO locates no UZSTOP in the first step after a restart: a locus continued chunk by
    chunk from just inside the edge can end beyond it. That is the range's end, like one on
    the edge; one inside is continued."""
    from whirl_cli.continuation.geometry import at_range_edge, chunk_used
    from whirl_cli.results import PointType

    bounds = {"p": (0.0, 1.0), "q": (0.0, 0.5)}
    width = np.array([1.0, 0.5])
    for last, edge in (((0.5, 0.3), False), ((1.0, 0.3), True), ((0.5, 0.5), True),
                       ((1.003, 0.3), True), ((0.5, 0.52), True), ((0.5, -0.01), True)):
        points = np.array([[0.2, 0.1], [0.3, 0.2], last])
        curve = make_locus(points)
        curve.point_type[-1] = PointType.EP
        assert at_range_edge(curve, bounds, width) == edge, last
        assert chunk_used(curve, width, bounds) == (not edge), last


def test_a_locus_chunk_that_adds_no_point_ends_the_locus(monkeypatch):
    """Continuing a locus chunk by chunk stops when a chunk adds no point (AUTO stopped at
    once): continuing it again would repeat the same run for ever. (The runs are stubs: this
    is the loop's control, not a continuation result.)"""
    from whirl_cli.continuation import loci
    from whirl_cli.continuation.engine import Numerics, RunSpec
    from whirl_cli.results import Origin, PointType

    curve = make_locus(np.array([[0.2, 0.1], [0.3, 0.2], [0.4, 0.3]]))
    curve.point_type[-1] = PointType.EP
    curve.label[-1] = 7
    curve = dataclasses.replace(curve, runs=("c.fold_of_cycles_1a2",))
    spec = RunSpec("c/fold_of_cycles_1a2", {"NMX": loci.LOCUS_CHUNK}, curve.kind, Origin(""),
                   ("p", "q"))
    calls = []

    class Engine:
        def run_many(self, specs):
            calls.append([s.name for s in specs])
            assert len(calls) < 3, "the same chunk run again"
            return [None] * len(specs)

    monkeypatch.setattr(loci, "read_run", lambda _engine, _spec, _outcome: make_locus(
        np.array([[0.4, 0.3]])))
    kept, _ = loci._grown(Engine(), {0: (PointType.LPC, spec, curve)}, [], Numerics(),
                          {"p": (0.0, 1.0), "q": (0.0, 0.5)}, np.array([1.0, 0.5]))
    assert calls == [["c/fold_of_cycles_1a2c1"]] and len(kept[0][2]) == 3


def test_a_locus_chunk_drawn_over_its_own_path_ends_the_locus(monkeypatch):
    """A chunk whose every point lies within 1e-3 of the ranges of the locus's earlier path in
    the parameter plane (AUTO wandering to and fro over it, its orbits changing) adds nothing
    to the picture: the locus is not continued. A chunk reaching new ground is continued.
    (Stub runs: the loop's control, not a continuation result.)"""
    from whirl_cli.continuation import loci
    from whirl_cli.continuation.engine import Numerics, RunSpec
    from whirl_cli.results import Origin, PointType

    def ending(points):
        curve = make_locus(points)
        curve.point_type[-1] = PointType.EP
        curve.label[-1] = 7
        return curve

    path = np.column_stack([np.linspace(0.2, 0.6, 41), np.full(41, 0.2)])
    curve = dataclasses.replace(ending(path), runs=("c.fold_of_cycles_1a2",))
    spec = RunSpec("c/fold_of_cycles_1a2", {"NMX": loci.LOCUS_CHUNK}, curve.kind, Origin(""),
                   ("p", "q"))
    for chunk, continued in ((path[::-1][:30], False),  # back over its path
                             (np.vstack([path[-1], path[-1] + [[0.01, 0.01]]]), True)):
        calls = []

        class Engine:
            def run_many(self, specs, calls=calls):
                calls.append([s.name for s in specs])
                return [None] * len(specs)

        monkeypatch.setattr(loci, "read_run", lambda _engine, s, _outcome, chunk=chunk: (
            ending(chunk) if s.name.endswith("c1") else ending(chunk[-1:])))
        loci._grown(Engine(), {0: (PointType.LPC, spec, curve)}, [], Numerics(),
                    {"p": (0.0, 1.0), "q": (0.0, 0.5)}, np.array([1.0, 0.5]))
        assert (len(calls) > 1) == continued, calls


def test_a_locus_wholly_on_others_is_dropped_later_one_first():
    """A locus lying, point by point, within 1e-3 of the ranges of the other kept loci of its
    type (here: two halves of its path traced from two other starts) is dropped; of two equal
    ones the later goes; a locus of another type or elsewhere stays."""
    from whirl_cli.continuation.loci import _distinct

    width = np.ones(2)
    path = np.column_stack([np.linspace(0.1, 0.9, 161), 0.3 + 0.1 * np.sin(np.linspace(0, 3, 161))])
    whole = make_locus(path)
    left, right = make_locus(path[:90]), make_locus(path[80:])
    offset = make_locus(path + [0.0, 0.004])  # drawn beside the others: kept
    curves = {1: (13, None, left), 2: (13, None, right), 3: (13, None, whole),
              4: (13, None, offset), 5: (2, None, whole)}
    kept, _ = _distinct(curves, [], width)
    assert sorted(kept) == [1, 2, 4, 5]
    kept, _ = _distinct({1: (13, None, whole), 2: (13, None, whole)}, [], width)
    assert sorted(kept) == [1]
    kept, _ = _distinct({1: (13, None, left)}, [(13, whole)], width)  # on a known locus
    assert kept == {}


def test_a_locus_that_runs_onto_another_stops_where_both_are_kept():
    """A locus whose last points lie on another locus of its type (parameters and orbits) has
    run onto it and is not continued; both stay (each holds a part the other lacks). Near its
    start a locus lies on its twin traced the other way: that is no merge; nor is running
    onto the parameters of a locus whose orbits differ."""
    from whirl_cli.continuation.loci import _distinct

    width = np.ones(2)
    path = np.column_stack([np.linspace(0.1, 0.9, 161), np.full(161, 0.3)])
    first = make_locus(path[:100])        # 0.1 .. 0.595
    second = make_locus(path[150:60:-1])  # 0.85 back to 0.4: ends on the first
    kept, merged = _distinct({1: (13, None, first), 2: (13, None, second)}, [], width)
    assert sorted(kept) == [1, 2] and merged == {1, 2}  # head-on: both stop, nothing lost
    ahead = make_locus(path[40:120])      # 0.3 .. 0.695
    behind = make_locus(path[:60])        # 0.1 .. 0.395: its end lies on the one ahead
    kept, merged = _distinct({1: (13, None, ahead), 2: (13, None, behind)}, [], width)
    assert merged == {2}
    twins = {1: (13, None, make_locus(path[80:84])), 2: (13, None, make_locus(path[80:76:-1]))}
    assert _distinct(twins, [], width)[1] == set()
    other = make_locus(path[150:60:-1], extremes=np.full(90, 0.5))  # other orbits, same parameters
    kept, merged = _distinct({1: (13, None, first), 2: (13, None, other)}, [], width)
    assert merged == set()


def test_points_on_paths_are_measured_to_segments():
    from whirl_cli.continuation.geometry import on_paths

    path = np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.2]])
    points = np.array([[0.05, 0.0009], [0.05, 0.0011], [0.1009, 0.1], [0.3, 0.3]])
    assert on_paths(points, [path]).tolist() == [True, False, True, False]
    assert on_paths(points, [np.array([[0.3, 0.3]])]).tolist() == [False, False, False, True]
    assert not on_paths(points, []).any()


def _segment_distance(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """Euclidean distance of ``point`` to the segment a-b, by the closed form."""
    step = b - a
    length = float(step @ step)
    t = 0.0 if length == 0 else min(max(float((point - a) @ step) / length, 0.0), 1.0)
    return float(np.linalg.norm(point - (a + t * step)))


def test_points_on_paths_agree_with_the_distance_to_every_segment():
    """Random walks and points in 2 and 6 coordinates, many of them near the walks: a point
    is on the paths exactly when its distance to some segment (the closed form, segment by
    segment) is below the tolerance; also with a one-point path and an empty one."""
    from whirl_cli.continuation.geometry import on_paths

    rng = np.random.default_rng(7)
    found = []
    for dims in (2, 6):
        paths = [np.cumsum(rng.normal(0.0, 0.002, (m, dims)), axis=0) + rng.uniform(0, 0.05, dims)
                 for m in (40, 25, 1)] + [np.empty((0, dims))]
        ends = np.vstack([path[rng.integers(len(path), size=30)] for path in paths[:3]])
        points = np.vstack([ends + rng.normal(0.0, 0.0008, ends.shape),
                            rng.uniform(0.0, 0.06, (40, dims))])
        expected = [any(_segment_distance(p, a, b) < 1e-3 for path in paths if len(path) > 1
                        for a, b in zip(path[:-1], path[1:], strict=True))
                    or any(len(path) == 1 and np.linalg.norm(p - path[0]) < 1e-3
                           for path in paths) for p in points]
        assert on_paths(points, paths).tolist() == expected
        found += expected
    assert 0 < sum(found) < len(found)


def test_a_locus_back_at_its_start_with_another_orbit_reached_the_next_fold():
    """Back within 0.005 of the ranges of its start's parameters, a locus has closed, unless
    its period there is nearer that of another start point of its type there (the folds of
    cycles of a family snaking toward a homoclinic orbit: one locus leads to the next)."""
    from whirl_cli.continuation.loci import _locus_end
    from whirl_cli.results import PointType, SpecialPoint

    width = np.array([0.8, 0.5])
    bounds = {"p": (-0.3, 0.5), "q": (0.0, 0.5)}
    loop = np.vstack([_circle(1.0, centre=(0.1, 0.25))[:-1], [[0.3, 0.2501]]])
    curve = dataclasses.replace(make_locus(loop), period=np.linspace(0.525, 0.6136, len(loop)))

    def fold(k1: float, period: float) -> SpecialPoint:
        return SpecialPoint("slice_2.periodic_2", 3, int(PointType.LPC), ("p", "q"),
                            np.array([k1, 0.25]), np.array([0.1, 0.0]), period, False)

    own, next_fold = fold(0.3, 0.5248), fold(0.3001, 0.6136)
    ended = _locus_end(curve, [], bounds, width, (own, next_fold))
    assert ended.end == "at the LPC of slice_2.periodic_2 at p = 0.3001 (period 0.6136 s)"
    alone = _locus_end(curve, [], bounds, width, (own,)).end
    assert alone.startswith("back at its start's parameters with another orbit (period 0.6136")
    # round the loop and back to about its start's period (a step's change away): closed
    round_trip = 0.525 + 0.05 * np.sin(np.linspace(0, 2 * np.pi, len(loop) + 1)[:-1])
    near_own = dataclasses.replace(curve, period=round_trip)
    assert _locus_end(near_own, [], bounds, width, (own, next_fold)).end == "closed"


def test_a_locus_stopped_a_few_steps_from_its_start_has_not_closed():
    """Four points within 1e-4 of the ranges of its start, then MX: a failure, not a loop."""
    from whirl_cli.continuation.loci import _locus_end
    from whirl_cli.results import PointType, RunStatus

    width = np.array([0.8, 0.5])
    bounds = {"p": (-0.3, 0.5), "q": (0.0, 0.5)}
    stalled = dataclasses.replace(
        make_locus(np.array([[0.27485, 0.2], [0.27484, 0.20001], [0.27482, 0.20003],
                             [0.27481, 0.20004]])),
        status=RunStatus.MX, point_type=np.array([0, 0, 0, int(PointType.MX)]))
    assert _locus_end(stalled, [], bounds, width).end == "no convergence (MX)"
