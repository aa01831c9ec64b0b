"""Which stretches of a fold-of-cycles locus bound stable cycles, from the folds the slices'
periodic families find on it (whirl_cli.analysis.boundaries.stable_fold_stretches)."""

from __future__ import annotations

import numpy as np

from whirl_cli.analysis.boundaries import bounding_ends, crossings, stable_fold_stretches

#: a locus from (0.45, 0.3) down to (0.95, 0.1): K1 = 0.45 + 2.5 (0.3 - K_psi)
LOCUS = np.column_stack([np.linspace(0.45, 0.95, 41), np.linspace(0.3, 0.1, 41)])


def rows(stretches, values):
    return {v: [x for s in stretches for x in crossings(s, v)] for v in values}


def test_a_locus_counts_between_slices_where_either_fold_bounds_stable_cycles():
    folds = {0.3: [(0.45, True)], 0.2: [(0.70, False)]}
    found = rows(stable_fold_stretches(LOCUS, folds, 1e-3), (0.3, 0.25, 0.2, 0.15))
    assert np.allclose(found[0.3], [0.45]) and np.allclose(found[0.25], [0.575])
    assert found[0.2] == [] and found[0.15] == []  # no at the slice, and past it
    assert bounding_ends(LOCUS, folds, 1e-3) == (True, False)


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
