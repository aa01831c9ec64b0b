"""First Lyapunov coefficient against the closed form of Guckenheimer & Holmes (planar case)
and on the classical model (its symmetry and the linear model's zero)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from whirl_cli.analysis.normal_form import criticality_of, first_lyapunov_coefficient
from whirl_cli.models import get_model

x, y = sp.symbols("x y")


def planar_tensors(f: sp.Matrix):
    """Jacobian, second and third derivative tensors of a planar field at the origin."""
    v, at = (x, y), {x: 0, y: 0}
    jacobian = np.array(f.jacobian(v).subs(at), dtype=float)
    second = np.array([[[float(sp.diff(f[i], v[j], v[k]).subs(at)) for k in range(2)]
                        for j in range(2)] for i in range(2)])
    third = np.array([[[[float(sp.diff(f[i], v[j], v[k], v[m]).subs(at)) for m in range(2)]
                        for k in range(2)] for j in range(2)] for i in range(2)])
    return jacobian, second, third


def guckenheimer_holmes(f_: sp.Expr, g_: sp.Expr, omega: float) -> float:
    """Coefficient a of r' = a r^3 for x' = -omega y + f, y' = omega x + g (their eq. 3.4.11)."""
    def d(e, *v):
        return float(sp.diff(e, *v).subs({x: 0, y: 0}))

    return ((d(f_, x, x, x) + d(f_, x, y, y) + d(g_, x, x, y) + d(g_, y, y, y)) / 16
            + (d(f_, x, y) * (d(f_, x, x) + d(f_, y, y)) - d(g_, x, y) * (d(g_, x, x)
               + d(g_, y, y)) - d(f_, x, x) * d(g_, x, x) + d(f_, y, y) * d(g_, y, y))
            / (16 * omega))


@pytest.mark.parametrize("seed", range(5))
def test_planar_fields_match_the_closed_form(seed):
    rng = np.random.default_rng(seed)
    omega = float(rng.uniform(0.5, 3.0))
    monomials = [x**2, x * y, y**2, x**3, x**2 * y, x * y**2, y**3]
    f_ = sum(float(c) * m for c, m in zip(rng.normal(size=7), monomials, strict=True))
    g_ = sum(float(c) * m for c, m in zip(rng.normal(size=7), monomials, strict=True))
    field = sp.Matrix([-omega * y + f_, omega * x + g_])
    l1 = first_lyapunov_coefficient(*planar_tensors(field))
    # with <q, q> = 1 (Kuznetsov's normalisation) l1 = 2 a / omega
    assert l1 == pytest.approx(2 * guckenheimer_holmes(f_, g_, omega) / omega, rel=1e-9)


def test_no_complex_pair_is_refused():
    with pytest.raises(ValueError, match="not a Hopf point"):
        first_lyapunov_coefficient(np.diag([-1.0, 2.0]), np.zeros((2, 2, 2)),
                                   np.zeros((2, 2, 2, 2)))


def test_criticality_sign_convention():
    assert criticality_of(-0.2, 1.0) == "supercritical"
    assert criticality_of(0.2, 1.0) == "subcritical"
    assert criticality_of(1e-12, 1.0) == "" and criticality_of(float("nan"), 1.0) == ""


def test_derivative_tensors_of_the_classical_model():
    model = get_model("classical")
    params = model.parameter_vector({"K_theta": 0.2, "K2_theta": 10.0, "K3_theta": 0.0})
    rng = np.random.default_rng(1)
    state = rng.normal(scale=0.1, size=model.n_states)
    second, third = model.derivative_tensors(state, params)
    # second derivatives from differences of the Jacobian
    step = 1e-6
    for j in range(model.n_states):
        dy = np.zeros(model.n_states)
        dy[j] = step
        numeric = (model.jacobian_numpy(state + dy, params)
                   - model.jacobian_numpy(state - dy, params)) / (2 * step)
        np.testing.assert_allclose(second[:, :, j], numeric, atol=1e-6)
    assert np.allclose(second, second.transpose(0, 2, 1))
    assert np.allclose(third, third.transpose(0, 1, 3, 2))
