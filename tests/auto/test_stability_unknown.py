"""Unknown stability: at the first point of a periodic family started at a Hopf point AUTO
prints no Floquet multipliers, yet flags the point unstable. whirl stores that point's
stability as unknown (``Branch.stability_known``, dataset ``stability_known``), draws no
"unstable periodic" stub there, and nothing takes the flag for a verdict (cross-checks,
unsafe intervals, compare)."""

from __future__ import annotations

from dataclasses import replace

import h5py
import numpy as np
import pytest

from whirl_cli.analysis import simulate
from whirl_cli.analysis.boundaries import unsafe_from_branches
from whirl_cli.output import store
from whirl_cli.output.compare import compare_results
from whirl_cli.plots.diagrams import bifurcation_diagram, period_plot
from whirl_cli.plots.key import PLOT_KEY, stability_segments
from whirl_cli.results import BranchKind, PointType

from ..conftest import ROOT

REFERENCE = ROOT / "tests" / "data" / "legacy_hardening_case2.h5"  # written before stability_known


@pytest.fixture(scope="module")
def continuation(run_thesis):
    return run_thesis("hardening_case2").continuations[0]


def periodic(continuation):
    return [b for b in continuation.branches if b.kind == BranchKind.PERIODIC]


def test_the_first_point_of_a_family_from_a_hopf_point_has_unknown_stability(continuation):
    families = periodic(continuation)
    assert [b.name for b in families] == ["periodic_1", "periodic_3", "periodic_5"]
    for branch in families:
        assert branch.origin.point == PointType.HB
        nan = np.isnan(branch.eigenvalues).all(axis=1)
        assert list(np.flatnonzero(nan)) == [0], branch.name  # AUTO printed no multipliers
        assert not branch.stable[0] and branch.stable[1:4].all()  # AUTO's flag: "unstable"
        assert list(np.flatnonzero(~branch.stability_known)) == [0], branch.name
    for branch in continuation.branches:
        if branch.kind == BranchKind.EQUILIBRIUM:
            assert branch.stability_known.all() and len(branch.stability_known) == len(branch)


def test_unknown_stability_survives_the_hdf5_round_trip(run_thesis, tmp_path):
    result = run_thesis("hardening_case2")
    path = store.write(result, tmp_path / "r.h5")
    with h5py.File(path, "r") as handle:
        data = handle["continuations/k1/branches/periodic_1/stability_known"]
        assert data.dtype == bool and not data[0] and data[1:].all()
    read = store.read(path).continuations[0]
    for ours, theirs in zip(result.continuations[0].branches, read.branches, strict=True):
        assert ours.name == theirs.name
        np.testing.assert_array_equal(ours.stability_known, theirs.stability_known)
        np.testing.assert_array_equal(ours.stable, theirs.stable)
    # files from before have no such dataset: stability known everywhere
    for branch in store.read(REFERENCE).continuations[0].branches:
        assert branch.stability_known.dtype == bool and branch.stability_known.all()


def _vertices(line) -> np.ndarray:
    return np.column_stack([np.asarray(line.get_xdata(), float),
                            np.asarray(line.get_ydata(), float)])


def _has_vertex(line, xy) -> bool:
    return bool(np.isclose(_vertices(line), xy, rtol=1e-12, atol=1e-12).all(axis=1).any())


@pytest.mark.parametrize("kind", ["bifurcation", "period"])
def test_no_unstable_stub_is_drawn_at_the_hopf_point(continuation, kind):
    if kind == "bifurcation":
        figure = bifurcation_diagram(continuation)
        y = {b.name: np.degrees(b.state("theta", "max")) for b in periodic(continuation)}
    else:
        figure = period_plot(continuation)
        y = {b.name: b.period for b in periodic(continuation)}
    (ax,) = figure.axes
    styles = {key: (PLOT_KEY[key]["color"], PLOT_KEY[key]["linestyle"])
              for key in ("stable_periodic", "unstable_periodic")}
    lines = {key: [line for line in ax.lines
                   if (line.get_color(), line.get_linestyle()) == style]
             for key, style in styles.items()}
    assert lines["stable_periodic"] and lines["unstable_periodic"]
    for branch in periodic(continuation):
        start = (branch.parameters[0, 0], y[branch.name][0])
        following = (branch.parameters[1, 0], y[branch.name][1])
        assert not [line for line in lines["unstable_periodic"] if _has_vertex(line, start)], \
            f"an unstable stub at the first point of {branch.name}"
        # the first point starts the stable line of the points after it
        assert [line for line in lines["stable_periodic"]
                if _has_vertex(line, start) and _has_vertex(line, following)], branch.name


def test_stability_segments_let_unknown_points_join_their_neighbours():
    x = np.arange(7.0)
    stable = np.array([0, 1, 1, 0, 0, 0, 1], bool)
    known = np.array([0, 1, 1, 1, 0, 1, 1], bool)
    segments = stability_segments(x, x, stable, known)
    assert [(list(xs), s) for xs, _, s in segments] == [
        ([0, 1, 2, 3], True), ([3, 4, 5, 6], False), ([6], True)]
    assert [s for *_, s in stability_segments(x, x, stable)] == [False, True, False, True]
    nothing = stability_segments(x, x, stable, np.zeros(7, bool))
    assert [s for *_, s in nothing] == [False, True, False, True]  # AUTO's flags as they are


def test_unknown_points_are_not_checked_nor_taken_as_stable(continuation):
    family = next(b for b in periodic(continuation) if b.name == "periodic_1")
    planned = simulate.planned_checks((family,))
    rows = [family.orbits[item].index for _, _, item in planned]
    assert rows
    known = family.stability_known.copy()
    known[rows] = False
    hidden = replace(family, stability_known=known)
    assert [family.orbits[item].index for _, _, item in simulate.planned_checks((hidden,))] \
        != rows
    assert not set(rows) & {hidden.orbits[item].index
                            for _, _, item in simulate.planned_checks((hidden,))}
    # a family "stable" only where its stability is unknown has no unsafe interval
    flagged = replace(family, stable=np.ones(len(family), bool),
                      stability_known=np.zeros(len(family), bool))
    span = [(-1.0, 1.0)]
    assert unsafe_from_branches((replace(family, stable=np.ones(len(family), bool)),), span,
                                0.3)
    assert unsafe_from_branches((flagged,), span, 0.3) == []


def test_compare_skips_points_of_unknown_stability(run_thesis):
    result = run_thesis("hardening_case2")

    def changed(**columns):
        branches = tuple(replace(b, **columns) if b.name == "periodic_1" else b
                         for b in result.continuations[0].branches)
        return replace(result, continuations=(replace(result.continuations[0],
                                                      branches=branches),))

    family = next(b for b in result.continuations[0].branches if b.name == "periodic_1")
    flipped = family.stable.copy()
    flipped[:30] = ~flipped[:30]
    unknown = family.stability_known.copy()
    unknown[:30] = False
    assert compare_results(result, changed(stable=flipped, stability_known=unknown)) == []
    (difference,) = compare_results(result, changed(stable=flipped))
    assert difference.path == "/continuations/k1/branches/periodic_1/stable"
