"""The gimballed model at a tiltrotor gimbal (1.05 per rev) on the real AUTO-07p, every number
checked against a computation written here (tests/gimballed_exact.py's matrices, numpy
eigenvalues, scipy simulation and monodromy matrix), never against whirl's own output.

Study ``studies/gimballed/tiltrotor_gimbal_combined_airspeed.yaml``: K_beta = 0.008446 N m/rad,
the thesis' combined law scaled onto both gimbal dofs, linear nacelle, airspeed 0.2-4 m/s.
"""

from __future__ import annotations

import tempfile
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from whirl_cli.pipeline import run_study
from whirl_cli.plots.files import study_figures
from whirl_cli.results import MotionKind, PointType, Spacing
from whirl_cli.study import load_study

from ..conftest import ROOT
from ..gimballed_exact import matrices

pytestmark = pytest.mark.auto

STUDY = ROOT / "studies" / "gimballed" / "tiltrotor_gimbal_combined_airspeed.yaml"
VALUES = {"K_theta": 0.4, "K_psi": 0.3, "K_beta": 0.008446}  # K_theta: the datum
#: cubic and quintic coefficients per dof (theta, psi, beta_y, beta_z): the study's gimbal laws
GIMBAL_LAWS = (np.array([0, 0, -0.21, -0.21]), np.array([0, 0, 7.4, 7.4]))
#: the explore study's: the combined pitch law, hardening cubic gimbal springs
PITCH_LAWS = (np.array([-10, 0, 0.5, 0.5]), np.array([350, 0, 0, 0]))
#: whirl's (thesis) frame to the derivation frame of gimballed_exact: psi, beta_z negated
FRAME = np.array([1, -1, 1, -1, 1, -1, 1, -1], dtype=float)


@cache
def computed():
    return run_study(load_study(STUDY), Path(tempfile.mkdtemp(prefix="whirl-test-")), jobs=2)


def _continuation():
    (continuation,) = computed().continuations
    return continuation


def _points(kind: PointType):
    return [p for p in _continuation().special_points if p.point_type == kind]


def _linear(v: float, values: dict = VALUES) -> np.ndarray:
    """First-order matrix of the linear model (derivation frame) at airspeed ``v``."""
    mass, damping, stiffness = matrices({**values, "V": v})
    minv = np.linalg.inv(mass)
    return np.block([[np.zeros((4, 4)), np.eye(4)], [-minv @ stiffness, -minv @ damping]])


def _growth(v: float) -> float:
    return float(np.linalg.eigvals(_linear(v)).real.max())


def _field(v: float, laws=GIMBAL_LAWS):
    """Right-hand side and Jacobian of the nonlinear model (derivation frame, whose odd laws
    are the thesis frame's) with the polynomial ``laws`` (cubic, quintic coefficients)."""
    mass, _, _ = matrices({**VALUES, "V": v})
    minv = np.linalg.inv(mass)
    linear = _linear(v)
    cubic, quintic = laws

    def f(_t, y):
        q = y[:4]
        square = q * q
        result = linear @ y
        result[4:] -= minv @ (q * square * (cubic + quintic * square))
        return result

    def jac(y):
        square = y[:4] ** 2
        slope = square * (3 * cubic + 5 * quintic * square)
        result = linear.copy()
        result[4:, :4] -= minv * slope  # minv @ diag(slope)
        return result
    return f, jac


def _onset() -> tuple[float, float]:
    """(V, omega) where the numpy eigenvalues' largest real part crosses zero."""
    v = brentq(_growth, 0.5, 1.5, xtol=1e-10)
    eigenvalues = np.linalg.eigvals(_linear(v))
    return v, float(abs(eigenvalues[np.argmax(eigenvalues.real)].imag))


def test_the_hopf_point_is_the_numpy_onset():
    """AUTO's one Hopf point is the linear onset (1e-4) at its frequency (1e-3), and the
    gimbal frequency of the study is 1.05 per rev."""
    v, omega = _onset()
    (hopf,) = _points(PointType.HB)
    print(f"\n  onset: numpy {v:.6f} m/s, {omega:.4f} rad/s; AUTO {hopf.parameters[0]:.6f}, "
          f"period {hopf.period:.5f} s")
    assert hopf.parameters[0] == pytest.approx(v, rel=1e-4)
    assert hopf.period == pytest.approx(2 * np.pi / omega, rel=1e-3)
    assert np.sqrt(1 + VALUES["K_beta"] / (5.15e-5 * 40.0**2)) == pytest.approx(1.05, abs=1e-4)


def _unstable_mode(v: float, values: dict) -> tuple[complex, np.ndarray]:
    eigenvalues, vectors = np.linalg.eig(_linear(v, values))
    k = int(np.argmax(eigenvalues.real + 1e-6 * np.sign(eigenvalues.imag)))
    return eigenvalues[k], vectors[:4, k]


def _sense(eigenvalue: complex, y: complex, z: complex) -> float:
    """> 0 and < 0 for the two senses of the path (y, z) of a mode."""
    return float(np.imag(np.conj(y) * z) * np.sign(eigenvalue.imag))


def test_the_unstable_mode_is_the_gimbal_whirling_against_the_classical_flutter_sense():
    """Up to 9 m/s one pair is unstable: mostly gimbal (kinetic energy of beta over theta, psi)
    whose disc normal whirls in the sense of the classical model's flutter mode (BW, the thesis;
    K_beta = 1e6 here), as whirl's linear sweep labels it; no forward-whirl mode goes
    unstable."""
    bw, vector = _unstable_mode(9.0, {**VALUES, "K_beta": 1e6})
    reference = _sense(bw, vector[1], -vector[0])  # the hub path (-aR psi, -aR theta), thesis
    (sweep,) = computed().linear_sweeps
    checked = 0
    for row, v in enumerate(sweep.values):
        if v == 0:  # the strip theory's limit mu -> 0, not written out here
            continue
        eigenvalues = np.linalg.eigvals(_linear(v))
        assert np.sum(eigenvalues.real > 0) in (0, 2)
        if _growth(v) <= 1e-6:
            continue
        value, q = _unstable_mode(v, VALUES)
        mass = matrices({**VALUES, "V": v})[0]
        energy = [np.real(np.conj(q[s]) @ mass[s, s] @ q[s]) for s in (slice(0, 2), slice(2, 4))]
        assert energy[1] > energy[0]
        disc = _sense(value, q[1] + q[3], -(q[0] + q[2]))  # (-(psi+beta_z), -(theta+beta_y))
        assert np.sign(disc) == np.sign(reference)
        k = int(np.argmin(np.abs(sweep.eigenvalues[row] - value)))
        assert abs(sweep.eigenvalues[row, k] - value) < 1e-6 * abs(value)
        assert (sweep.mode_group[row, k], sweep.whirl[row, k]) == ("gimbal", "BW")
        checked += 1
    assert checked > 100


def _settle(v: float, beta_deg: float, duration: float) -> np.ndarray:
    """The states over the last quarter of a scipy simulation from a gimbal tilt."""
    f, _ = _field(v)
    y0 = np.zeros(8)
    y0[2] = np.radians(beta_deg)
    sol = solve_ivp(f, (0, duration), y0, method="LSODA", rtol=1e-9, atol=1e-12,
                    t_eval=np.linspace(0.75 * duration, duration, 20001))
    return sol.t, sol.y


def test_stable_cycles_exist_below_the_linear_onset():
    """The Hopf point is subcritical and the family turns back at a fold of cycles below the
    onset: between the fold and the onset a 10 deg gimbal tilt settles (scipy) on a cycle of
    AUTO's amplitude (2 %) and period (1 %) while a 0.5 deg one decays; below the fold the
    10 deg one decays too."""
    (hopf,) = _points(PointType.HB)
    fold = min(_points(PointType.LPC), key=lambda p: p.parameters[0])
    assert fold.parameters[0] < hopf.parameters[0] - 0.05
    branch = next(b for b in _continuation().branches if b.name == fold.branch)
    v = fold.parameters[0] + 0.5 * (hopf.parameters[0] - fold.parameters[0])
    assert _growth(v) < 0
    stable = np.flatnonzero(branch.stable & (np.arange(len(branch)) > fold.index))
    row = stable[np.argmin(np.abs(branch.parameters[stable, 0] - v))]
    v = float(branch.parameters[row, 0])
    t, y = _settle(v, 10.0, 400.0)
    amplitude = np.abs(y[2]).max()
    crossings = t[1:][(y[6, :-1] < 0) & (y[6, 1:] >= 0)]
    print(f"\n  V = {v:.4f}: scipy beta_y {np.degrees(amplitude):.3f} deg, period "
          f"{np.diff(crossings).mean():.4f} s; AUTO {np.degrees(branch.state_max[row, 2]):.3f}, "
          f"{branch.period[row]:.4f}")
    assert amplitude == pytest.approx(branch.state_max[row, 2], rel=0.02)
    assert np.diff(crossings).mean() == pytest.approx(branch.period[row], rel=0.01)
    assert np.abs(_settle(v, 0.5, 200.0)[1][2]).max() < np.radians(0.05)
    below = fold.parameters[0] - 0.03
    assert np.abs(_settle(below, 10.0, 400.0)[1][2]).max() < np.radians(0.5)


def test_floquet_multipliers_are_the_monodromy_matrix_eigenvalues():
    """At every stored orbit but the folds' (among them, at V = 0.92 m/s, the unstable cycle
    between the fold and the onset) the eigenvalues of the monodromy matrix, integrated with
    scipy over AUTO's orbit, are AUTO's multipliers (1e-3)."""
    (continuation,) = computed().continuations
    branch = next(b for b in continuation.branches if b.name.startswith("periodic"))
    largest = []
    for orbit in branch.orbits:
        if orbit.point_type == PointType.LPC:
            continue  # a Jordan block at 1: its eigenvalues move by the root of the error
        f, jac = _field(float(orbit.parameters[0]))

        def variational(t, z, f=f, jac=jac):
            y, phi = z[:8], z[8:].reshape(8, 8)
            return np.concatenate([f(t, y), (jac(y) @ phi).ravel()])
        y0 = orbit.states[0] * FRAME
        sol = solve_ivp(variational, (0, orbit.period), np.concatenate([y0, np.eye(8).ravel()]),
                        method="DOP853", rtol=1e-11, atol=1e-12)
        ours = np.linalg.eigvals(sol.y[8:, -1].reshape(8, 8))
        auto = branch.eigenvalues[orbit.index]
        print(f"\n  V = {orbit.parameters[0]:.4f}: |mu| ours {np.round(np.sort(np.abs(ours)), 4)}, "
              f"AUTO {np.round(np.sort(np.abs(auto)), 4)}")
        for mu in auto[np.isfinite(auto)]:
            assert np.min(np.abs(ours - mu)) < 1e-3 * max(1.0, abs(mu))
        largest.append(np.abs(ours).max())
    assert max(largest) > 1.05 and min(largest) < 1 + 1e-3


LINEAR_STUDY = ROOT / "studies" / "gimballed" / "tiltrotor_linear_onset.yaml"


@cache
def linear_computed():
    return run_study(load_study(LINEAR_STUDY), Path(tempfile.mkdtemp(prefix="whirl-test-")),
                     jobs=2)


def test_the_hopf_locus_is_the_numpy_onset_across_tiltrotor_gimbals():
    """Every point of the Hopf locus in (V, K_beta), from 1.02/rev to beyond the thesis'
    K_beta = 10 (11/rev), is where the numpy eigenvalues' largest real part crosses zero at its
    K_beta (1e-4), and the locus spans the whole K_beta range (0.61 m/s at 1.02/rev, 1.36 m/s
    at 1.10/rev, 7.31 m/s at 11/rev); over 1.02-1.10/rev alone it has points enough to draw."""
    (continuation,) = linear_computed().continuations
    loci = [b for b in continuation.branches if b.name.startswith("hopf")]
    k_beta = np.concatenate([b.parameters[:, 1] for b in loci])
    assert k_beta.min() == pytest.approx(0.0033, abs=1e-6)
    assert k_beta.max() == pytest.approx(12.0, abs=1e-6)
    assert np.count_nonzero(k_beta <= 0.0173) > 20
    checked = 0
    for branch in loci:
        for v, kb in branch.parameters[::3, :2]:
            values = {**VALUES, "K_psi": 0.3, "K_beta": float(kb)}
            onset = brentq(lambda x, values=values: np.linalg.eigvals(
                _linear(x, values)).real.max(), 0.2, 8.9, xtol=1e-10)
            assert v == pytest.approx(onset, rel=1e-4)
            checked += 1
    assert checked > 10
    thesis = [p for p in continuation.special_points if p.point_type == PointType.HB
              and p.parameters[1] == pytest.approx(10.0)]
    assert [p.parameters[0] for p in thesis] == pytest.approx([brentq(
        lambda x: np.linalg.eigvals(_linear(x, {**VALUES, "K_beta": 10.0})).real.max(),
        5.0, 8.9, xtol=1e-10)], rel=1e-4)


def test_the_onset_map_draws_k_beta_on_a_log_axis_over_the_stored_log_grid():
    """The study's grid samples K_beta log from 1.02/rev to beyond 11/rev: its map draws K_beta
    (y) on a log axis over that range and V (x) linear, the Hopf locus drawn across it."""
    import matplotlib.pyplot as plt

    result = linear_computed()
    grid = result.linear_grid
    assert grid.x_parameter == "K_beta" and grid.x_spacing == Spacing.LOG
    ratios = grid.x[1:] / grid.x[:-1]
    np.testing.assert_allclose(ratios, ratios[0], rtol=1e-12)
    ((_, figure), *_) = study_figures(result, ("boundary",), "s")
    try:
        ax = figure.axes[0]
        assert (ax.get_xscale(), ax.get_yscale()) == ("linear", "log")
        low, high = ax.get_ylim()
        assert low == pytest.approx(0.0033) and high == pytest.approx(12.0)
        locus = max((line.get_ydata() for line in ax.lines), key=np.ptp)
        assert min(locus) < 0.0034 and max(locus) > 10.0
    finally:
        plt.close(figure)


EXPLORE_STUDY = ROOT / "studies" / "gimballed" / "tiltrotor_combined_airspeed.yaml"


def _lyapunov(v: float, transient: float, steps: int) -> float:
    """Largest Lyapunov exponent (1/s, Benettin: a tangent vector renormalised every 1 s) from
    the explore's default start, pitch at 2 deg."""
    f, jac = _field(v, PITCH_LAWS)
    y = np.zeros(8)
    y[0] = np.radians(2.0)
    y = solve_ivp(f, (0, transient), y, method="DOP853", rtol=1e-8, atol=1e-11).y[:, -1]
    d = np.full(8, 8 ** -0.5)
    total = 0.0

    def tangent(t, z):
        return np.concatenate([f(t, z[:8]), jac(z[:8]) @ z[8:]])
    for _ in range(steps):
        z = solve_ivp(tangent, (0, 1.0), np.concatenate([y, d]), method="DOP853", rtol=1e-8,
                      atol=1e-11).y[:, -1]
        y, growth = z[:8], np.linalg.norm(z[8:])
        total, d = total + np.log(growth), z[8:] / growth
    return total / steps


#: the explore values the tests look at: each is classified on its own (forked, from the same
#: start), so one run of the study with both gives what a run with either alone would
EXPLORED = (5.0, 8.0)


@cache
def _explored_run():
    """The shipped explore study run with ``explore`` at :data:`EXPLORED` alone (a copy): its
    continuation, the classification at each value."""
    directory = Path(tempfile.mkdtemp(prefix="whirl-test-"))
    copy = directory / "explore.yaml"
    text = EXPLORE_STUDY.read_text()
    assert "explore: [2.0, 5.0, 6.0, 7.0, 8.0, 8.8]" in text
    copy.write_text(text.replace("explore: [2.0, 5.0, 6.0, 7.0, 8.0, 8.8]",
                                 f"explore: {list(EXPLORED)}"))
    (continuation,) = run_study(load_study(copy), directory, jobs=2).continuations
    assert [e.value for e in continuation.explorations] == list(EXPLORED)
    return continuation, dict(zip(EXPLORED, continuation.explorations, strict=True))


def _explored(value: float):
    """(the explore study's continuation, its classification at ``value``)."""
    continuation, found = _explored_run()
    return continuation, found[value]


def test_explore_finds_chaos_where_the_motion_has_a_positive_lyapunov_exponent():
    """At V = 8 m/s the explore calls the motion chaotic; a Benettin estimate written here
    (10 s transient, 30 s of tangent growth) is positive and within 40 % of whirl's exponent."""
    _, chaotic = _explored(8.0)
    ours = _lyapunov(8.0, 10.0, 30)
    print(f"\n  V = 8: whirl {chaotic.kind}, lambda {chaotic.lyapunov:.3f}; ours {ours:.3f} 1/s")
    assert chaotic.kind == "chaotic"
    assert ours > 0.5
    assert chaotic.lyapunov == pytest.approx(ours, rel=0.4)


def _pitch_spectrum(v: float) -> tuple[np.ndarray, np.ndarray]:
    """(frequencies, relative amplitudes) of the spectral lines of pitch above 1e-2 of the
    largest, of a scipy simulation from the explore's start (60 s after 40 s)."""
    f, _ = _field(v, PITCH_LAWS)
    y0 = np.zeros(8)
    y0[0] = np.radians(2.0)
    step = 2e-3
    t = np.arange(40.0, 100.0, step)
    theta = solve_ivp(f, (0, 100.0), y0, method="DOP853", rtol=1e-8, atol=1e-11,
                      t_eval=t).y[0]
    power = np.abs(np.fft.rfft((theta - theta.mean()) * np.hanning(len(t))))
    freq = np.fft.rfftfreq(len(t), step)
    lines = [k for k in range(1, len(power) - 1) if power[k] >= power[k - 1]
             and power[k] >= power[k + 1] and power[k] > 1e-2 * power.max()]
    return freq[lines], power[lines] / power.max()


def test_at_5_m_s_the_motion_settles_on_the_cycle_auto_continues():
    """At V = 5 m/s a scipy simulation from the explore's start is periodic: every spectral
    line of pitch is a harmonic of the strongest (within 2 bins), which is the frequency of
    AUTO's stable cycle there (2 bins)."""
    continuation, _ = _explored(5.0)
    family = next(b for b in continuation.branches if b.name == "periodic_1")
    row = int(np.argmin(np.abs(family.parameters[:, 0] - 5.0)))
    assert family.stable[row] and abs(family.parameters[row, 0] - 5.0) < 0.05
    freq, amplitude = _pitch_spectrum(float(family.parameters[row, 0]))
    base = freq[np.argmax(amplitude)]
    print(f"\n  V = 5: scipy lines {np.round(freq, 3)} Hz; AUTO 1/T = "
          f"{1 / family.period[row]:.3f}")
    assert base == pytest.approx(1 / family.period[row], abs=2 / 60.0)
    assert np.all(np.abs(freq / base - np.round(freq / base)) * base < 2 / 60.0)


def test_explore_calls_the_cycle_at_5_m_s_periodic():
    """The explore's class at V = 5 m/s is the simulation's above: periodic at AUTO's
    frequency (1 %). Its first window, sampled at the origin's whirl period / 40 (1.75 s / 40),
    is too coarse for this 3.9 Hz cycle and its harmonics: it is sampled again finer (the
    aliased lines read as a second frequency: quasi-periodic)."""
    continuation, found = _explored(5.0)
    family = next(b for b in continuation.branches if b.name == "periodic_1")
    row = int(np.argmin(np.abs(family.parameters[:, 0] - 5.0)))
    print(f"\n  V = 5: {found.evidence}")
    assert found.kind == MotionKind.PERIODIC
    assert found.frequencies[0] == pytest.approx(1 / family.period[row], rel=0.01)
    assert "finer" in found.evidence
