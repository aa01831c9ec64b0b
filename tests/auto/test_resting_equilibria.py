"""Equilibrium branches no branch point leads to (real AUTO-07p): with pitch freeplay and
K_in = 0 the offset equilibria exist at every airspeed apart from the origin's branch; a seed
of ``studies/freeplay/pitch_airspeed.yaml`` comes to rest on one, which starts a branch (and
its mirror image another). Checked against the classical model written out in the test
(tests/classical_exact.py): the exact law's offset equilibrium solved with scipy at 6.7 m/s,
and their Hopf point, the linear onset with K_theta = K_out (their stability is that of the
linear model there), from the test's own eigenvalues by Brent's method.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq, fsolve

from whirl_cli.pipeline import run_study
from whirl_cli.results import PointType
from whirl_cli.study import load_study

from ..classical_exact import field, freeplay, linear_matrix
from ..conftest import ROOT

DELTA, K_OUT, K_PSI = math.radians(1.0), 0.4, 0.3


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    study = load_study(ROOT / "studies" / "freeplay" / "pitch_airspeed.yaml")
    return run_study(study, tmp_path_factory.mktemp("resting"), jobs=2)


def offset_equilibrium(v: float, sign: float) -> np.ndarray:
    f = field({"K_psi": K_PSI, "V": v}, freeplay(DELTA, K_OUT))
    root = fsolve(lambda y: f(0.0, y), [sign * 2 * DELTA, 0, 0, 0], xtol=1e-11)
    assert np.abs(f(0.0, root)).max() < 1e-9
    return root


def test_offset_equilibria_start_branches_with_their_hopf_point(result):
    (continuation,) = result.continuations
    resting = [b for b in continuation.branches if b.name.startswith("resting_")]
    assert len(resting) == 4, [b.name for b in continuation.branches]  # two, both ways
    for sign in (1.0, -1.0):
        expected = offset_equilibrium(6.7, sign)
        assert abs(expected[0]) > DELTA  # outside the gap
        rows = [(b, k) for b in resting for k in np.flatnonzero(
            np.abs(b.parameters[:, 0] - 6.7) < 1e-9) if np.sign(b.state_max[k, 0]) == sign]
        assert rows
        for branch, k in rows:
            np.testing.assert_allclose(branch.state_max[k, :2], expected[:2], rtol=1e-6)
    onset = brentq(lambda v: np.linalg.eigvals(
        linear_matrix({"K_psi": K_PSI, "K_theta": K_OUT, "V": v})).real.max(), 7.0, 8.0,
        xtol=1e-10)
    hopfs = [p for p in continuation.special_points if p.point_type == PointType.HB
             and p.branch.startswith("resting_")]
    assert len(hopfs) == 2
    for point in hopfs:
        assert point.parameters[0] == pytest.approx(onset, abs=1e-4)
        equilibrium = offset_equilibrium(point.parameters[0], np.sign(point.state[0]))
        np.testing.assert_allclose(point.state[:2], equilibrium[:2], rtol=1e-5)
    print(f"offset equilibria theta = +-{math.degrees(offset_equilibrium(6.7, 1)[0]):.5f} deg "
          f"at 6.7 m/s; Hopf {hopfs[0].parameters[0]:.5f} m/s (eigenvalues {onset:.5f})")
