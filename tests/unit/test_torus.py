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
