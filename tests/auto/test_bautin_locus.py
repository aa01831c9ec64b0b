"""GH (Bautin) points on Hopf loci (real AUTO-07p): on tests/data/bautin.model.yaml, whose
Hopf locus is the parabola mu = nu^2/4, the GH point is listed as located where the first
Lyapunov coefficient, computed here from the rates with sympy and Guckenheimer and Holmes'
planar formula (not whirl's normal-form code), changes sign."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from scipy.optimize import brentq

from whirl_cli.pipeline import run_study
from whirl_cli.results import LocateStatus, PointType
from whirl_cli.study import load_study

from ..conftest import ROOT

pytestmark = pytest.mark.auto

STUDY = ROOT / "tests" / "data" / "bautin_mu_nu.yaml"


def _lyapunov_sign(nu_value: float) -> float:
    """Guckenheimer and Holmes' a (eq. 3.4.11), a multiple of l1, at the Hopf point of the
    origin for ``nu``: the rates minus their linear part, in the frame where the linear part
    is [[0, -omega], [omega, 0]] (the model's is, on the locus)."""
    x, y, nu = sp.symbols("x y nu")
    omega = 1 + nu**2
    f = x**2 + x * y + (nu - 0.3) * x**3  # the nonlinear parts of the rates
    g = x**2

    def d(h, *by):
        return sp.diff(h, *by).subs({x: 0, y: 0})

    a = (d(f, x, x, x) + d(f, x, y, y) + d(g, x, x, y) + d(g, y, y, y)) / 16 + (
        d(f, x, y) * (d(f, x, x) + d(f, y, y)) - d(g, x, y) * (d(g, x, x) + d(g, y, y))
        - d(f, x, x) * d(g, x, x) + d(f, y, y) * d(g, y, y)) / (16 * omega)
    return float(a.subs(nu, nu_value))


def test_the_rates_written_here_are_the_model_files():
    """The test's nonlinear parts and linear part are those of the model file."""
    text = (ROOT / "tests" / "data" / "bautin.model.yaml").read_text()
    assert "x: (mu - nu**2/4)*x - (1 + nu**2)*y + x**2 + x*y + (nu - 0.3)*x**3" in text
    assert "y: (1 + nu**2)*x + (mu - nu**2/4)*y + x**2" in text


def test_a_bautin_point_is_located_where_l1_changes_sign(tmp_path):
    nu_gh = brentq(_lyapunov_sign, 0.0, 1.5)
    result = run_study(load_study(STUDY), tmp_path, jobs=1)
    (continuation,) = result.continuations
    gh = [p for p in continuation.special_points if p.point_type == PointType.GH]
    assert len(gh) == 1
    (point,) = gh
    assert point.status == LocateStatus.LOCATED
    mu, nu = point.parameters[:2]
    assert nu == pytest.approx(nu_gh, abs=1e-4)
    assert mu == pytest.approx(nu_gh**2 / 4, abs=1e-4)
    assert np.sign(_lyapunov_sign(nu_gh - 0.05)) != np.sign(_lyapunov_sign(nu_gh + 0.05))
