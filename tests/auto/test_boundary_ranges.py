"""The shipped boundary studies' ranges hold their unsafe regions (real AUTO-07p).

``boundary_softening``: below K_psi = 0.29 its folds of cycles lie beyond K1 = 0.5, so with
K1 stopping there the unsafe region was reported only from K_psi = 0.295. Checked against
the classical model written out in the test (tests/classical_exact.py): at K_psi = 0.285 and
0.29 the right Hopf point from the eigenvalues of the test's own matrix (Brent's method), and
a stable limit cycle beyond it by simulation of the softening law, carried from K1 = 0.25
(where the origin is unstable and the motion grows onto the cycle) up to K1 = 0.36 in steps;
the study's unsafe interval on those rows starts at that Hopf point and holds 0.36, and no
interval of the study ends at the edge of its range.
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
               and i.slice_value > 0.2) <= 0.28  # the thesis's region starts near 0.28
