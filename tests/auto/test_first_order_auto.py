"""First-order states on the real AUTO: the Lorenz system written as a model file (AUTO-07p's
demo ``lor``) against its closed forms and the published homoclinic orbit, and a mixed model
(a dof loaded by a first-order state) whose start is not the zero state, against its folds in
closed form."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from whirl_cli import api
from whirl_cli.results import BranchKind, PointType
from whirl_cli.study import load_study

DATA = Path(__file__).resolve().parents[1] / "data"
SIGMA, BETA = 10.0, 8.0 / 3.0


@pytest.fixture(scope="module")
def lorenz():
    return api.run(load_study(DATA / "lorenz_rho.yaml"))


def of_type(result, kind: PointType) -> list:
    return [p for c in result.continuations for p in c.special_points if p.point_type == kind]


def lorenz_jacobian(rho: float, state: np.ndarray) -> np.ndarray:
    """The Lorenz system's Jacobian, written out here (not whirl's generated code)."""
    x, y, z = state
    return np.array([[-SIGMA, SIGMA, 0.0], [rho - z, -1.0, -x], [y, x, -BETA]])


def test_lorenz_pitchfork_of_the_origin(lorenz):
    (bp,) = of_type(lorenz, PointType.BP)
    assert bp.parameters[0] == pytest.approx(1.0, abs=1e-6)
    np.testing.assert_allclose(bp.state[:3], 0.0, atol=1e-8)


def test_lorenz_hopf_points_closed_form(lorenz):
    """rho_H = sigma (sigma + beta + 3) / (sigma - beta - 1) on both nontrivial equilibria
    (+-sqrt(beta (rho - 1)), ..., rho - 1), period 2 pi / omega from the eigenvalues of the
    Jacobian there."""
    hopfs = of_type(lorenz, PointType.HB)
    rho_h = SIGMA * (SIGMA + BETA + 3) / (SIGMA - BETA - 1)
    assert len(hopfs) == 2
    for hopf in hopfs:
        assert hopf.parameters[0] == pytest.approx(rho_h, abs=1e-6)
        x = np.sqrt(BETA * (rho_h - 1))
        np.testing.assert_allclose(np.abs(hopf.state[:3]), [x, x, rho_h - 1], atol=1e-6)
        eigenvalues = np.linalg.eigvals(lorenz_jacobian(rho_h, np.array(hopf.state[:3])))
        omega = np.abs(eigenvalues.imag).max()
        assert hopf.period == pytest.approx(2 * np.pi / omega, rel=1e-6)
    assert sorted(np.sign(h.state[0]) for h in hopfs) == [-1.0, 1.0]


def test_lorenz_homoclinic_orbit(lorenz):
    """The unstable cycles from the subcritical Hopf points end in the homoclinic orbits of
    the origin at rho = 13.926 (Sparrow, The Lorenz Equations, 1982), their period growing
    without bound."""
    homoclinic = of_type(lorenz, PointType.HOMOCLINIC)
    assert len(homoclinic) == 2
    for point in homoclinic:
        assert point.parameters[0] == pytest.approx(13.926, abs=2e-3)
    families = [b for c in lorenz.continuations for b in c.branches
                if b.kind == BranchKind.PERIODIC]
    assert families and all(np.nanmax(f.period) > 10 * np.nanmin(f.period) for f in families)


@pytest.fixture(scope="module")
def lagged():
    return api.run(load_study(DATA / "lagged_spring_mu.yaml"))


def test_mixed_model_folds_closed_form(lagged):
    """mu = lam^3/3 - lam: folds at mu = +-2/3 where lam = -+1, and q = lam / K there."""
    folds = sorted(of_type(lagged, PointType.LP), key=lambda p: p.parameters[0])
    assert [p.parameters[0] for p in folds] == pytest.approx([-2 / 3, 2 / 3], abs=1e-6)
    k = 2.0
    for point, lam in zip(folds, (1.0, -1.0), strict=True):
        q, dq, load = point.state
        assert load == pytest.approx(lam, abs=1e-6)
        assert q == pytest.approx(lam / k, abs=1e-6)
        assert dq == pytest.approx(0.0, abs=1e-9)


def test_mixed_model_starts_at_its_equilibrium(lagged):
    """At mu = -2 the zero state is no equilibrium; the branch starts at the one real root
    of lam^3/3 - lam - mu (numpy's polynomial roots, not whirl's Newton method)."""
    branch = next(b for c in lagged.continuations for b in c.branches if b.name == "main_up")
    roots = np.roots([1 / 3, 0.0, -1.0, 2.0])
    lam = float(roots[np.abs(roots.imag) < 1e-12].real[0])
    assert branch.parameters[0, 0] == pytest.approx(-2.0)
    assert branch.state_max[0, 2] == pytest.approx(lam, abs=1e-9)
    assert branch.state_max[0, 0] == pytest.approx(lam / 2.0, abs=1e-9)
    assert branch.end == "range"
