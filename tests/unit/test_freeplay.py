"""whirl's freeplay law (../shared/models.md section 7) through the generated numpy module:
its smoothing error, no overflow at any amplitude, the describing function, and the exact
piecewise-law simulation's events."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.linalg import expm

from whirl_cli.analysis.simulate import integrate, integrate_exact
from whirl_cli.models import get_model
from whirl_cli.models.laws.freeplay import equivalent_stiffness

DELTA = math.radians(1.0)
K_OUT, K_IN = 0.4, 0.05


@pytest.fixture(scope="module")
def freeplay():
    return get_model("classical", ("freeplay", "polynomial"))


def values(delta=DELTA, epsilon=DELTA / 100, k_in=K_IN, k_out=K_OUT, **more):
    return {"K_theta": k_out, "K_psi": 0.3, "delta_theta": delta, "epsilon_theta": epsilon,
            "K_in_theta": k_in, **more}


def exact_moment(x, delta=DELTA, k_in=K_IN, k_out=K_OUT):
    """models.md 7: M_fp(x) = K_in x + (K_out - K_in) [x - delta sat(x/delta)]."""
    return k_in * x + (k_out - k_in) * (x - delta * np.clip(x / delta, -1.0, 1.0))


def generated_moment(model, x, overrides):
    """The pitch restoring moment the generated module applies at states (x, 0, 0, 0): the
    generated residual R = G - S of the linear model with K_theta = 0 (G alone) minus the
    freeplay model's, at the same parameters."""
    linear = get_model("classical")
    y = np.zeros((4, len(x)))
    y[0] = x
    shared = {k: v for k, v in overrides.items() if k in linear.parameter_names}

    def residual(m, p):
        return np.asarray(m.numeric.residual(tuple(y), m.numeric.prepare(tuple(p)))[0])

    return (residual(linear, linear.parameter_vector({**shared, "K_theta": 0.0}))
            - residual(model, model.parameter_vector(overrides)))


@pytest.mark.parametrize("epsilon_fraction", [1e-2, 1e-3])
def test_smoothed_law_error_is_largest_at_the_corners(freeplay, epsilon_fraction):
    """max |M_eps - M_fp| = (K_out - K_in) epsilon ln2 / 2, at x = +-delta (1e-6 relative),
    and nowhere larger on a fine grid over +-5 delta."""
    epsilon = DELTA * epsilon_fraction
    x = np.unique(np.r_[np.linspace(-5 * DELTA, 5 * DELTA, 20001), -DELTA, DELTA])
    error = np.abs(generated_moment(freeplay, x, values(epsilon=epsilon)) - exact_moment(x))
    bound = (K_OUT - K_IN) * epsilon * math.log(2.0) / 2
    corners = np.isin(x, [-DELTA, DELTA])
    np.testing.assert_allclose(error[corners], bound, rtol=1e-6)
    assert error.max() <= bound * (1 + 1e-6)
    assert abs(x[np.argmax(error)]) == DELTA


@pytest.mark.parametrize("epsilon_fraction", [1e-2, 1e-9])
def test_numpy_module_has_no_overflow_at_any_amplitude(freeplay, epsilon_fraction):
    """At |x| = 1e6 epsilon (and 1e6 delta) the right-hand side, Jacobian and the second and
    third derivative tensors are finite (exp may underflow to 0, harmlessly; nothing
    overflows or divides by zero), and the slope there is K_out."""
    epsilon = DELTA * epsilon_fraction
    params = freeplay.parameter_vector(values(epsilon=epsilon))
    for x in (1e6 * epsilon, -1e6 * epsilon, 1e6 * DELTA, DELTA + 1e-3 * epsilon):
        y = np.array([x, 0.0, 0.0, 0.0])
        with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
            rhs = freeplay.rhs_numpy(y, params)
            jacobian = freeplay.jacobian_numpy(y, params)
            second, third = freeplay.derivative_tensors(y, params)
        assert np.isfinite(rhs).all() and np.isfinite(jacobian).all()
        assert np.isfinite(second).all() and np.isfinite(third).all()
    y = np.array([1e6 * epsilon + DELTA, 0.0, 0.0, 0.0])
    slope = -freeplay.jacobian_numpy(y, params)[2, 0] * 0.000178  # I_y * d(theta'')/d(theta)
    linear = get_model("classical")
    aero = linear.jacobian_numpy(np.zeros(4), linear.parameter_vector(
        {"K_psi": 0.3, "K_theta": 0.0}))[2, 0] * 0.000178
    assert slope + aero == pytest.approx(K_OUT, rel=1e-9)


def _kinks(ratio: float) -> list[float]:
    """Where A sin t crosses +-delta over one period (ratio = A / delta >= 1)."""
    t = math.asin(1.0 / ratio)
    return [t, math.pi - t, math.pi + t, 2 * math.pi - t]


def test_describing_function_is_the_first_harmonic_of_the_exact_law():
    """K_eq(A) = (1/(pi A)) int_0^2pi M_fp(A sin t) sin t dt, by quadrature (1e-9)."""
    for ratio in (1.0, 1.01, 1.5, 3.0, 20.0):
        amplitude = ratio * DELTA
        harmonic, _ = quad(lambda t, a=amplitude: exact_moment(a * np.sin(t)) * np.sin(t),
                           0.0, 2 * np.pi, points=_kinks(ratio), limit=200)
        expected = harmonic / (np.pi * amplitude)
        assert equivalent_stiffness(amplitude, DELTA, K_IN, K_OUT) == pytest.approx(
            expected, rel=1e-9, abs=1e-12)
    assert equivalent_stiffness(0.5 * DELTA, DELTA, K_IN, K_OUT) == K_IN


def test_freeplay_is_linear_only_when_both_stiffnesses_agree(freeplay):
    assert not freeplay.is_linear(values())
    assert freeplay.is_linear(values(k_in=K_OUT))
    assert freeplay.canonical("K_out_theta") == "K_theta"


def _affine(model, params, piece):
    """[[A, b], [0, 0]] of the exact law's piece: y' = A y + b (the classical model with the
    exact deadband is affine on each piece)."""
    field, jacobian = model.exact_numeric.field_at(np.r_[params, piece])
    augmented = np.zeros((5, 5))
    augmented[:4, :4] = jacobian(np.zeros(4))
    augmented[:4, 4] = field(np.zeros(4))
    return augmented


def test_exact_simulation_switches_pieces_on_the_breakpoints(freeplay):
    """integrate_exact restarts at |theta| = delta; propagating the exact piecewise-affine
    solution (matrix exponentials, independent of the integrator) from the start through the
    simulation's event times puts theta on +-delta at every event to 1e-9 rad, and in the
    state the simulation restarts from."""
    params = freeplay.parameter_vector(values(k_in=0.0, V=6.7))
    start = np.array([4 * DELTA, 0.0, 0.0, 0.0])
    run = integrate_exact(freeplay, params, start, 1.0, samples=500)
    assert len(run.event_time) >= 10 and set(run.event_dof) == {0}
    np.testing.assert_allclose(np.abs(run.event_state[:, 0]), DELTA, atol=1e-14)
    state, time, piece = np.r_[start, 1.0], 0.0, 2
    for when, restart in zip(run.event_time, run.event_state, strict=True):
        state = expm(_affine(freeplay, params, piece) * (when - time)) @ state
        time = when
        assert abs(abs(state[0]) - DELTA) < 1e-9
        np.testing.assert_allclose(state[:4], restart, atol=1e-9)
        piece += 1 if restart[2] > 0 else -1
        assert piece in (0, 1, 2)


def test_whirl_models_lists_freeplay_as_whirls_law():
    from click.testing import CliRunner

    from whirl_cli.cli import cli

    done = CliRunner().invoke(cli, ["models"])
    assert done.exit_code == 0, done.output
    (line,) = [x for x in done.output.splitlines() if x.startswith("  freeplay:")]
    assert "whirl's law (models.md 7)" in line and "K_out (= the dof's stiffness)" in line


def test_exact_simulation_is_generic_and_the_smoothed_law_converges_to_it():
    """Any model, several piecewise dofs: the 6-state oscillators (full mass matrix) with
    freeplay on q1 (delta 0.1 m) and q2 (delta 0.05 m, K_in 0.2 N/m). Every event lies on its
    own dof's breakpoint; the smoothed law's trajectory (LSODA) approaches the exact one as
    epsilon shrinks: ten times smaller epsilon, at least five times closer, and within 1e-4
    of delta at epsilon = delta/1000."""
    model = get_model("oscillators", ("freeplay", "freeplay", "polynomial"))
    assert model.piecewise_dofs == (0, 1)
    deltas = np.array([0.1, 0.05])
    start = np.array([0.3, -0.2, 0.1, 0.0, 0.0, 0.0])

    def params(fraction):
        return model.parameter_vector({
            "delta_q1": deltas[0], "epsilon_q1": fraction * deltas[0], "delta_q2": deltas[1],
            "epsilon_q2": fraction * deltas[1], "K_in_q2": 0.2, "alpha": 0.02, "gamma": 0.0})

    exact = integrate_exact(model, params(1e-2), start, 20.0, samples=2000)
    assert set(exact.event_dof) == {0, 1} and len(exact.event_time) >= 6
    rows = np.arange(len(exact.event_dof))
    np.testing.assert_allclose(np.abs(exact.event_state[rows, exact.event_dof]),
                               deltas[exact.event_dof], atol=1e-14)
    gaps = []
    for fraction in (1e-2, 1e-3):
        _, smoothed = integrate(model, params(fraction), start, 20.0, samples=2000)
        gaps.append(np.abs(smoothed[:, :3] - exact.states[:, :3]).max())
    assert gaps[1] < gaps[0] / 5 and gaps[1] < 1e-4 * deltas.min(), gaps
