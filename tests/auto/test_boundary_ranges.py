"""The shipped boundary studies' ranges hold their unsafe regions (real AUTO-07p).

``boundary_softening``: below K_psi = 0.29 its folds of cycles lie beyond K1 = 0.5, so with
K1 stopping there the unsafe region was reported only from K_psi = 0.295. Checked against
the classical model written out in the test (tests/classical_exact.py): at K_psi = 0.285 and
0.29 the right Hopf point from the eigenvalues of the test's own matrix (Brent's method), and
a stable limit cycle beyond it by simulation of the softening law, carried from K1 = 0.25
(where the origin is unstable and the motion grows onto the cycle) up to K1 = 0.36 in steps;
the study's unsafe interval on those rows starts at that Hopf point and holds 0.36, and no
interval of the study ends at the edge of its range. At K_psi = 0.25 and 0.27 (between the
slices at 0.2 and 0.3, below the edge where stable cycles cease) no start settles on a cycle
and the study reports those rows safe.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from whirl_cli.pipeline import run_study
from whirl_cli.study import load_study
from whirl_cli.verdict import range_warnings

from ..classical_exact import linear_matrix, polynomial, simulate
from ..conftest import STUDIES

K2 = -10.0
BEYOND = 0.36  # K1 beyond the right Hopf point, where the simulation finds a stable cycle


@pytest.fixture(scope="module")
def softening(tmp_path_factory):
    study = load_study(STUDIES / "boundary_softening.yaml")
    return run_study(study, tmp_path_factory.mktemp("softening"), jobs=2)


def right_hopf(k_psi: float) -> float:
    """K1 of the right Hopf point of the linear model at ``k_psi`` (numpy eigenvalues)."""
    def growth(k1):
        return np.linalg.eigvals(linear_matrix({"K_psi": k_psi, "K_theta": k1})).real.max()
    return brentq(growth, 0.2, 0.4, xtol=1e-10)


def cycle_amplitude(k_psi: float, k1_values: tuple[float, ...]) -> float:
    """Half the peak-to-peak pitch (deg) over the last 2 s at the last of ``k1_values``, each
    simulated 20 s from where the one before it ended (the first from a small disturbance)."""
    y0 = np.array([0.01, 0.0, 0.0, 0.0])
    for k1 in k1_values:
        t, y = simulate({"K_psi": k_psi, "K_theta": k1}, polynomial(k1, K2), y0, 20.0)
        assert t[-1] == pytest.approx(20.0), f"diverged at K1 = {k1}"
        y0 = y[-1]
    return float(np.degrees(np.ptp(y[t > 18.0, 0]) / 2))


@pytest.mark.parametrize("k_psi", [0.285, 0.29])
def test_softening_region_holds_the_cycles_beyond_the_right_hopf(softening, k_psi):
    hopf = right_hopf(k_psi)
    assert hopf < BEYOND
    # linearly stable at BEYOND, yet a stable cycle of several degrees is there
    assert np.linalg.eigvals(linear_matrix({"K_psi": k_psi, "K_theta": BEYOND})).real.max() < 0
    amplitude = cycle_amplitude(k_psi, (0.25, 0.30, 0.33, BEYOND))
    assert amplitude > 5.0
    # and a small disturbance at BEYOND decays (the origin is stable)
    t, y = simulate({"K_psi": k_psi, "K_theta": BEYOND}, polynomial(BEYOND, K2),
                    [0.01, 0, 0, 0], 20.0)
    assert np.abs(y[t > 18.0, :2]).max() < 1e-4
    (boundary,) = softening.boundaries
    rows = [i for i in boundary.intervals
            if abs(i.slice_value - k_psi) < 1e-9 and i.cause == "flutter"]
    assert rows, f"no unsafe interval at K_psi = {k_psi}"
    (row,) = rows
    assert row.lower == pytest.approx(hopf, abs=1e-4)
    assert row.upper > BEYOND
    print(f"K_psi = {k_psi}: Hopf {hopf:.5f} (study {row.lower:.5f}), unsafe to "
          f"{row.upper:.4f}; stable cycle at K1 = {BEYOND}: {amplitude:.2f} deg")


def test_softening_intervals_end_inside_the_range(softening):
    (boundary,) = softening.boundaries
    assert not [w for w in range_warnings(boundary) if "the unsafe interval" in w]
    assert min(i.slice_value for i in boundary.intervals if i.cause == "flutter"
               and i.slice_value > 0.2) < 0.2851  # the thesis's region starts near 0.28


def settles_on_cycle(k_psi: float, k1: float, y0) -> bool:
    """Whether the motion from ``y0`` neither decays nor diverges in 30 s: its largest pitch
    and yaw over the last two 3 s windows agree to 1 % and exceed 0.5 deg."""
    t, y = simulate({"K_psi": k_psi, "K_theta": k1}, polynomial(k1, K2), y0, 30.0,
                    samples_per_second=400)
    if t[-1] < 30.0 - 1e-6:
        return False  # diverged
    late = np.abs(y[t > 27.0, :2]).max()
    before = np.abs(y[(t > 24.0) & (t <= 27.0), :2]).max()
    return late > np.radians(0.5) and abs(late - before) < 0.01 * late


@pytest.mark.parametrize("k_psi", [0.25, 0.27])
def test_softening_rows_without_stable_cycles_are_safe(softening, k_psi):
    """Between the slices at K_psi = 0.2 (no stable cycle beside the fold of cycles) and 0.3
    (stable cycles), the rows below the edge where the family's stable cycles cease are safe:
    at K1 beyond the right Hopf point (where the origin is stable) no start of 5-15 deg in
    pitch or yaw settles on a cycle, and the study reports no flutter interval there."""
    hopf = right_hopf(k_psi)
    for k1 in (hopf + 0.04, 0.40, 0.50):
        assert np.linalg.eigvals(linear_matrix({"K_psi": k_psi, "K_theta": k1})).real.max() < 0
        for degrees in (5.0, 10.0, 15.0):
            for dof in (0, 1):
                y0 = np.zeros(4)
                y0[dof] = np.radians(degrees)
                assert not settles_on_cycle(k_psi, k1, y0), (k1, degrees, dof)
    (boundary,) = softening.boundaries
    assert any(abs(v - k_psi) < 1e-9 for v in np.linspace(0.0, 0.5, 101))  # a row of the study
    assert not [(i.lower, i.upper) for i in boundary.intervals
                if abs(i.slice_value - k_psi) < 1e-9 and i.cause == "flutter"]
