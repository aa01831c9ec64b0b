"""Which stretches of a fold-of-cycles locus bound stable cycles, from the folds the slices'
periodic families find on it (whirl_cli.analysis.boundaries: slice_folds, refined_folds,
stable_fold_stretches)."""

from __future__ import annotations

import numpy as np

from whirl_cli.analysis.boundaries import (
    bounding_ends,
    crossings,
    refined_folds,
    slice_folds,
    stable_fold_stretches,
)
from whirl_cli.results import BranchKind, PointType

from .plot_data import make_branch

#: a locus from (0.45, 0.3) down to (0.95, 0.1): K1 = 0.45 + 2.5 (0.3 - K_psi)
LOCUS = np.column_stack([np.linspace(0.45, 0.95, 41), np.linspace(0.3, 0.1, 41)])


def rows(stretches, values):
    return {v: [x for s in stretches for x in crossings(s, v)] for v in values}


def test_between_disagreeing_slices_a_locus_counts_to_the_middle():
    folds = {0.3: [(0.45, True)], 0.2: [(0.70, False)]}
    found = rows(stable_fold_stretches(LOCUS, folds, 1e-3), (0.3, 0.27, 0.23, 0.2, 0.15))
    assert np.allclose(found[0.3], [0.45]) and np.allclose(found[0.27], [0.525])
    assert found[0.23] == [] and found[0.2] == [] and found[0.15] == []
    assert bounding_ends(LOCUS, folds, 1e-3) == (True, False)


def test_more_slices_place_the_edge_where_stable_cycles_cease():
    """Slices added by bisection (a judge whose folds on the locus say yes above K_psi = 0.283)
    until the edge is within the step; the rows then change verdict at 0.283."""
    asked = []

    def judge(values):
        asked.extend(values)
        return {v: [(0.45 + 2.5 * (0.3 - v), v > 0.283)] for v in values}

    folds = refined_folds({0.3: [(0.45, True)], 0.2: [(0.70, False)]}, [LOCUS], 1e-3,
                          0.00125, judge)
    assert asked[:3] == [0.25, 0.275, 0.2875] and len(asked) == 7
    yes = max(v for v, f in folds.items() if not f[0][1])
    no = min(v for v, f in folds.items() if f[0][1])
    assert yes < 0.283 < no and no - yes <= 0.00125
    found = rows(stable_fold_stretches(LOCUS, folds, 1e-3), (0.285, 0.284, 0.282, 0.25))
    assert found[0.285] and found[0.284] and not found[0.282] and not found[0.25]


def test_refining_stops_where_a_new_slice_has_no_fold_on_the_locus():
    folds = refined_folds({0.3: [(0.45, True)], 0.2: [(0.70, False)]}, [LOCUS], 1e-3, 1e-4,
                          lambda values: {v: [] for v in values})
    assert sorted(folds) == [0.2, 0.25, 0.3]


def family(k1, stable, folds):
    """A periodic family on K1 with LPC points at the rows ``folds``."""
    point_type = np.zeros(len(k1), int)
    point_type[list(folds)] = PointType.LPC
    return make_branch("periodic_1", BranchKind.PERIODIC, k1, np.full(len(k1), 0.1), stable,
                       point_type=point_type)


def test_a_fold_bounds_stable_cycles_found_anywhere_between_it_and_its_hopf():
    """Hopf at 0.30, fold at 0.50: the cycles beside the fold are unstable (a torus point lies
    between), those at 0.36-0.41 stable where the origin is stable: the fold counts. With the
    same cycles only where the origin is unstable, or none stable, it does not."""
    k1 = np.array([0.30, 0.40, 0.50, 0.45, 0.41, 0.38, 0.36, 0.30, 0.20])
    stable = [0, 0, 0, 0, 1, 1, 1, 0, 1]
    branches = (family(k1, stable, [2]),)
    assert slice_folds(branches, [0.30, 0.08], [(0.08, 0.30)]) == [(0.5, False)]
    assert slice_folds(branches, [0.30, 0.08], [(0.30, 1.0)]) == [(0.5, True)]
    assert slice_folds((family(k1, [0] * 8 + [1], [2]),), [0.30], [(0.30, 1.0)]) \
        == [(0.5, False)]
    assert slice_folds(branches, [], [(0.30, 1.0)]) == [(0.5, False)]


def test_a_locus_whose_folds_join_unstable_cycles_counts_nowhere():
    folds = {0.3: [(0.45, False)], 0.2: [(0.70, False)]}
    assert stable_fold_stretches(LOCUS, folds, 1e-3) == []
    assert bounding_ends(LOCUS, folds, 1e-3) == (False, False)


def test_a_fold_too_far_from_the_crossing_gives_no_verdict():
    folds = {0.3: [(0.40, False)], 0.2: [(0.70, True)]}  # 0.40 is another fold, not this one
    found = rows(stable_fold_stretches(LOCUS, folds, 1e-3), (0.3, 0.2, 0.15))
    assert np.allclose(found[0.3], [0.45]) and np.allclose(found[0.2], [0.70])
    assert np.allclose(found[0.15], [0.825])
    assert stable_fold_stretches(LOCUS, {0.3: [(0.40, False)]}, 1e-3)[0] is LOCUS  # unknown


def test_a_fold_beside_a_run_of_stable_cycles_to_a_hopf_counts_anywhere():
    """The stable cycles beside the fold (-0.04) reach the Hopf point (-0.15) where the origin
    is unstable (a divergence lobe): the fold still counts; its locus may bound an unsafe
    region on other rows."""
    k1 = np.array([-0.15, -0.10, -0.04, -0.041, -0.10, -0.148])
    branches = (family(k1, [0, 0, 0, 1, 1, 1], [2]),)
    assert slice_folds(branches, [-0.15], [(0.03, 0.32)]) == [(-0.04, True)]
