"""Freeplay on a gimbal dof (studies/gimballed/freeplay_gimbal_airspeed.yaml: beta_y, K_in =
0, K_out = 10 N m/rad, delta = 1 deg): whirl's classifier calls the motion from 2 deg of pitch
at 6.7 m/s chaotic. Checked against the exact piecewise-linear law's motion written in the test
(tests/gimballed_exact.py, each piece of the law in closed form): after a transient, two starts 1e-9
delta apart part exponentially, at about the exponent whirl estimates, to the size of the
motion itself, and the motion neither settles nor diverges."""

from __future__ import annotations

import numpy as np
import pytest

from whirl_cli.pipeline import run_study
from whirl_cli.study import load_study

from ..conftest import ROOT
from ..gimballed_exact import freeplay_simulation

DELTA, K_OUT = np.radians(1.0), 10.0
STUDY = ROOT / "studies" / "gimballed" / "freeplay_gimbal_airspeed.yaml"
VALUES = {"K_psi": 0.3, "V": 6.7}


@pytest.fixture(scope="module")
def exploration(tmp_path_factory):
    result = run_study(load_study(STUDY), tmp_path_factory.mktemp("gimbal"), jobs=2)
    (continuation,) = result.continuations
    (found,) = continuation.explorations
    return found


def exact(y0: np.ndarray, duration: float) -> tuple[np.ndarray, np.ndarray]:
    return freeplay_simulation(VALUES, "beta_y", DELTA, K_OUT, y0, duration,
                               samples_per_second=500)


def test_chaos_at_6_7_m_s_against_the_exact_law(exploration):
    assert exploration.kind == "chaotic", exploration.evidence
    start = np.zeros(8)
    start[0] = np.radians(2.0)  # the study's explore start: 2 deg of pitch
    t, y = exact(start, 25.0)
    late = y[t > 10.0]
    size = np.abs(late[:, :4]).max() / DELTA
    assert 1.0 < size < 20.0  # neither at rest nor diverged
    assert np.ptp(late[:, 2]) / DELTA > 2.0  # the gimbal crosses its gap
    ta, a = exact(y[-1], 3.0)
    shifted = y[-1].copy()
    shifted[0] += 1e-9 * DELTA
    tb, b = exact(shifted, 3.0)
    n = min(len(a), len(b))
    apart = np.abs(a[:n, :4] - b[:n, :4]).max(axis=1) / DELTA
    assert apart[ta[:n] <= 3.0].max() > 0.1 * size  # parted to the motion's own size
    growing = (apart > 1e-7) & (apart < 1e-3)  # the exponential stretch, before saturation
    rate = np.polyfit(ta[:n][growing], np.log(apart[growing]), 1)[0]
    assert rate > 3.0
    assert exploration.lyapunov == pytest.approx(rate, rel=0.5)
    print(f"exact law: separation rate {rate:.2f} 1/s; whirl: lambda = "
          f"{exploration.lyapunov:.2f} +- {exploration.lyapunov_error:.2f} 1/s")
