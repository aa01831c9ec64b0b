"""The settle test of seeds judges what the motion does on its return map: a cycle that crosses
its section several times a period repeats with that lag, a motion approaching a cycle is
followed at the rate it converges, a torus never passes; the gimballed model with pitch
freeplay (K_beta = 10, K_psi = 0.3, delta = 1 deg, K_out = 0.4) settles at 6.7 m/s on the cycle
the exact law's motion (tests/gimballed_exact.py, each piece of the law in closed form)
stays on; a study whose seeds found nothing and could not all be judged fails."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.gimballed_exact import freeplay_simulation, maxima
from whirl_cli.analysis import seeds
from whirl_cli.output.summary import tables
from whirl_cli.results import ContinuationResult, SeedOutcome, StudyResult
from whirl_cli.study import validate_text
from whirl_cli.verdict import verdict

DELTA = math.radians(1.0)
STEP = 2 * np.pi / 200


def returns_of(x: np.ndarray, y: np.ndarray, t: np.ndarray):
    trajectory = np.column_stack([x, y])
    return seeds.returns(t, trajectory, [0, 1], np.ones(2))


@pytest.mark.parametrize("order, crossings", [(1, 1), (2, 2), (3, 3)])
def test_a_cycle_repeats_with_the_lag_of_its_crossings_per_period(order, crossings):
    """x = cos t + 1.6 cos(n t) crosses its mean upwards n times a period 2 pi (counted here
    on a fine grid); the return map repeats with that lag, at that period."""
    fine = np.linspace(0, 2 * np.pi, 200_001)[:-1]
    wave = np.cos(fine) + 1.6 * np.cos(order * fine)
    assert int(np.sum((wave < 0) & (np.roll(wave, -1) >= 0))) == crossings
    t = np.arange(0, 50 * 2 * np.pi, STEP)
    times, points = returns_of(np.cos(t) + 1.6 * np.cos(order * t), np.sin(t + 0.3), t)
    judged = seeds.judge(times, points, 1e-4)
    assert judged.lag == crossings
    assert abs(times[-1] - times[-1 - judged.lag] - 2 * np.pi) < 1e-6


def test_a_motion_approaching_a_cycle_is_followed_at_its_rate():
    """A cycle approached by a factor 0.9 a period (amplitude 1 + 0.5 x 0.9^(t / 2 pi)): not
    yet repeating to 1e-4 after 50 periods; the distances between returns shrink by 0.9 a
    return, and the time still needed follows from it."""
    t = np.arange(0, 50 * 2 * np.pi, STEP)
    rate = 0.9
    envelope = 1 + 0.5 * rate ** (t / (2 * np.pi))
    times, points = returns_of(envelope * np.cos(t), envelope * np.sin(t), t)
    judged = seeds.judge(times, points, 1e-4)
    assert judged.lag == 0
    assert abs(judged.rate - rate) < 0.01
    expected = math.log(1e-4 / judged.distance) / math.log(rate) * 2 * np.pi
    assert judged.needed(1e-4) == pytest.approx(expected, rel=0.02)
    assert "converge too slowly" in judged.why(1e-4, 300.0, 2 * np.pi)


def test_a_torus_never_passes():
    """Two incommensurate frequencies: the returns fill a curve, neither repeating nor
    converging, and the reason says so."""
    t = np.arange(0, 50 * 2 * np.pi, STEP)
    slow = 0.3 * np.cos(np.sqrt(2) / 5 * t)
    times, points = returns_of((1 + slow) * np.cos(t), (1 + slow) * np.sin(t), t)
    judged = seeds.judge(times, points, 1e-4)
    assert judged.lag == 0 and judged.needed(1e-4) == np.inf
    assert "do not converge" in judged.why(1e-4, 300.0, 2 * np.pi)


GIMBALLED = f"""
name: gimballed-pitch-freeplay
model: gimballed
parameters: {{K_psi: 0.3, K_beta: 10.0, V: 6.7}}
nonlinearity: {{type: freeplay, dof: theta, delta: {DELTA!r}, K_out: 0.4}}
continuations:
  - {{name: v, type: one-parameter, parameter: V, start: 6.7, range: [6.0, 9.0], seeds: auto}}
"""


def test_gimballed_pitch_freeplay_seed_settles_on_the_exact_laws_cycle():
    """The seed at 4 delta settles on a cycle (its gimbal rates' fast content once kept the
    section's returns from repeating); an exact-law simulation started on it stays on it:
    theta's maxima and the period over its last 10 periods agree to 1e-3."""
    study = validate_text(GIMBALLED)
    model = study.variant()
    params = model.parameter_vector(study.parameter_values())
    seed = np.zeros(model.n_states)
    seed[0] = 4 * DELTA
    settled = seeds.settle(model, params, seed)
    assert settled.kind == "periodic", settled.message
    orbit = settled.orbit
    start = orbit.states[0] * np.array([1, -1, 1, -1] * 2)  # the derivation frame
    t, y = freeplay_simulation({"K_psi": 0.3, "K_beta": 10.0, "V": 6.7}, "theta", DELTA, 0.4,
                               start, 40 * orbit.period)
    times, peaks = maxima(t, y[:, 0])
    late = times > 30 * orbit.period
    assert np.ptp(peaks[late]) < 1e-3 * peaks[late].max()  # the exact law's cycle
    assert abs(peaks[late].max() / orbit.states[:, 0].max() - 1) < 1e-3
    assert abs(np.diff(times[late]).mean() / orbit.period - 1) < 1e-3
    assert orbit.states[:, 0].max() > 5 * DELTA
    print(f"\ngimballed pitch freeplay at 6.7 m/s: cycle theta max "
          f"{orbit.states[:, 0].max() / DELTA:.5f} delta, period {orbit.period:.6f} s "
          f"(exact law: {peaks[late].max() / DELTA:.5f} delta, "
          f"{np.diff(times[late]).mean():.6f} s); {settled.message}")


def outcome(index: int, kind: str, branch: str = "") -> SeedOutcome:
    return SeedOutcome(index, np.zeros(4), kind, np.nan, branch, f"what seed {index} did")


def result_with(*outcomes: SeedOutcome) -> StudyResult:
    continuation = ContinuationResult("v", "one-parameter", (), (), seeds=outcomes)
    return StudyResult("x", "gimballed", (continuation,), (), ())


def test_seeds_that_found_nothing_and_could_not_all_be_judged_fail_the_study():
    nothing = result_with(outcome(1, "equilibrium"), outcome(2, "unsettled"),
                          outcome(3, "unsettled"))
    (problem,) = verdict(nothing).problems
    assert problem.startswith("v: 2 of 3 seeds could not be judged (seed 2: what seed 2 did)")
    assert "no other seed led to a limit cycle" in problem
    assert any("2 of 3 seeds could not be judged" in n for n in tables(nothing)[0].notes)

    some = result_with(outcome(1, "periodic", "periodic_o1"), outcome(2, "unsettled"))
    assert verdict(some).problems == ()
    (note,) = tables(some)[0].notes
    assert "may not be all" in note
    assert verdict(result_with(outcome(1, "equilibrium"))).problems == ()
