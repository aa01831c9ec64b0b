"""Persistence of period doublings (:mod:`whirl_cli.continuation.shrinking`,
:mod:`whirl_cli.continuation.persistence`): AUTO finds them from its Floquet multipliers, whose
error on the study's mesh can exceed how far a shallow pair dips below -1, so the short runs
recompute them on a finer mesh, at the study's width too, from before the first of a row of
them (a finer mesh moves each of a pair but keeps their order), and the point is moved to
where that run finds it before its values at the reduced widths are judged."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from whirl_cli.continuation import persistence, shrinking
from whirl_cli.continuation.persistence import Recomputed
from whirl_cli.results import (
    ContinuationKind,
    ContinuationResult,
    PointType,
    SpecialPoint,
)

RG = 4  # AUTO's regular labelled point


def _run(types: list[int]):
    """A run's label and point type columns: a label on every row but the first."""
    return SimpleNamespace(label=np.arange(len(types)) + 10 * (np.arange(len(types)) > 0),
                           point_type=np.array(types))


def _point(kind: PointType, label: int, value: float = 8.13) -> SpecialPoint:
    return SpecialPoint("periodic_1", 0, int(kind), ("V",), np.array([value]), np.zeros(4),
                        0.4, False, label=label, parameter_units=("m/s",))


def test_a_pair_is_recomputed_from_before_its_first_point_in_its_order():
    # rows: start, regular, fold, regular, regular, PD, regular, PD
    run = _run([0, RG, int(PointType.LPC), RG, RG, int(PointType.PD), RG, int(PointType.PD)])
    labels = run.label
    first = shrinking._multiplier_start(run, _point(PointType.PD, labels[5]), "r", ("q", 3))
    second = shrinking._multiplier_start(run, _point(PointType.PD, labels[7]), "r", ("q", 3))
    assert first == (("r", labels[4]), 1, 1)
    assert second == (("r", labels[4]), 3, 2)  # not from the regular label between the two


def test_from_where_its_run_started_or_not_at_all():
    run = _run([0, int(PointType.PD), RG, int(PointType.PD)])
    assert shrinking._multiplier_start(run, _point(PointType.PD, run.label[3]), "r",
                                       ("q", 3)) == (("q", 3), 3, 2)
    assert shrinking._multiplier_start(run, _point(PointType.PD, run.label[3]), "r",
                                       None) is None
    run = _run([0, RG, int(PointType.LPC), int(PointType.PD)])  # a fold right before it
    assert shrinking._multiplier_start(run, _point(PointType.PD, run.label[3]), "r",
                                       ("q", 3)) is None


def test_a_point_located_again_is_moved_and_judged_from_there():
    coarse = _point(PointType.PD, 76, 8.1284)
    result = ContinuationResult("airspeed", ContinuationKind.ONE_PARAMETER, (), (coarse,))
    fine = Recomputed(np.array([8.1379, 8.1377]), shrinking.RESTART,
                      located=_point(PointType.PD, 87, 8.1381))
    (point,) = persistence.annotate(result, [], 3.0, recomputed={0: fine}).special_points
    assert point.parameters[0] == 8.1381 and not point.artefact
    assert "8.1284" in point.note
    # the same values judged from the coarse location move by 9.5e-3 > 2e-3 of the range
    (point,) = persistence.annotate(result, [], 3.0, recomputed={
        0: Recomputed(fine.values, shrinking.RESTART)}).special_points
    assert point.artefact
