"""The unsafe region pairs a fold of cycles with a Hopf point only where stable cycles lie
beside the fold (real AUTO-07p).

``boundary_softening`` with K1 widened to 1.0: its folds of cycles at K_psi <= 0.2 join
unstable cycles to unstable ones, yet each was paired with the nearest Hopf point, which marked
unsafe intervals down to K_psi 0.04. Checked against the classical model written out in the
test (tests/classical_exact.py) with the softening law: where the study keeps an interval a
stable cycle is found by simulation (carried from the flutter side) while small disturbances
decay; where it drops one, no start of up to 15 deg in pitch or yaw settles on a cycle.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from whirl_cli.pipeline import run_study
from whirl_cli.study import validate_text

from ..classical_exact import linear_matrix, polynomial, simulate
from ..conftest import STUDIES

K2 = -10.0
WIDE = 1.0  # K1 range to 1.0: the folds of unstable cycles at small K_psi fall inside it


@pytest.fixture(scope="module")
def boundary(tmp_path_factory):
    text = (STUDIES / "boundary_softening.yaml").read_text()
    text = re.sub(r"range: \{K1: \[-0.3, [0-9.]+\]", f"range: {{K1: [-0.3, {WIDE}]", text)
    text = re.sub(r"range: \[-0.3, [0-9.]+\], points: \d+", f"range: [-0.3, {WIDE}], points: 31",
                  text)
    assert f"K1: [-0.3, {WIDE}]" in text
    study = validate_text(text, "boundary_softening_wide.yaml")
    (found,) = run_study(study, tmp_path_factory.mktemp("wide"), jobs=2).boundaries
    return found


def flutter_at(boundary, k_psi: float) -> list[tuple[float, float]]:
    row = min({i.slice_value for i in boundary.intervals} | {k_psi},
              key=lambda v: (abs(v - k_psi) > 1e-9, abs(v - k_psi)))
    return [(i.lower, i.upper) for i in boundary.intervals
            if i.cause == "flutter" and abs(i.slice_value - row) < 1e-9]


def origin_stable(k_psi: float, k1: float) -> bool:
    return np.linalg.eigvals(linear_matrix({"K_psi": k_psi, "K_theta": k1})).real.max() < 0


def settles_on_cycle(k_psi: float, k1: float, y0, duration: float = 30.0) -> bool:
    """Whether the motion from ``y0`` neither decays nor diverges: its largest pitch and yaw
    over the last two 3 s windows agree to 1 % and exceed 0.5 deg."""
    t, y = simulate({"K_psi": k_psi, "K_theta": k1}, polynomial(k1, K2), y0, duration,
                    samples_per_second=400)
    if t[-1] < duration - 1e-6:
        return False  # diverged
    late = np.abs(y[t > duration - 3.0, :2]).max()
    before = np.abs(y[(t > duration - 6.0) & (t <= duration - 3.0), :2]).max()
    return late > np.radians(0.5) and abs(late - before) < 0.01 * late


def carried_cycle(k_psi: float, k1_values: tuple[float, ...]) -> np.ndarray:
    """The state reached at the last of ``k1_values``, each simulated 20 s from where the one
    before ended (the first, on the flutter side, from a small disturbance)."""
    y0 = np.array([0.01, 0.0, 0.0, 0.0])
    for k1 in k1_values:
        t, y = simulate({"K_psi": k_psi, "K_theta": k1}, polynomial(k1, K2), y0, 20.0,
                        samples_per_second=400)
        assert t[-1] == pytest.approx(20.0), f"diverged at K1 = {k1}"
        y0 = y[-1]
    return y0


def test_kept_where_a_stable_cycle_coexists(boundary):
    k_psi, k1 = 0.3, 0.40
    assert origin_stable(k_psi, k1)
    assert not settles_on_cycle(k_psi, k1, [0.01, 0, 0, 0])  # small disturbance decays
    steps = (0.26, 0.28, 0.30, 0.32, 0.34, 0.36, 0.38, k1)  # fine steps: it stays on the cycle
    assert settles_on_cycle(k_psi, k1, carried_cycle(k_psi, steps))
    assert any(lo < k1 < hi for lo, hi in flutter_at(boundary, k_psi))


@pytest.mark.parametrize("k_psi, k1", [(0.04, 0.35), (0.1, 0.40), (0.15, 0.36)])
def test_dropped_where_no_stable_cycle_exists(boundary, k_psi, k1):
    assert origin_stable(k_psi, k1)
    for degrees in (5.0, 10.0, 15.0):
        for dof in (0, 1):
            y0 = np.zeros(4)
            y0[dof] = np.radians(degrees)
            assert not settles_on_cycle(k_psi, k1, y0), (degrees, dof)
    assert not any(lo < k1 < hi for lo, hi in flutter_at(boundary, k_psi)), \
        flutter_at(boundary, k_psi)
