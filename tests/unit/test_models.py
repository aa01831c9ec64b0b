"""The classical model against the values recovered in ../shared/models.md (sections 2-4)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from tests.strip_theory import coefficients
from whirl_cli.models import all_variants, get_model


@pytest.fixture(scope="module")
def model():
    return get_model("classical")


def test_aerodynamic_coefficients_at_datum(model):
    """models.md 2.3: k_d = 0.04657, k_c = 0.05179 N m/rad, c_a = 0.000883 N m s/rad."""
    symbols = {p.name: sp.Symbol(p.name, real=True) for p in model.parameters}
    values = {symbols[k]: v for k, v in model.defaults().items()}
    k_d, k_c, c_a = (float(e.subs(values)) for e in coefficients(symbols))
    assert k_d == pytest.approx(0.046567, abs=2e-6)
    assert k_c == pytest.approx(0.051795, abs=2e-6)
    assert c_a == pytest.approx(0.0008826, abs=2e-7)


def test_datum_modes(model):
    """models.md 3: BW 34.38 rad/s with zeta 0.0230, FW 57.53 rad/s with zeta 0.1677."""
    eigenvalues = np.linalg.eigvals(model.jacobian_numpy(np.zeros(4), model.parameter_vector()))
    upper = sorted(eigenvalues[eigenvalues.imag > 0], key=lambda z: z.imag)
    assert [z.imag for z in upper] == pytest.approx([34.38, 57.53], abs=0.01)
    assert [-z.real / abs(z) for z in upper] == pytest.approx([0.0230, 0.1677], abs=1e-4)


def test_jacobian_matches_finite_differences(model):
    rng = np.random.default_rng(1)
    params = model.parameter_vector({"K2_theta": -10.0, "K3_theta": 350.0, "K_psi": 0.3})
    y = rng.standard_normal(4) * [0.2, 0.2, 5.0, 5.0]
    jac = model.jacobian_numpy(y, params)
    step = 1e-6
    numeric = np.column_stack([
        (model.rhs_numpy(y + step * e, params) - model.rhs_numpy(y - step * e, params))
        / (2 * step) for e in np.eye(4)])
    np.testing.assert_allclose(jac, numeric, rtol=1e-6, atol=1e-6)


def test_odd_symmetry(model):
    """The model is invariant under y -> -y (equilibria come in +/- pairs)."""
    params = model.parameter_vector({"K2_theta": 10.0, "K3_theta": 350.0})
    y = np.array([0.1, -0.05, 3.0, 1.0])
    np.testing.assert_allclose(model.rhs_numpy(-y, params), -model.rhs_numpy(y, params))


def test_pitch_yaw_exchange_symmetry(model):
    """models.md 2.4: swapping K_theta and K_psi leaves the eigenvalues unchanged."""
    a = model.parameter_vector({"K_theta": 0.13, "K_psi": 0.31})
    b = model.parameter_vector({"K_theta": 0.31, "K_psi": 0.13})
    eig_a = np.sort_complex(np.linalg.eigvals(model.jacobian_numpy(np.zeros(4), a)))
    eig_b = np.sort_complex(np.linalg.eigvals(model.jacobian_numpy(np.zeros(4), b)))
    np.testing.assert_allclose(eig_a, eig_b, rtol=1e-10)


@pytest.mark.parametrize("family", ["classical", "oscillators"])
def test_generated_numeric_module_equals_the_symbolic_equations(family):
    """The generated numpy code (cached, what runs use) against the sympy equations with the
    mass matrix inverted symbolically (fine for these small models): rhs, Jacobian and the
    fixed-parameter functions of time integration, at random states and parameter values."""
    from whirl_cli.models.symbolic import Symbolic

    model = get_model(family)
    symbolic = Symbolic(model)
    rhs = symbolic.rhs()
    f = sp.lambdify((symbolic.states, symbolic.parameters), list(rhs))
    jacobian = sp.lambdify((symbolic.states, symbolic.parameters),
                           rhs.jacobian(symbolic.states))
    rng = np.random.default_rng(3)
    for _ in range(3):
        params = model.parameter_vector() * rng.uniform(0.5, 1.5, len(model.parameters))
        y = rng.standard_normal(model.n_states) * 0.3
        expected, slope = np.array(f(y, params), float), np.array(jacobian(y, params), float)
        np.testing.assert_allclose(model.rhs_numpy(y, params), expected, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(model.jacobian_numpy(y, params), slope, rtol=1e-10,
                                   atol=1e-12)
        field, field_jacobian = model.field_at(params)
        np.testing.assert_allclose(field(y), expected, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(field_jacobian(y), slope, rtol=1e-10, atol=1e-12)


def test_zero_airspeed_is_finite(model):
    params = model.parameter_vector({"V": 0.0})
    assert np.all(np.isfinite(model.jacobian_numpy(np.zeros(4), params)))


def test_names_and_variants(model):
    """Parameters are named by what they are: the dofs' stiffnesses K_theta, K_psi and the
    law coefficients by dof; one program serves laws on either dof (zeros where unused)."""
    assert model.name == "classical_poly"
    # the shipped variants: polynomial laws, and those of the freeplay studies
    assert [v.name for v in all_variants()] == [
        "classical_poly", "classical_fp_theta_poly_psi", "classical_poly_theta_fp_psi",
        "gimballed_poly"]
    assert {"K_theta", "K_psi", "K2_theta", "K3_theta", "K2_psi", "K3_psi"} <= set(
        model.parameter_names)
    assert model.parameter("K2_psi").unit == "N m/rad^3"
    with pytest.raises(KeyError):
        model.canonical("K1")  # the thesis' name belongs to a study with one law
    with pytest.raises(KeyError):
        model.canonical("K_phi")


def test_the_linearity_probe_agrees_with_the_declared_laws():
    """``continuation.equilibria.is_linear`` (the right-hand side against its Jacobian at one
    probe state) and ``Model.is_linear`` (the family and every law declared K x) agree for
    every shipped variant at its datum and with each law coefficient moved off it."""
    from whirl_cli.continuation.equilibria import is_linear

    answers = []
    for variant in all_variants():
        cases = [{}]
        for dof in variant.family.dof_names:
            stiffness = variant.family.dof(dof).stiffness
            cases += [{name: 1.5 * variant.defaults()[name] + 0.01}
                      for name in variant.coefficient_names(dof).values() if name != stiffness]
        for values in cases:
            declared = variant.is_linear(values)
            assert is_linear(variant, values) == declared, (variant.name, values)
            answers.append(declared)
    assert True in answers and False in answers
