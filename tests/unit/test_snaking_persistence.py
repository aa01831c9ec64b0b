"""Persistence of a global bifurcation bracketed by a snaking approach
(:func:`whirl_cli.continuation.persistence.snaking_recomputed`): its estimate is recomputed at
the reduced smoothing widths from its family's folds of cycles, which the short runs recompute,
so its verdict never rests on whether the repeated continuation reaches it again."""

from __future__ import annotations

import numpy as np

from whirl_cli.continuation import persistence
from whirl_cli.continuation.persistence import Recomputed
from whirl_cli.results import (
    ContinuationKind,
    ContinuationResult,
    LocateStatus,
    PointType,
    SpecialPoint,
)

#: p* and the folds of a snaking approach to it: p* + A q^k (-1)^k.
STAR, AMPLITUDE, RATIO = 8.12, 0.02, 0.4
#: How p* moves at each reduced width (the folds with it).
SHIFTS = (1.2e-3, 1.5e-3)


def _point(kind: PointType, value: float, index: int, **fields) -> SpecialPoint:
    return SpecialPoint("periodic_1", index, int(kind), ("V",), np.array([value]), np.zeros(4),
                        0.5, False, parameter_units=("m/s",), **fields)


def _snaking() -> tuple[ContinuationResult, dict[int, Recomputed]]:
    """Five alternating folds closing on STAR, the bracketed end after them, and the folds
    recomputed (each moved by SHIFTS) as the short runs would give them."""
    folds = STAR + AMPLITUDE * RATIO ** np.arange(5) * (-1.0) ** np.arange(5)
    points = [_point(PointType.LPC, v, 100 * (k + 1)) for k, v in enumerate(folds)]
    points.append(_point(PointType.HOMOCLINIC, STAR, 600, status=LocateStatus.BRACKETED,
                         bracket=np.sort(folds[-2:])))
    result = ContinuationResult("airspeed", ContinuationKind.ONE_PARAMETER, (), tuple(points))
    recomputed = {k: Recomputed(folds[k] + np.array(SHIFTS), "restart") for k in range(5)}
    return result, recomputed


def test_a_snaking_end_is_recomputed_from_its_folds():
    result, recomputed = _snaking()
    found = persistence.snaking_recomputed(result, recomputed)
    assert list(found) == [5]
    np.testing.assert_allclose(found[5].values, STAR + np.array(SHIFTS), atol=1e-12)
    assert found[5].method == persistence.FOLDS
    # ... and so judged without a repetition: it persists
    assert not persistence.needs_repetition(result, recomputed | found)
    (end,) = [p for p in persistence.annotate(result, [], 3.0, recomputed=recomputed | found)
              .special_points if p.point_type == PointType.HOMOCLINIC]
    assert not end.artefact and end.refined_by == persistence.FOLDS


def test_not_from_folds_that_were_not_recomputed_or_do_not_bracket_it():
    result, recomputed = _snaking()
    del recomputed[3]
    assert persistence.snaking_recomputed(result, recomputed) == {}
    result, recomputed = _snaking()
    points = list(result.special_points)
    points[5] = _point(PointType.HOMOCLINIC, STAR, 600, status=LocateStatus.BRACKETED,
                       bracket=np.array([STAR - 0.05, STAR + 0.05]))
    moved = ContinuationResult("airspeed", ContinuationKind.ONE_PARAMETER, (), tuple(points))
    assert persistence.snaking_recomputed(moved, recomputed) == {}
