"""Pure geometry helpers of the two-parameter recipe (no AUTO)."""

from __future__ import annotations

import numpy as np

from whirl_cli.continuation.geometry import _near_polyline


def test_point_between_vertices_is_on_the_polyline():
    curve = np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.2]])
    width = np.array([1.0, 1.0])
    assert _near_polyline(np.array([0.05, 0.0005]), curve, width)  # mid-segment, 5e-4 off
    assert _near_polyline(np.array([0.1003, 0.1]), curve, width)
    assert not _near_polyline(np.array([0.05, 0.002]), curve, width)
    assert not _near_polyline(np.array([0.2, 0.2]), curve, width)


def test_distance_is_measured_in_axes_scaled_by_the_ranges():
    curve = np.array([[0.0, 0.0], [1.0, 0.0]])
    point = np.array([0.5, 0.05])
    assert not _near_polyline(point, curve, np.array([1.0, 1.0]))
    assert _near_polyline(point, curve, np.array([1.0, 100.0]))  # 0.05 of a 100-wide axis


def test_degenerate_curves():
    width = np.array([1.0, 1.0])
    assert not _near_polyline(np.zeros(2), np.empty((0, 2)), width)
    assert _near_polyline(np.zeros(2), np.zeros((1, 2)), width)
