"""Stability boundaries (real AUTO-07p): two-parameter loci against the eigenvalue grid, the
thesis' anatomy of the K_theta-K_psi map, and the unsafe (overhang) region by two methods and
by time simulation."""

from __future__ import annotations

import numpy as np
import pytest

from whirl_cli.analysis import boundaries, linear, simulate
from whirl_cli.models import get_model
from whirl_cli.pipeline import run_study
from whirl_cli.results import BranchKind, LocateStatus, PointType
from whirl_cli.study import validate_text

from ..conftest import STUDIES

RIGHT_HOPF, LEFT_HOPF = 0.2888, 0.0807  # K_psi = 0.3 (models.md section 4)


def _study(name: str, slices: str = "[0.3]", grid: str | None = None):
    text = (STUDIES / f"{name}.yaml").read_text()
    text = text.replace("slices: [0.4, 0.3, 0.2, 0.05, 0.037]", f"slices: {slices}")
    if grid:
        text = text.replace("points: 321", grid).replace("points: 201", grid)
    return validate_text(text, f"{name}.yaml")


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    cache = {}

    def get(name: str, **kw):
        if name not in cache:
            study = _study(name, **kw)
            cache[name] = (study, run_study(study, tmp_path_factory.mktemp(name), jobs=2))
        return cache[name]

    return get


def _on_boundary(model, params, curve, first, second):
    """Locus points where the locus is the stability boundary: the max real part of the
    eigenvalues there is ~0 (elsewhere a locus runs through already unstable parameters)."""
    p = np.repeat(model.parameter_vector(params)[:, None], len(curve), axis=1)
    p[model.parameter_names.index(first)] = curve[:, 0]
    p[model.parameter_names.index(second)] = curve[:, 1]
    growth = np.linalg.eigvals(linear.jacobians(model, p)).real.max(axis=1)
    return curve[np.abs(growth) < 1e-6]


def test_linear_loci_coincide_with_the_eigenvalue_boundary(results):
    """Hopf and pitchfork loci from AUTO lie on the zero contour of the linear grid (within
    1 % of the axis range), and the boundary is symmetric about K_theta = K_psi."""
    study, result = results("boundary_linear", slices="[0.3, 0.4]")
    model = get_model("classical")
    grid = result.linear_grid
    contour = np.vstack(grid.flutter + grid.divergence)
    (boundary,) = result.boundaries
    kinds = {kind for kind, _ in boundary.loci.values()}
    assert kinds == {"hopf", "branch_point"}
    checked = 0
    for kind, curve in boundary.loci.values():
        points = _on_boundary(model, study.parameter_values(), curve, "K_theta", "K_psi")
        points = points[(points >= 0).all(axis=1) & (points <= 0.5).all(axis=1)]
        for point in points:
            assert np.abs(contour - point).max(axis=1).min() < 0.01 * 0.5, (kind, point)
        checked += len(points)
    assert checked > 100
    np.testing.assert_allclose(grid.max_real, grid.max_real.T, rtol=1e-9, atol=1e-9)
    mirrored = contour[:, ::-1]
    assert np.abs(mirrored[:, None, :] - contour[None, :, :]).max(axis=2).min(axis=1).max() \
        < 0.01 * 0.5


def test_linear_map_anatomy(results):
    """A flutter bubble bounded by the Hopf locus, two thin divergence lobes along the axes
    bounded by the pitchfork locus, and the datum (0.4, 0.4) stable, outside both."""
    _, result = results("boundary_linear", slices="[0.3, 0.4]")
    grid = result.linear_grid
    unstable = grid.max_real > 0
    flutter = unstable & grid.oscillatory
    divergence = unstable & ~grid.oscillatory
    xx, yy = np.meshgrid(grid.x, grid.y)
    # the bubble (models.md: ~0.03-0.30 on both axes) around K_theta ~ K_psi ~ 0.15
    assert flutter[np.abs(grid.y - 0.15).argmin(), np.abs(grid.x - 0.15).argmin()]
    assert 0.30 < xx[flutter].max() < 0.34 and 0.30 < yy[flutter].max() < 0.34
    # the lobes: divergence only in thin strips along the axes
    assert np.all(np.minimum(xx[divergence], yy[divergence]) < 0.045)
    assert divergence[np.abs(grid.y - 0.45).argmin(), np.abs(grid.x - 0.01).argmin()]
    assert divergence[np.abs(grid.y - 0.01).argmin(), np.abs(grid.x - 0.45).argmin()]
    # the datum is stable
    assert grid.max_real[np.abs(grid.y - 0.4).argmin(), np.abs(grid.x - 0.4).argmin()] < 0
    (boundary,) = result.boundaries
    hopf = np.vstack([c for k, c in boundary.loci.values() if k == "hopf"])
    assert hopf[:, 0].min() < 0.05 and hopf[:, 0].max() > 0.3  # the loci span the bubble
    assert not boundary.intervals  # a linear model has no overhang


def test_a_linear_models_hopf_locus_lists_no_located_bautin_point(results):
    """A linear model's first Lyapunov coefficient is identically zero, so the GH points AUTO
    flags along its Hopf loci (its test function changing sign on round-off) are listed as
    rejected, their note saying so, never as located."""
    _, result = results("boundary_linear", slices="[0.3, 0.4]")
    (continuation,) = [c for c in result.continuations if c.name == "boundary"]
    gh = [p for p in continuation.special_points if p.point_type == PointType.GH]
    assert gh  # AUTO flags them: the check below is not vacuous
    assert all(p.status == LocateStatus.REJECTED for p in gh)
    assert all("vanishes" in p.note for p in gh)


def _slice_intervals(boundary, value, cause=None):
    return [i for i in boundary.intervals if abs(i.slice_value - value) < 1e-12
            and (cause is None or i.cause == cause)]


@pytest.mark.parametrize("name", ["boundary_softening", "boundary_combined"])
def test_unsafe_region_right_of_the_right_hopf(results, name):
    """Softening and combined: the flutter overhang is non-empty and lies on the stable side of
    the right Hopf point (larger K1)."""
    _, result = results(name, grid="points: 81")
    (boundary,) = result.boundaries
    flutter = _slice_intervals(boundary, 0.3, "flutter")
    assert flutter, boundary.intervals
    assert all(i.lower >= RIGHT_HOPF - 2e-3 for i in flutter)
    assert max(i.upper for i in flutter) > RIGHT_HOPF + 0.05
    assert boundary.polygons


def test_hardening_sliver_left_of_the_left_hopf(results):
    """Hardening, case 2: no overhang right of the right Hopf point, a sliver just left of the
    left one; in it the origin is stable and a stable limit cycle coexists (time simulation)."""
    study, result = results("boundary_hardening", grid="points: 81")
    (boundary,) = result.boundaries
    flutter = _slice_intervals(boundary, 0.3, "flutter")
    assert flutter and all(i.upper <= LEFT_HOPF + 1e-3 for i in flutter)
    (sliver,) = flutter
    assert 0.0807 - sliver.lower > 0.01
    model = get_model("classical")
    k1 = 0.5 * (sliver.lower + sliver.upper)
    params = model.parameter_vector({**study.parameter_values(), "K_psi": 0.3, "K_theta": k1})
    eigenvalues = np.linalg.eigvals(model.jacobian_numpy(np.zeros(4), params))
    assert eigenvalues.real.max() < 0  # linear analysis: stable
    _, small = simulate.integrate(model, params, np.radians([0.05, 0, 0, 0]), 60.0, 600)
    assert np.abs(small[-1, :2]).max() < np.radians(0.05) / 2  # small motions decay
    _, large = simulate.integrate(model, params, np.radians([8.0, 0, 0, 0]), 60.0, 6000)
    assert np.degrees(large[-1000:, 0].max()) > 3.0  # ... yet a stable LCO is reached
    (family,) = [b for b in result.continuations[0].branches
                 if b.kind == BranchKind.PERIODIC and "0.288" in str(b.origin)]
    stable = family.stable & (np.abs(family.parameter("K_theta") - k1) < 2e-3)
    assert stable.any()
    assert np.degrees(large[-1000:, 0].max()) == pytest.approx(
        np.degrees(family.state_max[stable, 0].max()), rel=0.05)


@pytest.mark.parametrize("k_psi, k1", [(0.295, 0.0445), (0.29, 0.0358)])
def test_hardening_sliver_holds_stable_cycles_off_the_slice(results, k_psi, k1):
    """Hardening rows near the sliver's lower tip: where the origin is linearly stable, starts
    of 4-12 deg in pitch or yaw all settle on one stable cycle (the classical model written
    out in tests/classical_exact.py, scipy), and the study's unsafe interval holds K1 there."""
    from ..classical_exact import linear_matrix, polynomial
    from ..classical_exact import simulate as exact_simulation

    assert np.linalg.eigvals(linear_matrix({"K_psi": k_psi, "K_theta": k1})).real.max() < 0
    for degrees in (4.0, 8.0):
        for dof in (0, 1):
            y0 = np.zeros(4)
            y0[dof] = np.radians(degrees)
            t, y = exact_simulation({"K_psi": k_psi, "K_theta": k1}, polynomial(k1, 10.0), y0,
                                    60.0, samples_per_second=200)
            late = np.abs(y[t > 55.0, :2]).max()
            before = np.abs(y[(t > 50.0) & (t <= 55.0), :2]).max()
            assert late > np.radians(2.0) and abs(late - before) < 0.01 * late, (degrees, dof)
    _, result = results("boundary_hardening", grid="points: 81")
    (boundary,) = result.boundaries
    assert any(i.lower < k1 < i.upper for i in _slice_intervals(boundary, k_psi, "flutter")), \
        _slice_intervals(boundary, k_psi)


@pytest.mark.parametrize("name", ["boundary_hardening", "boundary_softening",
                                  "boundary_combined"])
def test_loci_and_slices_methods_agree(results, name):
    """The unsafe intervals at the slice from the loci equal those from the one-parameter runs
    with periodic branches (the thesis' method) within 2e-3 in K1."""
    study, result = results(name, grid="points: 81")
    (spec,) = study.continuations
    (continuation,) = result.continuations
    curves = [b for b in continuation.branches if b.kind.endswith("_locus")]
    per_slice = [tuple(b for b in continuation.branches if b.name.startswith("slice_0."))]
    model = get_model("classical")
    by_slices = boundaries.boundary("x", model, study.parameter_values(), ("K_theta", "K_psi"),
                                    spec.bounds(study.names()), "slices",
                                    (0.3,), 3, curves, per_slice)
    by_loci = _slice_intervals(result.boundaries[0], 0.3)
    assert len(by_loci) == len(by_slices.intervals) > 0
    for a, b in zip(sorted(by_loci, key=lambda i: i.lower),
                    sorted(by_slices.intervals, key=lambda i: i.lower), strict=True):
        assert a.cause == b.cause
        assert a.lower == pytest.approx(b.lower, abs=2e-3)
        assert a.upper == pytest.approx(b.upper, abs=2e-3)
    assert all(b.kind != BranchKind.PERIODIC or len(b) for b in per_slice[0])


def test_the_outermost_folds_of_snaking_families_draw_the_same_boundary(tmp_path):
    """Hardening at K_psi = 0.2, where two families snake toward a homoclinic orbit (six and
    eight folds of cycles at one point of the slice): with ``snaking_folds: outermost`` every
    point of the loci traced with ``all`` lies within 3e-3 of the ranges of the loci drawn
    (and the other way round within 1e-3), the unsafe intervals are the same, and fewer AUTO
    runs are made."""
    from whirl_cli.continuation.geometry import on_paths

    found = {}
    for mode in ("all", "outermost"):
        text = (STUDIES / "boundary_hardening.yaml").read_text()
        assert "snaking_folds: outermost" in text
        text = text.replace("snaking_folds: outermost", f"snaking_folds: {mode}")
        text = text.replace("slices: [0.4, 0.3, 0.2, 0.05, 0.037]", "slices: [0.2]")
        text = text.replace("points: 321", "points: 81").replace("points: 201", "points: 81")
        study = validate_text(text, "boundary_hardening.yaml")
        found[mode] = run_study(study, tmp_path / mode, jobs=2)
    (spec,) = study.continuations
    bounds = spec.bounds(study.names())
    width = np.array([bounds[p][1] - bounds[p][0] for p in spec.parameters])

    def picture(result):
        return [b.parameters[:, :2] / width for b in result.continuations[0].branches
                if b.kind.endswith("_locus")]

    every, outer = picture(found["all"]), picture(found["outermost"])
    assert all(on_paths(curve, outer, 3e-3).all() for curve in every)
    assert all(on_paths(curve, every, 1e-3).all() for curve in outer)

    def intervals(result):
        return sorted((i.cause, i.lower, i.upper) for i in result.boundaries[0].intervals)

    assert intervals(found["all"]) and len(intervals(found["all"])) == len(
        intervals(found["outermost"]))
    for a, b in zip(intervals(found["all"]), intervals(found["outermost"]), strict=True):
        assert a[0] == b[0] and a[1:] == pytest.approx(b[1:], abs=1e-6)
    assert len(found["outermost"].runs) < len(found["all"].runs) - 20
