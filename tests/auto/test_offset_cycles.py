"""The lop-sided limit cycles about freeplay's offset equilibria (real AUTO-07p), in
studies/freeplay/pitch_offset_cycles.yaml: Newton's method finds the offset equilibria, whose
Hopf points (7.4913 m/s) start the families; their stable cycles are checked against the
exact piecewise-linear law's motion written in the test (tests/classical_exact.py, each piece
of the law in closed form): from near the offset equilibrium at 7.6 and 8.3 m/s (above the
linear onset) the motion settles on a cycle of the continued cycle's pitch range, and at
7.4 m/s (below it, where the offset equilibrium is stable too) the stored stable orbit stays
a cycle of its own range."""

from __future__ import annotations

import math

import numpy as np
import pytest

from whirl_cli.pipeline import run_study
from whirl_cli.results import PointType
from whirl_cli.study import load_study

from ..classical_exact import freeplay_motion
from ..conftest import ROOT

DELTA, K_OUT, K_PSI = math.radians(1.0), 0.4, 0.3
STUDY = ROOT / "studies" / "freeplay" / "pitch_offset_cycles.yaml"


@pytest.fixture(scope="module")
def continuation(tmp_path_factory):
    result = run_study(load_study(STUDY), tmp_path_factory.mktemp("offset"), jobs=2)
    (found,) = result.continuations
    return found


def stable_ranges(branch, v: float) -> list[np.ndarray]:
    """(theta min, theta max, psi min, psi max) / delta of each stable cycle of ``branch`` at
    airspeed ``v`` (interpolated between the rows around it)."""
    p = branch.parameters[:, 0]
    rows = np.column_stack([branch.state_min[:, :2], branch.state_max[:, :2]])[:, [0, 2, 1, 3]]
    found = []
    for k in np.flatnonzero((p[:-1] - v) * (p[1:] - v) < 0):
        if branch.stable[k] and branch.stable[k + 1]:
            w = (v - p[k]) / (p[k + 1] - p[k])
            found.append((rows[k] + w * (rows[k + 1] - rows[k])) / DELTA)
    return found


def settled_range(v: float, y0, duration: float = 40.0) -> np.ndarray:
    """(theta min, theta max, psi min, psi max) / delta over the last 5 s of the exact law's
    motion from ``y0``."""
    t, y = freeplay_motion({"K_psi": K_PSI, "V": v}, DELTA, K_OUT, y0, duration,
                           samples_per_second=1000)
    assert t[-1] == pytest.approx(duration)  # did not diverge
    last = y[t > duration - 5.0]
    return np.array([last[:, 0].min(), last[:, 0].max(), last[:, 1].min(),
                     last[:, 1].max()]) / DELTA


def test_families_start_at_the_offset_equilibria_hopf_points(continuation):
    names = {b.name for b in continuation.branches}
    assert {"periodic_1", "periodic_2"} <= names
    for name in ("periodic_1", "periodic_2"):
        family = continuation.branch(name)
        assert family.origin.point == PointType.HB and family.origin.parameter == "V"
        assert family.origin.value == pytest.approx(7.491, abs=5e-4)
        assert abs(family.state_max[0, 0]) / DELTA > 1.0  # about an offset equilibrium
        assert family.status == "ok", family.message
    # each ends where its cycles grow into the saddle at the gap's centre (K_in = 0)
    ends = [p for p in continuation.special_points if p.point_type == PointType.HOMOCLINIC]
    assert sorted(p.branch for p in ends) == ["periodic_1", "periodic_2"]
    assert all(np.allclose(p.state, 0.0) for p in ends)


@pytest.mark.parametrize("v", [7.6, 8.3])
def test_stable_lopsided_cycles_above_the_onset_against_the_exact_law(continuation, v):
    exact = settled_range(v, [1.3 * DELTA, 0.0, 0.0, 0.0])
    assert exact[0] > 0.5 and exact[1] < 1.6  # lop-sided: never near the other side
    for name, sign in (("periodic_1", 1.0), ("periodic_2", -1.0)):
        (found,) = stable_ranges(continuation.branch(name), v)
        if sign < 0:  # the mirror image: ranges swap ends
            found = -found[[1, 0, 3, 2]]
        np.testing.assert_allclose(found, exact, atol=0.01)
    print(f"V = {v}: theta {exact[0]:.4f}-{exact[1]:.4f} delta (exact law)")


def test_stable_cycle_below_the_onset_persists_under_the_exact_law(continuation):
    """At 7.4 m/s, below the Hopf point, the family's stable cycle (between its fold and
    the onset) is a cycle of the exact law too: from its stored orbit the motion keeps its
    pitch range."""
    family = continuation.branch("periodic_1")
    (found,) = stable_ranges(family, 7.4)
    (orbit,) = [o for o in family.orbits
                if abs(o.parameters[0] - 7.4) < 1e-9 and family.stable[o.index]]
    exact = settled_range(7.4, orbit.states[0])
    np.testing.assert_allclose(found, exact, atol=0.01)
    assert found[1] - found[0] > 0.3  # a cycle, not the equilibrium at rest
