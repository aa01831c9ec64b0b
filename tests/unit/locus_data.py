"""A synthetic two-parameter locus shared by the locus geometry and wave tests."""

from __future__ import annotations

import numpy as np

from whirl_cli.results import Branch, BranchKind, Origin


def make_locus(points: np.ndarray, extremes: np.ndarray | None = None):
    """A two-parameter locus through ``points`` (K, 2) with one state whose orbit extremes are
    ``extremes`` (K,) (default: 0.1 along the whole locus)."""
    n = len(points)
    top = (np.full(n, 0.1) if extremes is None else extremes)[:, None]
    return Branch("fold_of_cycles_1a", BranchKind.FOLD_OF_CYCLES_LOCUS, Origin(""), ("p", "q"),
                  ("1", "1"), ("x",), ("1",), points.astype(float), top, -top, np.zeros(n),
                  np.ones(n), np.ones(n, bool), np.zeros(n, int), np.zeros(n, int),
                  np.zeros((n, 1), complex))
