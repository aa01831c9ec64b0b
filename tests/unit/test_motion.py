"""Classification of settled motion by simulation (whirl_cli.analysis.motion, .lyapunov) on
systems whose answer is known in closed form or from the literature, and on the classical
whirl model at a stable LCO of hardening case 2 (AUTO's period from the reference file)."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from whirl_cli.analysis.motion import classify, classify_model
from whirl_cli.models import get_model

REFERENCE = Path(__file__).resolve().parents[1] / "regression" / "references" / "hardening_case2.h5"

#: The largest Lyapunov exponent of Lorenz (10, 28, 8/3) (Sprott, Chaos and Time-Series
#: Analysis, 2003: 0.9056).
LORENZ_EXPONENT = 0.9056


def lorenz(sigma=10.0, rho=28.0, beta=8.0 / 3.0):
    def field(y):
        x, v, z = y
        return np.array([sigma * (v - x), x * (rho - z) - v, x * v - beta * z])

    def jacobian(y):
        x, v, z = y
        return np.array([[-sigma, sigma, 0.0], [rho - z, -1.0, -x], [v, x, -beta]])

    return field, jacobian


def hopf(mu, omega, shear):
    """z' = (mu + i omega) z - (1 + i shear) |z|^2 z: a stable cycle |z| = sqrt(mu) turning at
    omega - shear mu rad/s."""
    def field(y):
        x, v = y
        r2 = x * x + v * v
        return np.array([mu * x - omega * v - r2 * (x - shear * v),
                         omega * x + mu * v - r2 * (v + shear * x)])

    def jacobian(y):
        x, v = y
        r2 = x * x + v * v
        a, b = x - shear * v, v + shear * x
        return np.array([[mu - r2 - 2 * x * a, -omega + shear * r2 - 2 * v * a],
                         [omega - shear * r2 - 2 * x * b, mu - r2 - 2 * v * b]])

    return field, jacobian


@pytest.fixture(scope="module")
def lorenz_motion():
    field, jacobian = lorenz()
    return classify(field, jacobian, [1.0, 1.0, 1.0], transient=20.0, duration=400.0, dt=0.02,
                    rtol=1e-6)


def test_lorenz_largest_lyapunov_exponent(lorenz_motion):
    assert lorenz_motion.lyapunov == pytest.approx(LORENZ_EXPONENT, rel=0.02)
    # the confidence: small, and honest (the literature value within three standard errors)
    assert 0 < lorenz_motion.lyapunov_error < 0.05 * LORENZ_EXPONENT
    assert abs(lorenz_motion.lyapunov - LORENZ_EXPONENT) < 3 * lorenz_motion.lyapunov_error


def test_lorenz_is_chaotic(lorenz_motion):
    assert lorenz_motion.kind == "chaotic", lorenz_motion.evidence
    assert lorenz_motion.multiplicity == 0
    assert lorenz_motion.broadband > 0.1  # the spectrum is not a few lines


def test_hopf_cycle_is_periodic_at_its_closed_form_frequency():
    mu, omega, shear = 1.0, 2 * np.pi, 0.5
    field, jacobian = hopf(mu, omega, shear)
    motion = classify(field, jacobian, [0.1, 0.0], transient=20.0, duration=60.0, dt=0.025,
                      section_state=0)
    assert motion.kind == "periodic", motion.evidence
    assert motion.multiplicity == 1
    assert abs(motion.lyapunov) < 1e-3
    assert motion.frequencies[0] == pytest.approx((omega - shear * mu) / (2 * np.pi), rel=1e-5)
    # section x = mean(x) (0 but for the window's part period) rising: on the circle of
    # radius sqrt(mu), at y = -sqrt(mu - x^2)
    level = motion.section[:, 0]
    assert np.ptp(level) < 1e-12 and abs(level[0]) < 0.01
    assert np.abs(motion.section[:, 1] + np.sqrt(mu - level**2)).max() < 1e-4


def test_a_cycle_faster_than_the_window_resolves_is_sampled_again_finer():
    """A 0.92 Hz cycle sampled every 0.6 s (Nyquist 0.83 Hz) reads as 0.75 Hz, its alias; the
    window's power near its Nyquist frequency has it simulated again finer, and the cycle is
    periodic at its closed-form frequency (1e-3)."""
    mu, omega, shear = 1.0, 2 * np.pi, 0.5
    field, jacobian = hopf(mu, omega, shear)
    motion = classify(field, jacobian, [0.1, 0.0], transient=20.0, duration=60.0, dt=0.6,
                      section_state=0)
    assert motion.kind == "periodic", motion.evidence
    assert motion.frequencies[0] == pytest.approx((omega - shear * mu) / (2 * np.pi), rel=1e-3)
    assert "finer" in motion.evidence


def test_a_cycle_not_yet_reached_is_periodic_and_said_unsettled():
    # attraction at -2 mu = -0.1 1/s: after 10 s the radius is still 0.16 of the cycle's 0.224
    field, jacobian = hopf(0.05, 2 * np.pi, 0.0)
    motion = classify(field, jacobian, [0.05, 0.0], transient=10.0, duration=30.0, dt=0.025,
                      section_state=0)
    assert motion.kind == "periodic", motion.evidence
    assert "not settled" in motion.evidence
    assert motion.frequencies[0] == pytest.approx(1.0, rel=1e-4)  # omega / 2 pi at any radius


def uncoupled(first, second):
    """(field, jacobian) of two uncoupled 2-state oscillators, each a (field, jacobian) pair."""
    def field(y):
        return np.r_[first[0](y[:2]), second[0](y[2:])]

    def jacobian(y):
        block = np.zeros((4, 4))
        block[:2, :2], block[2:, 2:] = first[1](y[:2]), second[1](y[2:])
        return block

    return field, jacobian


def test_two_incommensurate_oscillators_are_quasi_periodic_with_both_frequencies():
    field, jacobian = uncoupled(hopf(1.0, 2 * np.pi, 0.5),
                                hopf(0.5, 2 * np.pi * np.sqrt(2.0), 0.0))
    motion = classify(field, jacobian, [0.1, 0.0, 0.1, 0.0], transient=20.0, duration=60.0,
                      dt=0.025)
    assert motion.kind == "quasi-periodic", motion.evidence
    assert abs(motion.lyapunov) < 1e-3
    expected = sorted([(2 * np.pi - 0.5) / (2 * np.pi), np.sqrt(2.0)])
    assert sorted(motion.frequencies) == pytest.approx(expected, rel=1e-3)
    assert motion.section_dimension == pytest.approx(1.0, abs=0.3)  # a closed curve


def test_damped_linear_oscillator_is_an_equilibrium_decaying_at_its_damping():
    omega, zeta = 2 * np.pi, 0.04  # decay rate zeta omega = 0.251 1/s

    def field(y):
        return np.array([y[1], -omega**2 * y[0] - 2 * zeta * omega * y[1]])

    def jacobian(_y):
        return np.array([[0.0, 1.0], [-omega**2, -2 * zeta * omega]])

    motion = classify(field, jacobian, [1.0, 0.0], transient=5.0, duration=30.0, dt=0.01,
                      scale=[1.0, omega])
    assert motion.kind == "equilibrium", motion.evidence
    assert motion.lyapunov == pytest.approx(-zeta * omega, abs=0.03)


def test_divergent_system_is_reported_not_raised():
    def field(y):  # an unstable focus: grows as e^(0.5 t)
        return np.array([0.5 * y[0] - 3.0 * y[1], 3.0 * y[0] + 0.5 * y[1]])

    def jacobian(_y):
        return np.array([[0.5, -3.0], [3.0, 0.5]])

    motion = classify(field, jacobian, [1.0, 0.0], transient=10.0, duration=20.0, dt=0.01,
                      bound=1e3)
    assert motion.kind == "diverged"
    assert np.isnan(motion.lyapunov)
    assert "bound" in motion.evidence


HARDENING_CASE2 = {"K_psi": 0.3, "K2_theta": 10.0}


def auto_stable_orbit(k1: float) -> tuple[float, float]:
    """(K1, period s) of the stable orbit of AUTO's first periodic branch nearest ``k1``."""
    with h5py.File(REFERENCE) as f:
        branch = f["continuations/k1/branches/periodic_1"]
        parameters, period = branch["parameters"][:, 0], branch["period"][:]
        stable = branch["stable"][:]
    row = int(np.argmin(np.where(stable, np.abs(parameters - k1), np.inf)))
    return float(parameters[row]), float(period[row])


def test_classical_model_at_a_stable_lco_is_periodic_at_autos_period():
    k1, period = auto_stable_orbit(0.24)
    motion = classify_model(get_model("classical"), {**HARDENING_CASE2, "K_theta": k1},
                            [0.08, 0.0, 0.0, 0.0], transient_periods=60)
    assert motion.kind == "periodic", motion.evidence
    assert abs(motion.lyapunov) < 0.01  # 1/s; an e-fold per 100 s, at 4.4 Hz
    assert motion.frequencies[0] == pytest.approx(1.0 / period, rel=1e-3)


def test_classical_model_far_from_any_lco_is_an_equilibrium():
    model = get_model("classical")
    overrides = {**HARDENING_CASE2, "K_theta": 0.45}
    motion = classify_model(model, overrides, [0.05, 0.0, 0.0, 0.0])
    assert motion.kind == "equilibrium", motion.evidence
    slowest = np.linalg.eigvals(model.jacobian_numpy(np.zeros(4),
                                                     model.parameter_vector(overrides))).real.max()
    assert motion.lyapunov == pytest.approx(slowest, abs=max(0.15, 3 * motion.lyapunov_error))


# ----------------------------------------------------------------------------- odeint path
def test_odeint_path_gives_the_lorenz_exponent():
    """classify_model's integrator (LSODA through odeint, the tangent continued chunk by
    chunk) on Lorenz: the literature exponent to 2 %."""
    field, jacobian = lorenz()
    motion = classify(field, jacobian, [1.0, 1.0, 1.0], transient=20.0, duration=400.0,
                      dt=0.02, rtol=1e-6, method="odeint")
    assert motion.kind == "chaotic", motion.evidence
    assert motion.lyapunov == pytest.approx(LORENZ_EXPONENT, rel=0.02)


def test_odeint_path_on_a_cycle_has_a_zero_exponent_and_the_same_bits_every_run():
    field, jacobian = hopf(1.0, 2 * np.pi, 0.5)
    motion, again = (classify(field, jacobian, [0.1, 0.0], transient=20.0, duration=60.0,
                              dt=0.025, section_state=0, method="odeint") for _ in range(2))
    assert motion.kind == "periodic", motion.evidence
    assert motion.lyapunov == again.lyapunov and motion.evidence == again.evidence
    assert np.array_equal(motion.section, again.section)
    assert abs(motion.lyapunov) < 1e-3
    assert motion.frequencies[0] == pytest.approx((2 * np.pi - 0.5) / (2 * np.pi), rel=1e-5)


def near_resonance():
    """Two uncoupled Hopf oscillators at 1 Hz and 1/12 Hz + 1.5e-3 Hz: a torus whose second
    frequency is 0.018 Hz off a 1:12 resonance (f_a - 12 f_b = -0.018 Hz)."""
    return uncoupled(hopf(1.0, 2 * np.pi, 0.0), hopf(1.0, 2 * np.pi * (1 / 12 + 1.5e-3), 0.0))


@pytest.mark.parametrize("method", ["odeint", "DOP853"])
def test_a_torus_near_resonance_needs_the_longer_window_to_be_quasi_periodic(method):
    """In 60 s (frequency bins of 1/60 Hz) 12 f_b is within 1.5 bins of f_a, so the spectrum
    reads as harmonics of f_b while the section (at f_a's returns, rotating by f_b / f_a) is
    a closed curve; the window doubled once resolves the two bases."""
    field, jacobian = near_resonance()
    options = dict(transient=10.0, duration=60.0, dt=0.025, section_state=0, method=method)
    short = classify(field, jacobian, [0.5, 0.0, 0.5, 0.0], extend=0, **options)
    assert short.kind == "periodic" and "did not repeat" in short.evidence, short.evidence
    assert short.multiplicity == 0
    longer = classify(field, jacobian, [0.5, 0.0, 0.5, 0.0], extend=1, **options)
    assert longer.kind == "quasi-periodic", longer.evidence
    # the second from the spectrum: within a tenth of a bin of the doubled window (1/120 Hz)
    assert sorted(longer.frequencies) == pytest.approx([1 / 12 + 1.5e-3, 1.0], abs=0.1 / 120)
    assert abs(longer.lyapunov) < 1e-3
    assert len(longer.section) > len(short.section)  # twice the returns
    assert "window doubled to 120 s" in longer.evidence


def test_a_trajectory_at_rest_at_a_stable_point_ends_the_transient_early():
    """Damped oscillator (decay zeta omega = 0.25 1/s) from amplitude 1: at rest (spread below
    1e-6 over a quarter window) after ln(1e6) / 0.25 = 55 s, before the 200 s transient ends;
    the class and exponent are the full run's."""
    omega, zeta = 2 * np.pi, 0.04

    def field(y):
        return np.array([y[1], -omega**2 * y[0] - 2 * zeta * omega * y[1]])

    def jacobian(_y):
        return np.array([[0.0, 1.0], [-omega**2, -2 * zeta * omega]])

    motion = classify(field, jacobian, [1.0, 0.0], transient=200.0, duration=30.0, dt=0.01,
                      scale=[1.0, omega], method="odeint")
    assert motion.kind == "equilibrium", motion.evidence
    assert motion.lyapunov == pytest.approx(-zeta * omega, abs=0.03)
    ended = float(motion.evidence.split("the transient ended at t = ")[1].split(" s")[0])
    assert 55.0 < ended < 80.0
