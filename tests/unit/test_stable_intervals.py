"""The linearly stable part of the rows of a two-parameter boundary (numpy only, no AUTO),
against the eigenvalues and the closed-form edges of a damped oscillator."""

from __future__ import annotations

import numpy as np
import pytest

from whirl_cli.analysis.boundaries import _cells, stable_intervals
from whirl_cli.models import get_model


def _growth(model, overrides, first, second, x, y):
    params = model.parameter_vector({**overrides, first: x, second: y})
    return np.linalg.eigvals(model.jacobian_numpy(np.zeros(model.n_states), params)).real.max()


@pytest.fixture(scope="module")
def model():
    return get_model("classical")


def test_rows_at_once_find_the_sign_changes_of_the_largest_real_part(model):
    """Each interval end inside the range is a zero of the largest real part (to 1e-9), the
    middle of each interval is stable and the middle of each gap unstable, on every row."""
    rows = [0.05, 0.2, 0.3, 0.45]
    found = stable_intervals(model, {}, "K_theta", "K_psi", rows, (-0.3, 0.5), 801)
    assert len(found) == len(rows) and any(len(r) > 1 for r in found)
    for value, intervals in zip(rows, found, strict=True):
        for lo, hi in intervals:
            assert _growth(model, {}, "K_theta", "K_psi", 0.5 * (lo + hi), value) < 0
            for end in (lo, hi):
                if -0.3 < end < 0.5:
                    step = 1e-9
                    left = _growth(model, {}, "K_theta", "K_psi", end - step, value)
                    right = _growth(model, {}, "K_theta", "K_psi", end + step, value)
                    assert left * right <= 0, (value, end)
        for (_, hi), (lo, _) in zip(intervals[:-1], intervals[1:], strict=True):
            assert _growth(model, {}, "K_theta", "K_psi", 0.5 * (hi + lo), value) > 0


def test_examining_only_some_cells_gives_the_same_stable_parts_there(model):
    """Restricted to windows, the stable intervals agree with the full row inside them."""
    rows = [0.2, 0.3]
    full = stable_intervals(model, {}, "K_theta", "K_psi", rows, (-0.3, 0.5), 801)
    windows = [[(0.05, 0.1), (0.25, 0.33)], []]
    part = stable_intervals(model, {}, "K_theta", "K_psi", rows, (-0.3, 0.5), 801,
                            within=windows)
    assert part[1] == []
    for lo, hi in windows[0]:
        def clip(intervals, lo=lo, hi=hi):
            return [(max(a, lo), min(b, hi)) for a, b in intervals if min(b, hi) > max(a, lo)]
        assert np.ravel(clip(part[0])) == pytest.approx(np.ravel(clip(full[0])), abs=1e-12)


def test_cells_cover_the_windows_with_their_bracketing_points():
    grid = np.linspace(0.0, 1.0, 11)
    assert np.flatnonzero(_cells(grid, [(0.25, 0.31)])).tolist() == [2, 3, 4]
    assert np.flatnonzero(_cells(grid, [(0.32, 0.38)])).tolist() == [3, 4]
    assert _cells(grid, None).all() and not _cells(grid, []).any()
