"""The periodic families of ``studies/gimballed/combined_case2_soft.yaml`` on the real AUTO-07p,
each claim checked by an independent computation written here:

* the family from the upper Hopf point of the undeflected equilibrium runs to the lower one (both
  found from numpy eigenvalues of the Jacobian): its period stays bounded by the two Hopf
  periods, and no global bifurcation is reported on it;
* the families from the Hopf points of the offset equilibria end at a genuine homoclinic orbit:
  the saddle's unstable manifold, integrated with scipy, returns onto the saddle at the value
  whirl reports, and misses it well to either side;
* the two mirror-image families of each +/- pair of Hopf points carry the same special points
  (the model is odd: checked with numpy here), and the mirrored family's orbits are solutions
  of the model (integrated over a period with scipy, they close).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, fsolve

from whirl_cli.models import get_model
from whirl_cli.pipeline import run_study
from whirl_cli.results import PointType
from whirl_cli.study import validate_text

from ..conftest import ROOT

SHIPPED = ROOT / "studies" / "gimballed" / "combined_case2_soft.yaml"
MODEL = get_model("gimballed")
GLOBAL = (PointType.HOMOCLINIC, PointType.HETEROCLINIC)


@pytest.fixture(scope="module")
def combined(tmp_path_factory):
    """(study, the continuation) of the shipped study, without its cross-checks."""
    text = SHIPPED.read_text()
    assert "cross_check: true" in text
    study = validate_text(text.replace("cross_check: true", "cross_check: false"),
                          "combined_case2_soft.yaml")
    result = run_study(study, tmp_path_factory.mktemp("combined"), jobs=2)
    (continuation,) = result.continuations
    return study, continuation


def _params(study, k1: float) -> np.ndarray:
    return MODEL.parameter_vector({**study.parameter_values(), "K_theta": k1})


def _origin_hopf_points(study) -> list[tuple[float, float]]:
    """(K1, period in s) where a complex pair of eigenvalues of the Jacobian at y = 0 crosses
    the imaginary axis over K1 in [-0.3, 0.5] (a 2e-3 grid, refined by Brent's method)."""
    def growth(k1: float) -> float:
        values = np.linalg.eigvals(MODEL.jacobian_numpy(np.zeros(8), _params(study, k1)))
        return float(values[np.abs(values.imag) > 1e-6].real.max())

    grid = np.arange(-0.3, 0.5, 2e-3)
    rates = np.array([growth(k) for k in grid])
    found = []
    for k in np.flatnonzero(np.sign(rates[:-1]) != np.sign(rates[1:])):
        root = brentq(growth, grid[k], grid[k + 1], xtol=1e-13)
        values = np.linalg.eigvals(MODEL.jacobian_numpy(np.zeros(8), _params(study, root)))
        crossing = values[np.argmin(np.abs(values.real) + (np.abs(values.imag) < 1e-6))]
        found.append((root, 2 * np.pi / abs(crossing.imag)))
    return found


def test_a_family_from_hopf_point_to_hopf_point_has_no_global_bifurcation(combined):
    """The family from the upper Hopf point ends on the lower one (K1 and period to 1e-3 of
    numpy's), its period never exceeds the slower Hopf period by more than 1 %, and it carries
    no homoclinic or heteroclinic point (the two Hopf periods differ by about 3x, which is no
    blow-up)."""
    study, continuation = combined
    (upper, upper_period), (lower, lower_period) = sorted(_origin_hopf_points(study))[::-1][:2]
    assert lower < upper
    (family,) = [b for b in continuation.branches if b.is_periodic
                 and abs(b.parameters[0, 0] - upper) < 1e-4 and b.origin.branch == "main_down"]
    assert abs(family.parameters[-1, 0] - lower) < 1e-3
    assert family.period[-1] == pytest.approx(lower_period, rel=1e-3)
    assert np.nanmax(family.period) < 1.01 * max(upper_period, lower_period)
    assert family.end.startswith("returns to HB")
    assert not [p for p in continuation.special_points
                if p.branch == family.name and p.point_type in GLOBAL]


def _return_distance(study, k1: float, near: np.ndarray, sign: float) -> float:
    """How close the unstable manifold of the saddle near ``near`` (Newton's method) comes
    back to it, as a fraction of its largest excursion (non-dimensional states): leave along
    the unstable eigenvector on side ``sign``, integrate 3 s (DOP853), take the smallest
    distance after the excursion's first half, sampled every 1e-4 s."""
    params = _params(study, k1)
    scale = np.asarray(MODEL.state_scale)
    saddle = fsolve(lambda y: MODEL.rhs_numpy(y, params), near, xtol=1e-13,
                    fprime=lambda y: MODEL.jacobian_numpy(y, params))
    values, vectors = np.linalg.eig(MODEL.jacobian_numpy(saddle, params))
    assert np.sum(values.real > 0) == 1 and abs(values[np.argmax(values.real)].imag) < 1e-9
    unstable = np.real(vectors[:, np.argmax(values.real)])
    start = saddle + 1e-7 * sign * unstable / np.linalg.norm(unstable / scale)
    field, _ = MODEL.field_at(params)  # the model's numpy right-hand side, set up once
    run = solve_ivp(lambda t, y: field(y), (0, 3.0), start, method="DOP853", rtol=1e-10,
                    atol=1e-13, dense_output=True)
    distance = np.linalg.norm((run.sol(np.linspace(0.0, 3.0, 30001)).T - saddle) / scale,
                              axis=1)
    far = np.flatnonzero(distance > 0.5 * distance.max())
    return float(distance[far[0]:].min() / distance.max())


def test_a_genuine_homoclinic_orbit_is_still_reported(combined):
    """The family from the Hopf point of the offset equilibria at K1 = 0.1067 ends in a
    homoclinic point located by HomCont with a period over 10 s; there the saddle's unstable
    manifold returns onto it closer than 1e-4 of its excursion, and 5e-4 to either side of it
    it misses by more than 1e-2."""
    study, continuation = combined
    located = [p for p in continuation.special_points if p.point_type == PointType.HOMOCLINIC
               and p.status == "located" and p.period > 10 and p.state[0] > 0]
    assert located, "no located homoclinic point with a period over 10 s"
    point = located[0]
    star = float(point.parameters[0])
    sides = {s: _return_distance(study, star, point.state, s) for s in (1.0, -1.0)}
    sign = min(sides, key=sides.get)
    assert sides[sign] < 1e-4
    for offset in (-5e-4, 5e-4):
        assert _return_distance(study, star + offset, point.state, sign) > 1e-2


def test_the_model_is_odd(combined):
    """f(-y) = -f(y) at random states of a few typical amplitudes (the premise of mirror
    images)."""
    study, _ = combined
    params = _params(study, 0.1)
    rng = np.random.default_rng(0)
    for _ in range(5):
        y = rng.normal(scale=0.2, size=8)
        np.testing.assert_allclose(MODEL.rhs_numpy(-y, params), -MODEL.rhs_numpy(y, params),
                                   rtol=1e-12, atol=1e-12)


def _mirror_pairs(continuation) -> list[tuple]:
    """(family, its mirror image's family) for each Hopf point on secondary_1a."""
    hopfs = [p for p in continuation.special_points if p.point_type == PointType.HB]
    families = [b for b in continuation.branches if b.is_periodic]
    pairs = []
    for hopf in (h for h in hopfs if h.branch == "secondary_1a"):
        (image,) = [h for h in hopfs if h.branch == "secondary_1b"
                    and abs(h.parameters[0] - hopf.parameters[0]) < 1e-9]
        pair = [next(f for f in families if f.origin.branch == h.branch
                     and abs(f.parameters[0, 0] - h.parameters[0]) < 1e-9)
                for h in (hopf, image)]
        pairs.append(tuple(pair))
    return pairs


def test_mirror_image_families_carry_the_same_special_points(combined):
    """For both +/- pairs of Hopf points on the offset equilibria: the same special point
    types, parameter values, periods and stability on both families, with mirrored states (the
    maximum on one is minus the minimum on the other)."""
    _, continuation = combined
    pairs = _mirror_pairs(continuation)
    assert len(pairs) == 2
    for first, second in pairs:
        points = [[p for p in continuation.special_points if p.branch == f.name]
                  for f in (first, second)]
        assert [p.type_name for p in points[0]] == [p.type_name for p in points[1]]
        assert points[0] and len(points[0]) == len(points[1])
        for a, b in zip(*points, strict=True):
            assert a.parameters[0] == pytest.approx(b.parameters[0], abs=1e-9)
            assert a.period == pytest.approx(b.period, rel=1e-9)
            assert (a.stable, a.status) == (b.stable, b.status)
        np.testing.assert_allclose(first.parameters, second.parameters, atol=1e-12)
        np.testing.assert_allclose(first.state_max, -second.state_min, atol=1e-12)
        np.testing.assert_array_equal(first.stable, second.stable)


def test_the_mirrored_family_orbits_close_under_the_model(combined):
    """The stored orbits of the families of secondary_1b with periods under 1 s (the longer
    ones pass the saddle, too unstable to integrate over a period), integrated from their first
    point over their period (scipy, rtol 1e-10), come back to it within 1e-5 of the orbit's
    size."""
    study, continuation = combined
    scale = np.asarray(MODEL.state_scale)
    orbits = [(mirrored.name, o) for _, mirrored in _mirror_pairs(continuation)
              for o in mirrored.orbits if o.period < 1]
    assert len(orbits) >= 2
    for name, orbit in orbits:
        params = _params(study, float(orbit.parameters[0]))
        field, _ = MODEL.field_at(params)
        run = solve_ivp(lambda t, y, f=field: f(y), (0, orbit.period), orbit.states[0],
                        rtol=1e-10, atol=1e-12)
        size = np.ptp(orbit.states / scale, axis=0).max()
        miss = np.linalg.norm((run.y[:, -1] - orbit.states[0]) / scale)
        print(f"\n  {name} at K1 = {orbit.parameters[0]:.6g}, T = {orbit.period:.4g} s: "
              f"misses by {miss / size:.1e} of its size")
        assert miss < 1e-5 * size
