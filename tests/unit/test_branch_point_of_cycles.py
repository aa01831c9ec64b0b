"""Branch points of cycles (BPC): AUTO's test function can change sign where no second
Floquet multiplier passes +1 (seen many times along one family of the tiltrotor study with the
combined law on the gimbal, where the count of multipliers outside the unit circle did not
change across them); such a point is listed as rejected, not switched at, not drawn."""

from __future__ import annotations

import numpy as np

from whirl_cli.continuation.branches import TORUS_TOLERANCE, special_points
from whirl_cli.results import Branch, BranchKind, LocateStatus, Origin, PointType


def _periodic_with_bpc(multipliers: np.ndarray) -> Branch:
    rows = 3
    return Branch("periodic_1", BranchKind.PERIODIC, Origin("test"), ("V",), ("m/s",),
                  ("theta", "psi", "theta_dot", "psi_dot"), ("rad",) * 2 + ("rad/s",) * 2,
                  np.array([[8.0], [8.1], [8.2]]), np.ones((rows, 4)), -np.ones((rows, 4)),
                  np.ones(rows), np.full(rows, 0.2), np.zeros(rows, bool),
                  np.array([0, int(PointType.BPC), 0]), np.array([0, 2, 0]),
                  np.tile(multipliers.astype(complex), (rows, 1)))


def test_a_bpc_with_one_multiplier_at_one_is_rejected_and_with_two_located():
    # the tiltrotor study's periodic_3 at V = 21.0457: the trivial multiplier, then 0.95 away
    (false,) = special_points(_periodic_with_bpc(np.array([1.0, 1.9485, 0.0445, 0.01])))
    assert false.status == LocateStatus.REJECTED and "branch-point" in false.note
    # a pitchfork: a second multiplier at +1 to AUTO's accuracy
    crossing = np.array([1.0, 1 + TORUS_TOLERANCE / 2, 0.3, 0.01])
    (real,) = special_points(_periodic_with_bpc(crossing))
    assert real.status == LocateStatus.LOCATED and not real.note
    # multipliers unknown: nothing to judge by
    (unknown,) = special_points(_periodic_with_bpc(np.full(4, np.nan)))
    assert unknown.status == LocateStatus.LOCATED
