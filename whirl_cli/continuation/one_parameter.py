"""The one-parameter recipe: equilibria with branch switching, the criticality of their Hopf
points and, when asked, the periodic family of every Hopf point and of every given orbit, and
the period-doubled family of every period-doubling point on them.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..results import ContinuationKind, ContinuationResult
from .criticality import with_criticality, with_lyapunov
from .doubling import doubled_families
from .engine import Engine, Numerics
from .equilibria import equilibria, is_linear
from .periodic import OrbitStart, orbit_families, periodic_families
from .switching import switched_families


def one_parameter(engine: Engine, name: str, parameter: str, start: float,
                  bounds: tuple[float, float], parameters: dict[str, float],
                  numerics: Numerics, branch_points: bool = True,
                  periodic: bool = False, orbits_at: tuple[float, ...] = (),
                  start_orbits: tuple[OrbitStart, ...] = (),
                  start_state: np.ndarray | None = None,
                  resting: tuple[np.ndarray, ...] = (), spread: bool = False,
                  period_doubling: bool = False, cycle_branching: bool = True
                  ) -> ContinuationResult:
    """Equilibria of ``parameter`` over ``bounds`` from ``start`` (from the equilibrium found
    by Newton's method from ``start_state``, SI, default zero), with branch switching, and
    (``periodic``) the periodic families of every Hopf point, and those through each of
    ``start_orbits`` (e.g. orbits settled by time simulation). ``orbits_at``: parameter values
    where every branch stores a labelled solution (orbit profiles); ``resting``: states (SI)
    at ``start`` near equilibria (e.g. where seeds came to rest), each starting a branch if
    it is on none (see :func:`.equilibria.equilibria`), as does (``spread``) every
    equilibrium Newton's method finds there from a spread of starts. The periodic families'
    branch points of cycles start the families crossing them there (:mod:`.switching`;
    not if ``cycle_branching`` is false);
    ``period_doubling``: the families doubled at the PD points of the periodic ones
    (:mod:`.doubling`)."""
    numerics = replace(numerics, orbits_at=tuple(orbits_at))
    branches, points = equilibria(engine, name, parameter, start, bounds, parameters, numerics,
                                  branch_points, start_state, tuple(resting), spread)
    points = with_lyapunov(engine.model, parameter, parameters, points)
    # a linear model has no limit cycles: at a Hopf point it carries a continuum of neutral
    # orbits of every amplitude, which AUTO reports as folds everywhere
    if periodic and not is_linear(engine.model, parameters):
        families, family_points = periodic_families(engine, name, parameter, bounds, numerics,
                                                     branches, points, parameters)
        branches += families
        points = with_criticality(points, families, branches, bounds[1] - bounds[0],
                                   np.asarray(engine.model.state_scale, dtype=float)) \
            + family_points
    if start_orbits:
        steady = [b for b in branches if not b.is_periodic]
        families, family_points = orbit_families(engine, name, parameter, bounds, numerics,
                                                 list(start_orbits), steady, points, parameters)
        branches += families
        points += family_points
    # families branching off the cycles found so far: at branch points, then (of those too)
    # at period doublings
    for wanted, branching in ((cycle_branching and (periodic or start_orbits),
                               switched_families), (period_doubling, doubled_families)):
        if not wanted:
            continue
        steady = [b for b in branches if not b.is_periodic]
        families, family_points = branching(
            engine, name, parameter, bounds, numerics, [b for b in branches if b.is_periodic],
            points, steady, parameters)
        branches += families
        points += family_points
    return ContinuationResult(name, ContinuationKind.ONE_PARAMETER, tuple(branches), tuple(points))

