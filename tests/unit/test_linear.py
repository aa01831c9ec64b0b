"""Linear analysis against the reference numbers of ../shared/models.md section 4 and
../shared/science.md (thesis chapter 3)."""

from __future__ import annotations

import numpy as np
import pytest

from whirl_cli import linear
from whirl_cli.models import get_model


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


@pytest.mark.parametrize(("k_psi", "expected"), [
    (0.3, [("branch_point", 0.03598), ("hopf", 0.0807), ("hopf", 0.2888)]),
    (0.4, [("branch_point", 0.0390)]),
    # a real pair turning into an unstable complex pair (K1 ~ 0.030) is not a Hopf point
    (0.2, [("branch_point", 0.02908), ("hopf", 0.3233)]),
    (0.037, [("hopf", 0.2852), ("branch_point", 0.3270)]),
])
def test_stiffness_sweep_critical_points(model, k_psi, expected):
    """models.md 4: K_psi = 0.3 -> BP 0.03598, HB 0.0807, HB 0.2888; K_psi = 0.4 -> 0.0390;
    cases 3 and 5 as AUTO finds them."""
    found = linear.critical_points(model, {"K_psi": k_psi}, "K_theta", -0.3, 0.5)
    assert [c.kind for c in found] == [kind for kind, _ in expected]
    for point, (_, value) in zip(found, expected, strict=True):
        assert point.value == pytest.approx(value, abs=5e-4)


def test_divergence_matches_closed_form(model):
    """models.md 2.4: K_theta,BP = k_d - k_c^2 / (K_psi - k_d) for K_psi = 0.2, 0.3, 0.4."""
    for k_psi, expected in ((0.2, 0.02908), (0.3, 0.03598), (0.4, 0.03898)):
        found = [c for c in linear.critical_points(model, {"K_psi": k_psi}, "K1", -0.3, 0.5)
                 if c.kind == "branch_point"]
        assert found[0].value == pytest.approx(expected, abs=1e-5)


def test_vectorised_sweep_equals_point_by_point(model):
    values = np.linspace(-0.3, 0.5, 37)
    sweep = linear.sweep(model, {"K_psi": 0.3}, "K1", values)
    for k, value in enumerate(values):
        single = linear.sweep(model, {"K_psi": 0.3}, "K1", np.array([value]))
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
