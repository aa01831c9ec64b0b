"""The aerodynamic-coupling switch ``aero_coupling`` of the classical model (issue 17, item 2):
a factor on the cross aerodynamic stiffness k_c (models.md 2.3; the theory has no aerodynamic
cross damping).

Expected values are derived here, never read off whirl's output:

* with k_c = 0 the equations of models.md 2.3 combine in z = theta + i psi (I_y = I_z,
  C_theta = C_psi, K_theta = K_psi) into one complex second-order equation
  I_y z'' + (C + c_a + i I_x Omega) z' + (K - k_d) z = 0; its two roots s_1, s_2 and their
  conjugates are the four eigenvalues. Since s_1 s_2 = (K - k_d)/I_y is real, arg s_2 =
  -arg s_1: FW and BW have exactly equal damping ratios;
* with the switch at 1 the model is the one of models.md (onset 7.764 m/s at the datum);
* a factor f between gives the quartic of models.md 2.3 with f k_c.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.polynomial import polynomial as P
from scipy.optimize import brentq

from whirl_cli.analysis import linear
from whirl_cli.models import get_model

from .linear_datum import DAMPING, I_X, I_Y, OMEGA, V, aerodynamic_coefficients

CLASSICAL = get_model("classical")
K = 0.4  # K_theta = K_psi at the datum


def uncoupled_modes(i_x: float, v: float) -> tuple[np.ndarray, np.ndarray]:
    """(damping ratios, frequencies [rad/s]) of the two modes with k_c = 0, from the roots of
    I_y s^2 + (C + c_a + i I_x Omega) s + (K - k_d) = 0, in order of frequency."""
    k_d, _, c_a = aerodynamic_coefficients(v)
    roots = np.roots([I_Y, DAMPING + c_a + 1j * i_x * OMEGA, K - k_d])
    upper = np.where(roots.imag > 0, roots, np.conj(roots))  # the Im > 0 one of each pair
    upper = upper[np.argsort(upper.imag)]
    return -upper.real / np.abs(upper), upper.imag


def whirl_modes(overrides: dict, parameter: str, values: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """(damping ratios, frequencies) of the Im > 0 eigenvalues of whirl's sweep, (M, 2), in
    order of frequency."""
    sweep = linear.sweep(CLASSICAL, overrides, parameter, values)
    upper = sweep.eigenvalues.imag > 0
    assert (upper.sum(axis=1) == 2).all()
    damping = sweep.damping_ratio[upper].reshape(len(values), 2)
    frequency = sweep.frequency[upper].reshape(len(values), 2)
    order = np.argsort(frequency, axis=1)
    return (np.take_along_axis(damping, order, axis=1),
            np.take_along_axis(frequency, order, axis=1))


def test_the_switch_is_a_parameter_on_by_default():
    parameter = CLASSICAL.parameter("aero_coupling")
    assert parameter.default == 1.0 and parameter.unit == "1"
    assert parameter.bounds.contains(0.0) and parameter.bounds.contains(1.0)
    assert not parameter.bounds.contains(-0.1) and not parameter.bounds.contains(1.1)
    assert "aero_coupling" in get_model("gimballed").parameter_names


@pytest.mark.parametrize(("parameter", "values"), [
    ("I_x", I_X * np.linspace(0.0, 5.0, 41)),
    ("V", np.linspace(0.5, 12.0, 47)),
])
def test_without_coupling_the_modes_are_the_closed_form(parameter, values):
    """aero_coupling = 0: damping ratio and frequency of both modes equal the roots of the
    complex quadratic in z = theta + i psi (1e-9), FW and BW equally damped, never unstable
    (science.md: gyroscopics alone cannot destabilise)."""
    damping, frequency = whirl_modes({"aero_coupling": 0.0}, parameter, values)
    for k, value in enumerate(values):
        i_x, v = (value, V) if parameter == "I_x" else (I_X, value)
        zeta, omega = uncoupled_modes(i_x, v)
        np.testing.assert_allclose(damping[k], zeta, rtol=0, atol=1e-9)
        np.testing.assert_allclose(frequency[k], omega, rtol=1e-9)
        assert zeta[0] == pytest.approx(zeta[1], abs=1e-12)
    np.testing.assert_allclose(damping[:, 0], damping[:, 1], rtol=0, atol=1e-9)
    assert (damping > 0).all()


def onset(overrides: dict) -> float:
    """The airspeed where the least-damped mode's damping ratio crosses 0 (brentq)."""
    def least(v: float) -> float:
        sweep = linear.sweep(CLASSICAL, overrides, "V", np.array([v]))
        return float(np.min(np.where(sweep.eigenvalues.imag > 0, sweep.damping_ratio, 9.0)))

    return brentq(least, 6.7, 9.0, xtol=1e-10)


def test_with_coupling_on_the_model_is_unchanged():
    """aero_coupling = 1 (and unset): the datum onset of models.md 4 (7.764 m/s) and the datum
    modes (BW 34.38 rad/s, zeta 0.0230; FW 57.53 rad/s, zeta 0.1677)."""
    assert onset({"aero_coupling": 1.0}) == pytest.approx(7.764, abs=5e-4)
    assert onset({}) == onset({"aero_coupling": 1.0})
    damping, frequency = whirl_modes({"aero_coupling": 1.0}, "V", np.array([V]))
    assert frequency[0] == pytest.approx([34.38, 57.53], abs=0.01)
    assert damping[0] == pytest.approx([0.0230, 0.1677], abs=1e-4)


@pytest.mark.parametrize("factor", [0.0, 0.5, 1.0])
def test_the_switch_scales_k_c_in_the_quartic(factor):
    """The characteristic polynomial of models.md 2.3 with k_c -> factor k_c (the closed-form
    coefficients of linear_datum.py): its roots are whirl's eigenvalues (1e-9 relative)."""
    k_d, k_c, c_a = aerodynamic_coefficients(V)
    axis = [K - k_d, DAMPING + c_a, I_Y]
    coupling = [-factor * k_c, I_X * OMEGA]
    roots = np.sort_complex(P.polyroots(P.polyadd(P.polymul(axis, axis),
                                                   P.polymul(coupling, coupling))))
    sweep = linear.sweep(CLASSICAL, {"aero_coupling": factor}, "V", np.array([V]))
    np.testing.assert_allclose(np.sort_complex(sweep.eigenvalues[0]), roots, rtol=1e-9)


def test_stiff_gimbal_without_coupling_is_the_uncoupled_classical_model():
    """The gimballed model carries the switch on its A'_2 terms: with K_beta = 1e6 and
    aero_coupling = 0 its nacelle modes are the closed form above (1e-3, the stiff-gimbal
    tolerance of test_gimballed)."""
    gimballed = get_model("gimballed")
    sweep = linear.sweep(gimballed, {"K_beta": 1e6, "aero_coupling": 0.0}, "V", np.array([V]))
    nacelle = (sweep.mode_group[0] == "nacelle") & (sweep.eigenvalues[0].imag > 0)
    frequency = np.sort(sweep.frequency[0][nacelle])
    damping = sweep.damping_ratio[0][nacelle][np.argsort(sweep.frequency[0][nacelle])]
    zeta, omega = uncoupled_modes(I_X, V)
    np.testing.assert_allclose(frequency, omega, rtol=1e-3)
    np.testing.assert_allclose(damping, zeta, rtol=1e-3)
