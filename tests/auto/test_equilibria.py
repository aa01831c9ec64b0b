"""One-parameter equilibrium continuation with the real AUTO-07p against the reference
numbers (../shared/science.md, models.md section 4), the eigenvalue analysis and closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from whirl_cli.analysis import linear
from whirl_cli.models import get_model
from whirl_cli.results import PointType

VARIANTS = ("linear", "hardening", "softening", "combined")


def _points(result, kind, branch_prefix="main"):
    (continuation,) = result.continuations
    return sorted(p.parameters[0] for p in continuation.special_points
                  if p.point_type == kind and p.branch.startswith(branch_prefix))


def _branches(result, prefix):
    return [b for b in result.continuations[0].branches if b.name.startswith(prefix)]


def test_all_runs_succeed(run_thesis):
    for variant in VARIANTS:
        result = run_thesis(f"{variant}_case2")
        assert [r.status for r in result.runs] == ["ok"] * len(result.runs), result.runs


@pytest.mark.parametrize("variant", VARIANTS)
def test_case2_hopf_and_pitchfork_match_thesis_and_eigenvalues(run_thesis, variant):
    """K_psi = 0.3: Hopf at K1 ~ 0.28 and ~ 0.08, pitchfork at ~ 0.03 (+/- 0.01, thesis; the
    recovered model gives 0.2888, 0.0807, 0.0360), independent of K2 and K3; AUTO agrees with
    the eigenvalue analysis to 1e-4."""
    result = run_thesis(f"{variant}_case2")
    hopf = _points(result, PointType.HB)
    (pitchfork,) = _points(result, PointType.BP)
    assert hopf == pytest.approx([0.08, 0.28], abs=0.01)
    assert pitchfork == pytest.approx(0.03, abs=0.01)
    model = get_model("classical")
    eigen = linear.critical_points(model, {"K_psi": 0.3}, "K_theta", -0.3, 0.5)
    assert hopf == pytest.approx([c.value for c in eigen if c.kind == "hopf"], abs=1e-4)
    assert pitchfork == pytest.approx(
        next(c.value for c in eigen if c.kind == "branch_point"), abs=1e-4)
    assert hopf == pytest.approx([0.0807, 0.2888], abs=1e-4)
    assert pitchfork == pytest.approx(0.03598, abs=1e-5)


def test_airspeed_onset_by_auto_and_eigenvalues(run_thesis):
    """Linear model at datum: flutter onset V ~ 7.8 m/s (+/- 0.1) from AUTO's Hopf point, equal
    to the eigenvalue crossing to 1e-4."""
    result = run_thesis("linear_datum_airspeed")
    (onset,) = _points(result, PointType.HB)
    assert onset == pytest.approx(7.8, abs=0.1)
    (eigen,) = linear.critical_points(get_model("classical"), {}, "V", 0.0, 10.0)
    assert onset == pytest.approx(eigen.value, abs=1e-4)
    # the stored Hopf point carries the flutter frequency in its period
    (point,) = [p for p in result.continuations[0].special_points if p.point_type == 3]
    assert 2 * np.pi / point.period == pytest.approx(eigen.frequency, rel=1e-4)


@pytest.mark.parametrize("variant", ("hardening", "softening", "combined"))
def test_secondary_equilibria_are_symmetric(run_thesis, variant):
    """The two branches from the pitchfork are mirror images: (theta, psi) -> (-theta, -psi)."""
    first, second = _branches(run_thesis(f"{variant}_case2"), "secondary")
    assert first.status == second.status == "ok"
    grid = np.linspace(*sorted(first.parameter("K_theta")[[0, -1]]), 25)
    for state in ("theta", "psi"):
        a = np.interp(grid, *_sorted(first.parameter("K_theta"), first.state(state)))
        b = np.interp(grid, *_sorted(second.parameter("K_theta"), second.state(state)))
        np.testing.assert_allclose(a, -b, atol=1e-8)
        away = np.abs(grid - 0.0359815) > 1e-4
        assert np.all(np.abs(a[away]) > 1e-3)  # genuinely deflected away from the pitchfork


def _sorted(x, y):
    order = np.argsort(x)
    return x[order], y[order]


def test_hardening_secondary_equilibria_closed_form_and_stability(run_thesis):
    """models.md 2.4: K1 + K2 theta^2 = K_eff, psi = k_c theta / (K_psi - k_d); the branches
    are stable just below the (supercritical) pitchfork, down to their Hopf point."""
    model = get_model("classical")
    params = model.parameter_vector({"K_psi": 0.3, "K2_theta": 10.0})
    k_eff = 0.0359815  # pitchfork value = k_d - k_c^2 / (K_psi - k_d)
    for branch in _branches(run_thesis("hardening_case2"), "secondary"):
        k1, theta, psi = branch.parameter("K_theta"), branch.state("theta"), branch.state("psi")
        np.testing.assert_allclose(k1 + 10.0 * theta**2, k_eff, atol=2e-6)
        # psi/theta is the same constant everywhere: rows of the static stiffness equation
        ratio = psi[1:] / theta[1:]
        np.testing.assert_allclose(ratio, ratio[0], rtol=1e-6)
        near = (k1 < k_eff - 1e-3) & (k1 > 0.0137 + 1e-3)
        assert near.sum() >= 3 and np.all(branch.stable[near])
        # stability flag agrees with numpy eigenvalues at the same equilibria
        states = np.vstack([theta, psi, np.zeros_like(theta), np.zeros_like(theta)])
        p = np.repeat(params[:, None], len(k1), axis=1)
        p[0] = k1
        growth = np.linalg.eigvals(model.jacobian_numpy(states, p)).real.max(axis=1)
        clear = np.abs(growth) > 1e-3
        assert np.array_equal(branch.stable[clear], growth[clear] < 0)


def test_auto_eigenvalues_equal_numpy_eigenvalues(run_thesis):
    """Eigenvalues parsed from AUTO's d-file (rescaled to 1/s) equal numpy's at the same point."""
    model = get_model("classical")
    (branch,) = [b for b in _branches(run_thesis("combined_case2"), "secondary_1a")]
    rows = np.flatnonzero(np.all(np.isfinite(branch.eigenvalues), axis=1))[::7]
    params = model.parameter_vector({"K_psi": 0.3, "K2_theta": -10.0, "K3_theta": 350.0})
    for k in rows:
        p = params.copy()
        p[0] = branch.parameter("K_theta")[k]
        y = np.array([branch.state("theta")[k], branch.state("psi")[k], 0.0, 0.0])
        expected = np.sort_complex(np.linalg.eigvals(model.jacobian_numpy(y, p)))
        np.testing.assert_allclose(np.sort_complex(branch.eigenvalues[k]), expected,
                                   rtol=1e-4, atol=1e-4)


def test_combined_secondary_fold_matches_closed_form(run_thesis):
    """K1 = K_eff - K2 theta^2 - K3 theta^4 has its maximum K_eff + K2^2 / (4 K3) = 0.10741."""
    folds = [p for p in run_thesis("combined_case2").continuations[0].special_points
             if p.point_type == PointType.LP]
    assert len(folds) == 2
    for fold in folds:
        assert fold.parameters[0] == pytest.approx(0.0359815 + 100 / 1400, abs=1e-6)
        assert fold.state[0] ** 2 == pytest.approx(10 / 700, rel=1e-4)


def test_linear_variant_divergence_is_a_vertical_line(run_thesis):
    """With a linear spring the pitchfork carries a line of equilibria at fixed K1."""
    for branch in _branches(run_thesis("linear_case2"), "secondary"):
        np.testing.assert_allclose(branch.parameter("K_theta"), 0.0359815, atol=1e-6)
        assert abs(branch.state("theta")).max() == pytest.approx(1.5, abs=1e-6)  # amplitude stop
    assert _points(run_thesis("linear_case2"), PointType.LP, "") == []


@pytest.mark.parametrize("case", [f"{v}_case{c}" for v in VARIANTS[1:] for c in (2, 3, 5)])
def test_every_hopf_crossing_along_every_branch_is_found(run_thesis, case):
    """Along every equilibrium branch, the number of Hopf points AUTO reports equals the number
    of sign changes of the oscillatory growth rate from numpy eigenvalues at the same points."""
    model = get_model("classical")
    result = run_thesis(case)
    study_params = {"hardening": {"K2_theta": 10.0}, "softening": {"K2_theta": -10.0},
                    "combined": {"K2_theta": -10.0, "K3_theta": 350.0}}[case.split("_")[0]]
    k_psi = {"2": 0.3, "3": 0.2, "5": 0.037}[case[-1]]
    params = model.parameter_vector({**study_params, "K_psi": k_psi})
    for branch in result.continuations[0].branches:
        if branch.kind != "equilibrium" or len(branch) < 3:
            continue
        p = np.repeat(params[:, None], len(branch), axis=1)
        p[0] = branch.parameter("K_theta")
        eigenvalues = np.linalg.eigvals(model.jacobian_numpy(branch.state_max.T, p))
        oscillatory = np.abs(eigenvalues.imag) > 1e-6
        growth = np.where(oscillatory, eigenvalues.real, -np.inf).max(axis=1)
        # a sign change of a complex pair's real part, not a real pair turning complex
        count = oscillatory.sum(axis=1)
        same = (count[1:] == count[:-1]) & np.isfinite(growth[1:]) & np.isfinite(growth[:-1])
        crossings = int(np.sum(same & (np.sign(growth[1:]) * np.sign(growth[:-1]) < 0)))
        hopfs = int(np.sum(branch.point_type == PointType.HB))
        assert hopfs == crossings, (case, branch.name)
