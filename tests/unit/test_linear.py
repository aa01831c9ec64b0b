"""Linear analysis against the reference numbers of ../shared/models.md section 4 and
../shared/science.md (thesis chapter 3)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.polynomial import polynomial as P
from scipy.optimize import brentq

from whirl_cli.analysis import linear
from whirl_cli.models import get_model

from .linear_datum import DAMPING, I_X, I_Y, OMEGA, aerodynamic_coefficients


@pytest.fixture(scope="module")
def model():
    return get_model("classical")


def test_linear_onset_at_datum(model):
    """BW damping crosses zero at V = 7.764 m/s (thesis: ~7.8 m/s, +/- 0.1)."""
    (onset,) = linear.critical_points(model, {}, "V", 0.0, 10.0)
    assert onset.kind == "hopf"
    assert onset.value == pytest.approx(7.8, abs=0.1)
    assert onset.value == pytest.approx(7.764, abs=0.001)
    assert onset.frequency == pytest.approx(33.4, abs=0.1)


def test_airspeed_sweep_trends(model):
    sweep = linear.sweep(model, {}, "V", np.array([0.0, 4.0, 9.0]))
    upper = sweep.eigenvalues.imag > 0
    zeta = sweep.damping_ratio[upper].reshape(3, 2)  # columns: BW (low freq), FW
    freq = sweep.frequency[upper].reshape(3, 2)
    whirl = sweep.whirl[upper].reshape(3, 2)
    assert zeta[0, 0] == pytest.approx(0.1190, abs=1e-4) == zeta[0, 1]  # equal at V = 0
    assert zeta[:, 1] == pytest.approx([0.119, 0.138, 0.204], abs=1e-3)  # FW stabilises
    assert zeta[2, 0] < 0  # BW has fluttered by 9 m/s
    assert np.all(whirl[:, 0] == "BW") and np.all(whirl[:, 1] == "FW")
    assert np.all(np.diff(freq, axis=0) < 0)  # both frequencies fall with V
    assert np.all(freq[:, 1] - freq[:, 0] > 20)  # and stay well apart


def test_backward_whirl_has_theta_in_phase_with_psi_dot(model):
    """science.md: in the thesis convention a BW mode has theta and psi_dot in phase."""
    eigenvalues, vectors = np.linalg.eig(model.jacobian_numpy(np.zeros(4),
                                                              model.parameter_vector()))
    k = int(np.argmin(np.where(eigenvalues.imag > 0, eigenvalues.imag, np.inf)))  # BW mode
    theta, psi_dot = vectors[0, k], vectors[3, k]
    assert np.cos(np.angle(psi_dot / theta)) > 0.99
    labels = linear.whirl_direction(model, eigenvalues[None, :], vectors[None, :, :])[0]
    assert labels[k] == "BW"


# --- an independent linear analysis: models.md 2.2 closed forms and 2.3 matrices, by hand ----
# (the datum and k_d, k_c, c_a: linear_datum.py)
K_D, K_C, C_A = aerodynamic_coefficients()


def quartic(k_theta: float, k_psi: float) -> np.ndarray:
    """(a4, a3, a2, a1, 1): det(M s^2 + C s + K) / (I_y I_z) of models.md 2.3, lowest power
    first, with M = diag(I_y, I_z), C = [[C_t + c_a, -I_x W], [I_x W, C_p + c_a]],
    K = [[K_t - k_d, k_c], [-k_c, K_p - k_d]]."""
    pitch = [k_theta - K_D, DAMPING + C_A, I_Y]
    yaw = [k_psi - K_D, DAMPING + C_A, I_Y]
    coupling = [-K_C, I_X * OMEGA]  # the off-diagonal product is -(I_x W s - k_c)^2
    coefficients = P.polyadd(P.polymul(pitch, yaw), P.polymul(coupling, coupling))
    return coefficients / coefficients[-1]


def hurwitz(k_theta: float, k_psi: float) -> float:
    """a1 a2 a3 - a3^2 - a1^2 a4: zero where the quartic has a root pair on the imaginary
    axis (then it factors as (s^2 + a3/a1)(s^2 + a1 s + a1 a4/a3))."""
    a4, a3, a2, a1, _ = quartic(k_theta, k_psi)
    return a1 * a2 * a3 - a3 * a3 - a1 * a1 * a4


def independent_critical_points(k_psi: float, lower: float = -0.3, upper: float = 0.5
                                ) -> list[tuple[str, float, float]]:
    """(kind, K_theta, frequency) in order: the branch point from the closed form of models.md
    2.4 and the Hopf points from the Routh-Hurwitz condition, solved with brentq."""
    found = []
    branch_point = K_D - K_C ** 2 / (k_psi - K_D)
    if lower <= branch_point <= upper:
        found.append(("branch_point", branch_point, 0.0))
    grid = np.linspace(lower, upper, 801)
    values = np.array([hurwitz(k, k_psi) for k in grid])
    for k in np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:])):
        root = brentq(hurwitz, grid[k], grid[k + 1], args=(k_psi,), xtol=1e-14)
        a4, a3, a2, a1, _ = quartic(root, k_psi)
        if a3 / a1 > 0:  # else a real pair +/- sqrt(-a3/a1): no Hopf point
            found.append(("hopf", root, float(np.sqrt(a3 / a1))))
    return sorted(found, key=lambda point: point[1])


def test_independent_coefficients_match_models_md():
    """models.md 4: k_d, k_c, c_a = 0.046567 / 0.051795 / 0.0008826 at the datum."""
    assert (K_D, K_C, C_A) == pytest.approx((0.046567, 0.051795, 0.0008826), abs=1e-6)


@pytest.mark.parametrize(("k_psi", "reference"), [
    (0.3, [("branch_point", 0.03598), ("hopf", 0.0807), ("hopf", 0.2888)]),
    (0.4, [("branch_point", 0.0390)]),
    # a real pair turning into an unstable complex pair (K1 ~ 0.030) is not a Hopf point
    (0.2, [("branch_point", None), ("hopf", None)]),
    (0.037, [("hopf", None), ("branch_point", None)]),
])
def test_stiffness_sweep_critical_points(model, k_psi, reference):
    """Eigenvalues of whirl's symbolic model against the independent characteristic
    polynomial above (all four cases, to 1e-9) and, for K_psi = 0.3 and 0.4, against models.md
    4 (BP 0.03598, HB 0.0807, HB 0.2888; unstable below 0.0390)."""
    found = linear.critical_points(model, {"K_psi": k_psi}, "K_theta", -0.3, 0.5)
    independent = independent_critical_points(k_psi)
    assert [c.kind for c in found] == [kind for kind, _ in reference]
    assert [kind for kind, _, _ in independent] == [kind for kind, _ in reference]
    for point, (_, value, frequency), (_, quoted) in zip(found, independent, reference,
                                                        strict=True):
        assert point.value == pytest.approx(value, abs=1e-9)
        assert point.frequency == pytest.approx(frequency, rel=1e-7, abs=1e-9)
        if quoted is not None:
            assert point.value == pytest.approx(quoted, abs=5e-4)


def test_divergence_matches_closed_form(model):
    """models.md 2.4: K_theta,BP = k_d - k_c^2 / (K_psi - k_d) for K_psi = 0.2, 0.3, 0.4."""
    for k_psi, expected in ((0.2, 0.02908), (0.3, 0.03598), (0.4, 0.03898)):
        found = [c for c in linear.critical_points(model, {"K_psi": k_psi}, "K_theta", -0.3, 0.5)
                 if c.kind == "branch_point"]
        assert found[0].value == pytest.approx(expected, abs=1e-5)


def test_vectorised_sweep_equals_point_by_point(model):
    values = np.linspace(-0.3, 0.5, 37)
    sweep = linear.sweep(model, {"K_psi": 0.3}, "K_theta", values)
    for k, value in enumerate(values):
        single = linear.sweep(model, {"K_psi": 0.3}, "K_theta", np.array([value]))
        np.testing.assert_allclose(single.eigenvalues[0], sweep.eigenvalues[k], rtol=1e-12)


@pytest.mark.parametrize(("param", "factor", "expected"), [
    ("I_y", 2.0, -0.0039), ("C_theta", 2.0, 0.0528), ("a", 2.0, 0.0665),
    ("I_x", 3.0, -0.0244), ("R", 5.0, -0.1051), ("Omega", 3.0, 0.0101),
])
def test_sensitivity_table(model, param, factor, expected):
    """models.md 4: minimum modal damping ratio at the datum with one parameter scaled."""
    value = model.parameter(param).default * factor
    sweep = linear.sweep(model, {}, param, np.array([value]))
    assert sweep.damping_ratio.min() == pytest.approx(expected, abs=2e-4)
