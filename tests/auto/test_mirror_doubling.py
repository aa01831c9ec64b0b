"""Period-doubled families of mirror families (real AUTO-07p): on the forced double-well
Duffing oscillator (tests/data/forced_duffing.model.yaml, odd right-hand side), each well's
periodic family period-doubles; the doubled families of one well are computed and those of
the other mapped (y -> -y), so the AUTO runs of the doubled families halve, and the mapped
period-2 family holds the cycle a scipy simulation in the other well settles on."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from whirl_cli.pipeline import run_study
from whirl_cli.results import PointType
from whirl_cli.study import load_study

from ..conftest import ROOT

pytestmark = pytest.mark.auto

STUDY = ROOT / "tests" / "data" / "forced_duffing_mu.yaml"
GAMMA, DELTA, OMEGA = 0.5, 0.3, 1.2  # the model file's values


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    (continuation,) = run_study(load_study(STUDY), tmp_path_factory.mktemp("duffing"),
                                jobs=2).continuations
    return continuation


def _settled(mu: float, x0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(maxima, minima) of every state over the last four forcing periods of a simulation
    from x = ``x0`` at rest, the forcing on its cycle, and x at the last eight periods'
    starts."""
    def field(_t, s):
        x, y, p, q = s
        r = p * p + q * q
        return [y, -DELTA * y + x - x**3 + GAMMA * p, mu * p - OMEGA * q - p * r,
                OMEGA * p + mu * q - q * r]

    period = 2 * np.pi / OMEGA
    sol = solve_ivp(field, (0, 200 * period), [x0, 0.0, np.sqrt(mu), 0.0], rtol=1e-10,
                    atol=1e-12, dense_output=True)
    states = sol.sol(np.linspace(196 * period, 200 * period, 8001))
    return states.max(axis=1), states.min(axis=1), sol.sol(np.arange(192, 200) * period)[0]


def test_the_mirror_familys_doubled_families_are_mapped_not_run(result):
    doubled = [b for b in result.branches if "_pd" in b.name]
    from_right = [b for b in doubled if b.name.startswith("periodic_2_")]
    from_left = [b for b in doubled if b.name.startswith("periodic_3_")]
    assert len(from_right) == len(from_left) >= 2  # a cascade in each well
    runs = {run for b in doubled for run in b.runs}
    assert len(runs) * 2 == sum(len(b.runs) for b in doubled)
    assert runs == {run for b in from_right for run in b.runs}
    pd = sorted(p.parameters[0] for p in result.special_points
                if p.point_type == PointType.PD and p.branch.startswith("periodic_3"))
    assert pd == sorted(p.parameters[0] for p in result.special_points
                        if p.point_type == PointType.PD and p.branch.startswith("periodic_2"))


def test_the_mapped_period_2_family_is_the_left_wells_cycle(result):
    """At mu = 0.30 (between the first two PD points) a simulation from the left well settles
    on a period-2 cycle there (x alternates between two values at the forcing's period); the
    mapped family holds it."""
    mu = 0.30
    high, low, strobe = _settled(mu, -1.2)
    assert high[0] < 0  # the left well
    assert abs(strobe[0] - strobe[1]) > 0.1 and np.allclose(strobe[::2], strobe[0], atol=1e-6)
    (family,) = [b for b in result.branches if b.name == "periodic_3_pd1"]
    values = family.parameters[:, 0]
    assert np.all(np.diff(values) > 0) and values[0] < mu < values[-1]
    state_max = [np.interp(mu, values, family.state_max[:, k]) for k in range(4)]
    state_min = [np.interp(mu, values, family.state_min[:, k]) for k in range(4)]
    np.testing.assert_allclose(state_max, high, atol=1e-3)
    np.testing.assert_allclose(state_min, low, atol=1e-3)
