"""The cross-check does not simulate orbits right beside a fold of cycles: a smoothed law
moves its folds by about its smoothing width, so an orbit a hair past the smoothed fold may
not exist under the unsmoothed law (the gimballed pitch freeplay family's fold at 7.8909 m/s:
from its orbit at 7.8915 m/s the exact law leaves for a cycle 6 % smaller, while at 7.9515
m/s it keeps the stored one to 1e-4)."""

from __future__ import annotations

import numpy as np

from whirl_cli.analysis import simulate
from whirl_cli.results import Branch, BranchKind, Orbit, Origin, PointType

ROWS = 41


def _family() -> Branch:
    """A stable family over V in [7, 9] with a fold of cycles at row 20 (V = 8) and an orbit
    stored at every row."""
    v = np.linspace(7.0, 9.0, ROWS)
    types = np.zeros(ROWS, int)
    types[20] = PointType.LPC
    t = np.linspace(0.0, 0.2, 21)
    states = np.column_stack([np.cos(t * 10 * np.pi), np.sin(t * 10 * np.pi)])
    orbits = tuple(Orbit(label=k + 1, point_type=0, index=k, parameters=np.array([v[k]]),
                         period=0.2, time=t, states=states) for k in range(ROWS))
    return Branch("periodic_1", BranchKind.PERIODIC, Origin("test"), ("V",), ("m/s",), ("x", "v"),
                  ("m", "m/s"), v[:, None], np.ones((ROWS, 2)), -np.ones((ROWS, 2)),
                  np.zeros(ROWS), np.full(ROWS, 0.2), np.ones(ROWS, bool), types,
                  np.arange(1, ROWS + 1), np.full((ROWS, 2), np.nan, complex), orbits=orbits)


def test_orbits_beside_a_fold_are_not_checked():
    family = _family()
    # the fold's neighbours, 0.05 m/s away (2.5e-2 of the span), are checked when picked ...
    assert not simulate._near_fold(family, 18)
    # ... but where AUTO steps finely past the fold, an orbit three rows on and 1e-3 m/s
    # from it (5e-4 of the span) is not
    close = family.parameters.copy()
    close[21:24, 0] = (8.0003, 8.0006, 8.001)
    near = Branch(**{**family.__dict__, "parameters": close})
    assert simulate._near_fold(near, 23)
    planned = [near.orbits[item].index
               for _, _, item in simulate.planned_checks((near,), per_branch=ROWS)]
    assert 18 in planned and 23 not in planned
