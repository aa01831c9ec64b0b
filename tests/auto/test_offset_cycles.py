"""The lop-sided limit cycles about freeplay's offset equilibria (real AUTO-07p), in
studies/freeplay/pitch_offset_cycles.yaml: Newton's method finds the offset equilibria, whose
Hopf points (7.4913 m/s) start the families; their stable cycles are checked against the
exact piecewise-linear law's motion written in the test (tests/classical_exact.py, each piece
of the law in closed form): from near the offset equilibrium at 7.6 and 8.3 m/s (above the
linear onset) the motion settles on a cycle of the continued cycle's pitch range, and at
7.4 m/s (below it, where the offset equilibrium is stable too) the stored stable orbit stays
a cycle of its own range. The homoclinic end near 8.12 m/s is checked against the exact law's
homoclinic orbit to the gap's saddle: where the saddle's unstable manifold, after one loop
outside the gap, re-enters it on the stable manifold (found by bisection in airspeed)."""

from __future__ import annotations

import math
from itertools import pairwise

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm
from scipy.optimize import brentq, fsolve, minimize_scalar

from whirl_cli.continuation import persistence
from whirl_cli.pipeline import run_study
from whirl_cli.results import PointType
from whirl_cli.study import load_study

from ..classical_exact import field, freeplay, freeplay_map, freeplay_motion, linear_matrix
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


def reentry(v: float) -> tuple[np.ndarray, np.ndarray, float]:
    """The exact law's saddle at the gap's centre at airspeed ``v``: (the law's matrix inside
    the gap, the state where the saddle's unstable manifold re-enters the gap, that state's
    component along the unstable eigenvector / delta). The manifold (theta > 0 side; the law
    is linear inside the gap, so the manifold there is the eigenvector's line) is followed
    out of the gap and back to theta = delta; a zero component: it re-enters on the stable
    manifold, a homoclinic orbit."""
    values = {"K_psi": K_PSI, "V": v}
    inside = linear_matrix({**values, "K_theta": 0.0})
    eigenvalues, vectors = np.linalg.eig(inside)
    k = int(np.argmax(eigenvalues.real))
    assert abs(eigenvalues[k].imag) < 1e-12 and eigenvalues[k].real > 0
    left = np.linalg.inv(vectors)[k]
    unstable = (vectors[:, k] / vectors[0, k]).real
    f = field(values, freeplay(DELTA, K_OUT))

    def edge(direction):
        def event(_t, y):
            return y[0] - DELTA
        event.terminal, event.direction = True, direction
        return event

    out = solve_ivp(f, (0.0, 5.0), 0.5 * DELTA * unstable, method="DOP853", rtol=1e-11,
                    atol=1e-14, events=edge(1))
    t, y = out.t_events[0][0], out.y_events[0][0]
    back = solve_ivp(f, (t, t + 5.0), y + 1e-12 * f(t, y), method="DOP853", rtol=1e-11,
                     atol=1e-14, events=edge(-1))
    (y,) = back.y_events[0][:1]
    return inside, y, float((left @ y / left[0]).real / DELTA)


def homoclinic_miss(v: float) -> float:
    """:func:`reentry`'s component along the unstable eigenvector."""
    return reentry(v)[2]


#: The smoothed law's homoclinic value may differ from the exact law's by this (m/s): whirl's
#: snaking bracket is about 3.5e-3 m/s wide, the smoothing (epsilon = delta/100) moves it.
HOMOCLINIC_TOLERANCE = 2e-3


def test_homoclinic_end_against_the_exact_law(continuation):
    exact = brentq(homoclinic_miss, 8.0, 8.3, xtol=1e-9)
    assert homoclinic_miss(exact - 0.01) * homoclinic_miss(exact + 0.01) < 0
    inside, y, _ = reentry(exact)  # then stays in the gap, decaying onto the saddle
    theta = np.array([(expm(inside * t) @ y)[0] for t in np.linspace(0.0, 0.6, 601)])
    assert np.all(np.abs(theta[1:]) < DELTA) and abs(theta[-1]) < 0.01 * DELTA
    for name in ("periodic_1", "periodic_2"):
        (point,) = [p for p in continuation.special_points
                    if p.branch == name and p.point_type == PointType.HOMOCLINIC]
        low, high = point.bracket
        assert low <= exact <= high
        assert point.parameters[0] == pytest.approx(exact, abs=HOMOCLINIC_TOLERANCE)
        # it persists as the smoothing shrinks, judged from the folds that bracket it (not
        # from whether a repeated continuation happens to reach it again)
        assert not point.artefact, point.note
        assert point.refined_by == persistence.FOLDS
        np.testing.assert_allclose(point.refined, exact, atol=HOMOCLINIC_TOLERANCE)
    print(f"homoclinic: {exact:.6f} m/s (exact law), {point.parameters[0]:.6f} (whirl; "
          f"{point.refined[0]:.6f}, {point.refined[1]:.6f} at epsilon / 2, / 4)")


def exact_flow(v: float, y0: np.ndarray, duration: float) -> np.ndarray:
    """The exact law's state after ``duration`` s from ``y0`` at airspeed ``v``, restarted at
    each gap edge."""
    f = field({"K_psi": K_PSI, "V": v}, freeplay(DELTA, K_OUT))
    edges = [lambda _t, y, e=e: y[0] - e for e in (DELTA, -DELTA)]
    for edge in edges:
        edge.terminal = True
    t, y = 0.0, np.asarray(y0, dtype=float)
    while True:
        done = solve_ivp(f, (t, duration), y, method="DOP853", rtol=1e-11, atol=1e-14,
                         events=edges)
        if done.status != 1:
            return done.y[:, -1]
        t = min(e[0] for e in done.t_events if len(e)) + 1e-12
        y = done.y[:, -1] + 1e-12 * f(t, done.y[:, -1])


def exact_cycle(top: float, guess) -> np.ndarray:
    """(psi, psi', V, period) of the exact law's cycle whose pitch peaks at ``top`` (rad),
    started there with theta' = 0: shooting (scipy fsolve) from ``guess``."""
    def closes(x):
        y0 = np.array([top, x[0], 0.0, x[1]])
        return (exact_flow(x[2], y0, x[3]) - y0) / np.array([1, 1, 30, 30]) / DELTA

    found, _, solved, message = fsolve(closes, guess, full_output=True, xtol=1e-12)
    assert solved == 1, message
    return found


def test_no_fold_between_the_onset_and_the_lower_fold_under_the_exact_law(continuation):
    """The exact law's family of the offset Hopf point: vertical at the onset (the law is
    linear outside the gap), then, once its cycles reach into the gap (pitch peak above 1.25
    delta), its airspeed falls without a turn to the lower fold, where whirl's lowest fold
    converges as epsilon shrinks."""
    def growth(v):
        return np.linalg.eigvals(linear_matrix({"K_psi": K_PSI, "V": v,
                                                "K_theta": K_OUT})).real.max()

    onset = brentq(growth, 7.0, 8.0, xtol=1e-12)
    rest = fsolve(lambda y: field({"K_psi": K_PSI, "V": onset}, freeplay(DELTA, K_OUT))(
        0.0, np.r_[y, 0.0, 0.0])[2:], [1.1 * DELTA, 0.3 * DELTA])
    eigenvalues, vectors = np.linalg.eig(linear_matrix({"K_psi": K_PSI, "V": onset,
                                                        "K_theta": K_OUT}))
    k = int(np.argmax(eigenvalues.real))
    mode = (vectors[:, k] / vectors[0, k]).real
    guess = [rest[1] + (1.15 * DELTA - rest[0]) * mode[1],
             (1.15 * DELTA - rest[0]) * mode[3], onset, 2 * math.pi / eigenvalues[k].imag]
    airspeeds = []
    for top in (1.15, 1.22, 1.255, 1.26, 1.27, 1.28):
        guess = exact_cycle(top * DELTA, guess)
        airspeeds.append(guess[2])
    np.testing.assert_allclose(airspeeds[:2], onset, atol=1e-7)  # out of the gap: vertical
    assert onset - 1e-3 > airspeeds[2] > airspeeds[3] > airspeeds[4] > airspeeds[5]
    last = [guess]  # each cycle from the one before

    def airspeed(top):
        last.append(exact_cycle(top * DELTA, last[-1]))
        return last[-1][2]

    fold = minimize_scalar(airspeed, bounds=(1.28, 1.31), method="bounded",
                           options={"xatol": 1e-4})
    assert 1.28 < fold.x < 1.31
    lowest = min((p for p in continuation.special_points
                  if p.branch == "periodic_1" and p.point_type == PointType.LPC),
                 key=lambda p: p.parameters[0])
    errors = np.abs(np.r_[lowest.parameters[:1], lowest.refined] - fold.fun)
    assert errors[0] < 5e-3 and np.all(np.diff(errors) < 0)  # converges as epsilon shrinks
    print(f"lower fold: {fold.fun:.6f} m/s (exact law), whirl {lowest.parameters[0]:.6f}, "
          f"{lowest.refined[0]:.6f}, {lowest.refined[1]:.6f} at epsilon, /2, /4")


def exact_cycle_of_period(period: float, guess) -> tuple[np.ndarray, np.ndarray]:
    """((theta, psi, psi', V) of the exact law's cycle of ``period`` s started at theta' = 0,
    its Floquet multipliers): Newton's method on the closing condition, its derivative by
    the state from the monodromy matrix, by V by central differences."""
    def closing(x):
        y0 = np.array([x[0], x[1], 0.0, x[2]])
        end, monodromy = freeplay_map({"K_psi": K_PSI, "V": x[3]}, DELTA, K_OUT, y0, period)
        return end - y0, monodromy

    x = np.array(guess, dtype=float)
    for _ in range(20):
        gap, monodromy = closing(x)
        by_v = (closing(x + [0, 0, 0, 1e-7])[0] - closing(x - [0, 0, 0, 1e-7])[0]) / 2e-7
        step = np.linalg.solve(np.column_stack([(monodromy - np.eye(4))[:, [0, 1, 3]], by_v]),
                               -gap)
        x = x + step
        if np.all(np.abs(step) < [1e-15, 1e-15, 1e-13, 1e-11]):
            break
    gap, monodromy = closing(x)
    assert np.abs(gap).max() < 1e-9 * DELTA, gap
    return x, np.linalg.eigvals(monodromy)


def exact_period_doublings(period: float, guess, end: float, step: float = 2e-3) -> list:
    """(period, V) of each cycle of the exact law's family, from the cycle of ``period`` s
    (near ``guess``) to that of ``end`` s, with a real Floquet multiplier at -1."""
    def below(_x, multipliers):  # how far the lowest multiplier is beyond -1
        return float(np.sort(multipliers.real)[0]) + 1.0

    rows = []
    x, multipliers = exact_cycle_of_period(period, guess)
    for t in np.arange(period, end, step):
        predicted = x if len(rows) < 2 else 2 * rows[-1][1] - rows[-2][1]
        x, multipliers = exact_cycle_of_period(t, predicted)
        rows.append((t, x, below(x, multipliers)))
    found = []
    for (t0, x0, g0), (t1, x1, g1) in pairwise(rows):
        if g0 * g1 < 0:
            def g(t, t0=t0, x0=x0, t1=t1, x1=x1):
                return below(*exact_cycle_of_period(t, x0 + (x1 - x0) * (t - t0) / (t1 - t0)))
            t = brentq(g, t0, t1, xtol=1e-10)
            x, multipliers = exact_cycle_of_period(t, x0 + (x1 - x0) * (t - t0) / (t1 - t0))
            closest = multipliers[np.argmin(np.abs(multipliers + 1))]
            assert abs(closest + 1) < 1e-6  # a real multiplier at -1
            found.append((t, x[3]))
    return found


def test_period_doublings_near_the_homoclinic_persist_against_the_exact_law(continuation):
    """Between the 8.06 m/s fold and the homoclinic orbit a real Floquet multiplier of the
    exact law's cycles passes -1: twice, barely (to -1.005), at 0.406 and 0.410 s, then at
    0.539 s. whirl reports each of these period doublings (on a finer mesh than the study's:
    on its own AUTO's multipliers err by more than that dip) and judges them as they are:
    they persist as epsilon shrinks, towards the exact law's."""
    family = continuation.branch("periodic_1")
    fold = min((p for p in continuation.special_points if p.branch == "periodic_1"
                and p.point_type == PointType.LPC and 8.0 < p.parameters[0] < 8.1),
               key=lambda p: p.period)
    (orbit,) = [o for o in family.orbits if o.index == fold.index]
    top = orbit.states[np.argmax(orbit.states[:, 0])]  # theta' = 0 there: a guess
    exact = exact_period_doublings(fold.period, [top[0], top[1], top[3], fold.parameters[0]],
                                   0.56)
    assert len(exact) == 3
    for name in ("periodic_1", "periodic_2"):
        doublings = sorted((p for p in continuation.special_points
                            if p.branch == name and p.point_type == PointType.PD),
                           key=lambda p: p.period)
        assert len(doublings) == len(exact)
        for point, (period, v) in zip(doublings, exact, strict=True):
            assert not point.artefact, point.note
            assert point.parameters[0] == pytest.approx(v, abs=5e-3)
            assert point.refined[-1] == pytest.approx(v, abs=1e-3)
            assert point.period == pytest.approx(period, abs=2e-3)
    for point, (period, v) in zip(doublings, exact, strict=True):
        print(f"PD: {v:.6f} m/s, {period:.6f} s (exact law); whirl {point.parameters[0]:.6f}, "
              f"{point.refined[0]:.6f}, {point.refined[1]:.6f} at epsilon, /2, /4")
