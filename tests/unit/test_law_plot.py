"""The plot of a stiffness law: the smoothed freeplay law as drawn departs from the exact one
by its closed-form largest error at the corners, the polynomial law is K x + K2 x^3 + K3 x^5,
and the numeric form of the smoothed law is its symbolic form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from whirl_cli.models import get_model
from whirl_cli.output.provenance import law_curve, provenance
from whirl_cli.plots.laws import law_plot, nonlinear_laws
from whirl_cli.results import StudyResult
from whirl_cli.study import validate_text

DELTA, EPSILON, K_OUT, K_IN = math.radians(1.0), math.radians(0.05), 0.4, 0.05


def lines_by_label(figure):
    ax = figure.axes[0]
    return {line.get_label(): line for line in ax.get_lines()}


def test_freeplay_law_smoothed_exact_and_their_largest_difference():
    model = get_model("classical", ("freeplay", "polynomial"))
    values = {"K_theta": K_OUT, "delta_theta": DELTA, "epsilon_theta": EPSILON,
              "K_in_theta": K_IN}
    figure = law_plot(law_curve(model, values, "theta"))
    lines = lines_by_label(figure)
    smoothed, exact = lines["as continued (smoothed)"], lines["exact"]
    x = np.radians(smoothed.get_xdata())  # drawn in degrees
    np.testing.assert_allclose(np.radians(exact.get_xdata()), x)
    inside = np.abs(x) <= DELTA
    expected = np.where(inside, K_IN * x, K_IN * x + (K_OUT - K_IN) * (x - DELTA * np.sign(x)))
    np.testing.assert_allclose(exact.get_ydata(), expected, atol=1e-15)
    error = np.abs(smoothed.get_ydata() - exact.get_ydata())
    assert error.max() == pytest.approx((K_OUT - K_IN) * EPSILON * math.log(2) / 2, rel=1e-6)
    assert abs(x[np.argmax(error)]) == pytest.approx(DELTA)  # at the corners
    assert x.max() == pytest.approx(4 * DELTA)
    ax = figure.axes[0]
    assert ax.get_xlabel() == "$\\theta$ [deg]"
    assert ax.get_ylabel() == "restoring force on theta [N m]"
    assert "freeplay law on $\\theta$" in ax.get_title()


def test_numeric_smoothed_law_is_the_symbolic_one():
    import sympy as sp

    from whirl_cli.models.laws import FREEPLAY

    x, k = sp.symbols("x k")
    c = {"delta": DELTA, "K_in": K_IN, "epsilon": EPSILON}
    symbolic = sp.lambdify((x, k), FREEPLAY.moment(x, k, c), "numpy")
    points = np.linspace(-5 * DELTA, 5 * DELTA, 1001)
    np.testing.assert_allclose(FREEPLAY.force(points, K_OUT, c), symbolic(points, K_OUT),
                               rtol=1e-13, atol=1e-16)


def test_polynomial_law_and_which_laws_a_result_draws():
    model = get_model("classical")
    values = {"K_theta": 0.2, "K2_theta": 10.0, "K3_theta": 350.0}
    lines = lines_by_label(law_plot(law_curve(model, values, "theta")))
    x = np.radians(lines["law"].get_xdata())
    np.testing.assert_allclose(lines["law"].get_ydata(), 0.2 * x + 10 * x**3 + 350 * x**5,
                               rtol=1e-12)
    np.testing.assert_allclose(lines["linear spring ($K_{\\theta}$ = 0.2)"].get_ydata(), 0.2 * x)
    study = ("name: s\nmodel: classical\nnonlinearity: {type: polynomial, dof: psi, K2: 5}\n")
    result = StudyResult("s", "classical_poly", (), (), (),
                         provenance=provenance(validate_text(study)))
    assert [curve.dof for curve in nonlinear_laws(result)] == ["psi"]
    linear = StudyResult("s", "classical_poly", (), (), (),
                         provenance=provenance(validate_text("name: s\nmodel: classical\n")))
    assert nonlinear_laws(linear) == ()
