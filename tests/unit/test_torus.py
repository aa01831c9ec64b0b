"""Torus (Neimark-Sacker) points: the angle of the Floquet multipliers on the unit circle."""

from __future__ import annotations

import numpy as np
import pytest


def test_neimark_sacker_angle_of_the_pair_on_the_unit_circle():
    from whirl_cli.continuation.branches import neimark_sacker_angle

    angle = 2.1
    multipliers = np.array([1.0, 0.3 * np.exp(0.5j), 0.3 * np.exp(-0.5j),
                            1.0001 * np.exp(1j * angle), 1.0001 * np.exp(-1j * angle), 0.01])
    assert neimark_sacker_angle(multipliers) == pytest.approx(angle, abs=1e-12)
    assert np.isnan(neimark_sacker_angle(np.array([1.0, 0.5, -1.0, 0.2])))  # no complex pair
    assert np.isnan(neimark_sacker_angle(np.full(4, np.nan + 0j)))  # multipliers unknown


def test_a_pair_off_the_unit_circle_is_no_torus():
    from whirl_cli.continuation.branches import TORUS_TOLERANCE, neimark_sacker_angle

    off = np.array([1.0, 0.395 + 0.0146j, 0.395 - 0.0146j, -0.306 + 0.155j, -0.306 - 0.155j])
    assert np.isnan(neimark_sacker_angle(off))
    near = np.array([1.0, (1 + TORUS_TOLERANCE / 2) * np.exp(1j), (1 + TORUS_TOLERANCE / 2)
                     * np.exp(-1j)])
    assert neimark_sacker_angle(near) == pytest.approx(1.0)


def _periodic_with_tr(multipliers: np.ndarray):
    from whirl_cli.results import Branch, BranchKind, PointType

    rows = 3
    eigenvalues = np.tile(multipliers, (rows, 1))
    return Branch("periodic_1", BranchKind.PERIODIC, "test", ("V",), ("m/s",),
                  ("theta", "psi", "theta_dot", "psi_dot"), ("rad",) * 2 + ("rad/s",) * 2,
                  np.array([[8.0], [8.1], [8.2]]), np.ones((rows, 4)), -np.ones((rows, 4)),
                  np.ones(rows), np.full(rows, 0.2), np.zeros(rows, bool),
                  np.array([0, int(PointType.TR), 0]), np.array([0, 2, 0]), eigenvalues)


def test_a_tr_point_without_a_pair_on_the_unit_circle_is_listed_as_rejected():
    """AUTO's torus test function also changes sign at a neutral saddle (a real pair with
    product 1): that TR point is listed as rejected, its note says why, and it has no angle;
    one with a complex pair on the circle is located with its angle."""
    from whirl_cli.continuation.branches import special_points
    from whirl_cli.results import LocateStatus

    saddle = np.array([1.0, 4.0, 0.25, 0.1])
    (rejected,) = special_points(_periodic_with_tr(saddle))
    assert rejected.status == LocateStatus.REJECTED and np.isnan(rejected.torus_angle)
    assert "not a torus bifurcation" in rejected.note
    torus = np.array([1.0, np.exp(0.7j), np.exp(-0.7j), 0.1])
    (located,) = special_points(_periodic_with_tr(torus))
    assert located.status == LocateStatus.LOCATED and located.torus_angle == pytest.approx(0.7)
