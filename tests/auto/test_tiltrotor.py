"""The gimballed model at tiltrotor gimbals (1.02-1.10 per rev) with blade pitch held relative to
the shaft (``pitch_on_disc: 0``) on the real AUTO-07p, every number checked against a computation
written here (tests/gimbal_strip_theory.py's matrices, numpy eigenvalues, scipy simulation and
monodromy matrix, a Benettin estimate), never against whirl's own output. Each shipped study is
run once for the module.

``tiltrotor_gimbal_combined_airspeed.yaml``: K_beta = 0.008446 N m/rad (1.05/rev), the thesis'
combined law scaled onto both gimbal dofs, linear nacelle, airspeed 0.2-25 m/s.
``tiltrotor_linear_onset.yaml``: the onset loci in (V, K_beta) from 1.02/rev to past 11/rev.
``tiltrotor_combined_airspeed.yaml``: the combined law on pitch, hardening gimbal springs, and
``explore`` across the airspeed range.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from whirl_cli.pipeline import run_study
from whirl_cli.plots.files import study_figures
from whirl_cli.results import MotionKind, PointType, Spacing
from whirl_cli.study import load_study

from ..conftest import ROOT
from ..gimbal_strip_theory import matrices

pytestmark = pytest.mark.auto

STUDIES = ROOT / "studies" / "gimballed"
VALUES = {"K_theta": 0.4, "K_psi": 0.3, "K_beta": 0.008446}  # K_theta: the datum
#: cubic and quintic coefficients per dof (theta, psi, beta_y, beta_z): the gimbal-law study's
GIMBAL_LAWS = (np.array([0, 0, -0.21, -0.21]), np.array([0, 0, 7.4, 7.4]))
#: the explore study's: the combined pitch law, hardening cubic gimbal springs
PITCH_LAWS = (np.array([-10, 0, 0.5, 0.5]), np.array([350, 0, 0, 0]))
#: whirl's (thesis) frame to the derivation frame of gimbal_strip_theory: psi, beta_z negated
FRAME = np.array([1, -1, 1, -1, 1, -1, 1, -1], dtype=float)
#: K_beta at 1.02 and 1.10 per rev (I_d Omega^2 (nu^2 - 1), 2 digits)
K_BETA_ENDS = (0.0033, 0.0173)
#: the onset study's K_beta range: 1.02/rev to past the thesis' K_beta = 10 (11/rev)
K_BETA_RANGE = (0.0033, 12.0)


def _run(name: str, tmp_path_factory):
    return run_study(load_study(STUDIES / name), tmp_path_factory.mktemp("tilt"), jobs=2)


def _only(result):
    (continuation,) = result.continuations
    return continuation


@pytest.fixture(scope="module")
def gimbal_law(tmp_path_factory):
    return _run("tiltrotor_gimbal_combined_airspeed.yaml", tmp_path_factory)


@pytest.fixture(scope="module")
def onset_study(tmp_path_factory):
    return _run("tiltrotor_linear_onset.yaml", tmp_path_factory)


@pytest.fixture(scope="module")
def onset(onset_study):
    return _only(onset_study)


@pytest.fixture(scope="module")
def pitch_law(tmp_path_factory):
    return _only(_run("tiltrotor_combined_airspeed.yaml", tmp_path_factory))


def _points(continuation, kind: PointType, prefix: str = ""):
    return [p for p in continuation.special_points
            if p.point_type == kind and p.branch.startswith(prefix)]


def _linear(v: float, values: dict = VALUES) -> np.ndarray:
    """First-order matrix of the linear model, pitch on the shaft (derivation frame)."""
    mass, damping, stiffness = matrices({**values, "V": v}, shaft=True)
    minv = np.linalg.inv(mass)
    return np.block([[np.zeros((4, 4)), np.eye(4)], [-minv @ stiffness, -minv @ damping]])


def _oscillatory_growth(v: float, values: dict = VALUES) -> float:
    eigenvalues = np.linalg.eigvals(_linear(v, values))
    return float(eigenvalues[np.abs(eigenvalues.imag) > 1e-9].real.max())


def _on_the_axis(v: float, values: dict = VALUES) -> bool:
    """True if a complex pair sits on the imaginary axis at ``v`` (a Hopf point, not the jump
    of :func:`_oscillatory_growth` where a pair turns real)."""
    eigenvalues = np.linalg.eigvals(_linear(v, values))
    return bool(np.abs(eigenvalues[np.abs(eigenvalues.imag) > 1e-3].real).min() < 1e-7)


def _stiffness_determinant(v: float, values: dict = VALUES) -> float:
    return float(np.linalg.det(matrices({**values, "V": v}, shaft=True)[2]))


def _roots(function, lower: float, upper: float, values: dict = VALUES,
           points: int = 1001) -> list[float]:
    grid = np.linspace(lower, upper, points)
    signs = np.sign([function(v, values) for v in grid])
    return [brentq(function, grid[k], grid[k + 1], args=(values,), xtol=1e-12)
            for k in np.flatnonzero(signs[:-1] != signs[1:])]


def _hopf_speeds(lower: float, upper: float, values: dict = VALUES) -> list[float]:
    return [v for v in _roots(_oscillatory_growth, lower, upper, values)
            if _on_the_axis(v, values)]


def _field(v: float, laws=GIMBAL_LAWS):
    """Right-hand side and Jacobian of the nonlinear model (derivation frame, whose odd laws
    are the thesis frame's) with the polynomial ``laws`` (cubic, quintic coefficients)."""
    mass, _, _ = matrices({**VALUES, "V": v}, shaft=True)
    minv = np.linalg.inv(mass)
    linear = _linear(v)
    cubic, quintic = laws

    def f(_t, y):
        q = y[:4]
        square = q * q
        result = linear @ y
        result[4:] -= minv @ (q * square * (cubic + quintic * square))
        return result

    def jac(y):
        square = y[:4] ** 2
        slope = square * (3 * cubic + 5 * quintic * square)
        result = linear.copy()
        result[4:, :4] -= minv * slope  # minv @ diag(slope)
        return result
    return f, jac


def test_the_critical_points_along_v_are_the_numpy_ones(gimbal_law):
    """Along V in [0.2, 25] m/s the origin's Hopf points are where the derived model's oscillatory
    eigenvalues cross the imaginary axis and its branch points where det K = 0 (1e-4), each Hopf
    point at the crossing pair's period (1e-3); none below 15 m/s, the first at the linear onset
    (15.98 m/s); the gimbal is at 1.05 per rev."""
    gimbal_law = _only(gimbal_law)
    hopfs = sorted(_points(gimbal_law, PointType.HB, "main"), key=lambda p: p.parameters[0])
    branch_points = sorted(_points(gimbal_law, PointType.BP, "main"),
                           key=lambda p: p.parameters[0])
    expected_hopfs = _hopf_speeds(0.2, 25.0)
    expected_branch_points = _roots(_stiffness_determinant, 0.2, 25.0)
    print(f"\n  numpy Hopf {np.round(expected_hopfs, 5)}, BP {np.round(expected_branch_points, 5)}")
    assert len(hopfs) == len(expected_hopfs) >= 2
    assert len(branch_points) == len(expected_branch_points) >= 1
    for point, v in zip(hopfs, expected_hopfs, strict=True):
        assert point.parameters[0] == pytest.approx(v, rel=1e-4)
        eigenvalues = np.linalg.eigvals(_linear(v))
        omega = abs(eigenvalues[np.argmin(np.abs(eigenvalues.real))].imag)
        assert point.period == pytest.approx(2 * np.pi / omega, rel=1e-3)
    for point, v in zip(branch_points, expected_branch_points, strict=True):
        assert point.parameters[0] == pytest.approx(v, rel=1e-4)
    first = brentq(lambda v: np.linalg.eigvals(_linear(v)).real.max(), 10.0, 17.0, xtol=1e-10)
    assert min(p.parameters[0] for p in hopfs + branch_points) == pytest.approx(first, rel=1e-4)
    assert first > 15.0
    assert np.sqrt(1 + VALUES["K_beta"] / (5.15e-5 * 40.0**2)) == pytest.approx(1.05, abs=1e-4)


def _sense(eigenvalue: complex, y: complex, z: complex) -> float:
    """The ellipticity of the path (y, z) of a mode, in [-1, 1]: +-1 a circle, 0 a line; its
    sign tells the two senses apart."""
    return float(2 * np.imag(np.conj(y) * z) * np.sign(eigenvalue.imag)
                 / (abs(y) ** 2 + abs(z) ** 2))


def test_the_unstable_modes_are_the_gimbals_and_none_whirls_forward(gimbal_law):
    """Up to 25 m/s every unstable oscillatory mode is mostly gimbal (kinetic energy of beta over
    theta, psi), as whirl's linear sweep labels it, with whirl's whirl sense; those whose disc
    normal turns in the sense opposite to the classical model's flutter mode (BW, K_beta = 1e6
    here), forward, move in a line (ellipticity below 0.02), so no forward-whirl mode goes
    unstable; backward ones whirl (ellipticity up to above 0.8)."""
    eigenvalues, vectors = np.linalg.eig(_linear(9.0, {**VALUES, "K_beta": 1e6}))
    k = int(np.argmax(eigenvalues.real + 1e-6 * np.sign(eigenvalues.imag)))
    backward = np.sign(_sense(eigenvalues[k], vectors[1, k], -vectors[0, k]))
    (sweep,) = gimbal_law.linear_sweeps  # the study's, along V
    senses = []
    for row, v in enumerate(sweep.values):
        if v == 0:  # the strip theory's limit mu -> 0, not written out here
            continue
        eigenvalues, vectors = np.linalg.eig(_linear(v))
        mass = matrices({**VALUES, "V": v}, shaft=True)[0]
        for k in np.flatnonzero((eigenvalues.real > 1e-6) & (np.abs(eigenvalues.imag) > 1e-6)):
            q = vectors[:4, k]
            energy = [np.real(np.conj(q[s]) @ mass[s, s] @ q[s])
                      for s in (slice(0, 2), slice(2, 4))]
            assert energy[1] > energy[0]
            sense = backward * _sense(eigenvalues[k], q[1] + q[3], -(q[0] + q[2]))
            j = int(np.argmin(np.abs(sweep.eigenvalues[row] - eigenvalues[k])))
            assert abs(sweep.eigenvalues[row, j] - eigenvalues[k]) < 1e-6 * abs(eigenvalues[k])
            assert sweep.mode_group[row, j] == "gimbal"
            assert sweep.whirl[row, j] == ("BW" if sense > 0 else "FW")
            senses.append(sense)
    senses = np.array(senses)
    print(f"\n  {len(senses)} unstable modes, ellipticity {senses.min():.4f} to {senses.max():.4f}")
    assert len(senses) > 50
    assert senses.min() > -0.02 and senses.max() > 0.8


def _settle(v: float, beta_deg: float, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """The states over the last quarter of a scipy simulation from a gimbal tilt about z (the
    cycle's larger gimbal motion)."""
    f, _ = _field(v)
    y0 = np.zeros(8)
    y0[3] = np.radians(beta_deg)
    sol = solve_ivp(f, (0, duration), y0, method="LSODA", rtol=1e-9, atol=1e-12,
                    t_eval=np.linspace(0.75 * duration, duration, 20001))
    return sol.t, sol.y


def test_stable_cycles_exist_below_the_linear_onset(gimbal_law):
    """The Hopf point at the onset is subcritical and the family turns back at a fold of cycles
    below it: between the fold and the onset a 10 deg gimbal tilt settles (scipy) on a cycle of
    AUTO's amplitudes of both gimbal dofs (2 %) and period (1 %) while a 0.5 deg one decays;
    0.1 m/s below the fold the 10 deg one decays too."""
    gimbal_law = _only(gimbal_law)
    hopf = min(_points(gimbal_law, PointType.HB, "main"), key=lambda p: p.parameters[0])
    fold = min(_points(gimbal_law, PointType.LPC), key=lambda p: p.parameters[0])
    assert hopf.parameters[0] - 0.3 < fold.parameters[0] < hopf.parameters[0] - 0.05
    branch = next(b for b in gimbal_law.branches if b.name == fold.branch)
    v = fold.parameters[0] + 0.5 * (hopf.parameters[0] - fold.parameters[0])
    assert np.linalg.eigvals(_linear(v)).real.max() < 0
    stable = np.flatnonzero(branch.stable & (np.arange(len(branch)) > fold.index))
    row = stable[np.argmin(np.abs(branch.parameters[stable, 0] - v))]
    v = float(branch.parameters[row, 0])
    t, y = _settle(v, 10.0, 200.0)
    amplitude = np.abs(y[2:4]).max(axis=1)
    auto = np.maximum(branch.state_max[row, 2:4], -branch.state_min[row, 2:4])
    crossings = t[1:][(y[7, :-1] < 0) & (y[7, 1:] >= 0)]
    print(f"\n  V = {v:.4f}: scipy beta {np.degrees(amplitude).round(3)} deg, period "
          f"{np.diff(crossings).mean():.4f} s; AUTO {np.degrees(auto).round(3)}, "
          f"{branch.period[row]:.4f}")
    np.testing.assert_allclose(amplitude, auto, rtol=0.02)
    assert np.diff(crossings).mean() == pytest.approx(branch.period[row], rel=0.01)
    assert np.abs(_settle(v, 0.5, 100.0)[1][2:4]).max() < np.radians(0.05)
    below = fold.parameters[0] - 0.1
    assert np.abs(_settle(below, 10.0, 200.0)[1][2:4]).max() < np.radians(0.5)


def _monodromy(v: float, start: np.ndarray, period: float, laws=GIMBAL_LAWS) -> np.ndarray:
    """The monodromy matrix of the orbit through ``start`` (derivation frame), scipy."""
    f, jac = _field(v, laws)

    def variational(t, z):
        y, phi = z[:8], z[8:].reshape(8, 8)
        return np.concatenate([f(t, y), (jac(y) @ phi).ravel()])
    sol = solve_ivp(variational, (0, period), np.concatenate([start, np.eye(8).ravel()]),
                    method="DOP853", rtol=1e-11, atol=1e-12)
    return sol.y[8:, -1].reshape(8, 8)


def test_floquet_multipliers_are_the_monodromy_matrix_eigenvalues(gimbal_law):
    """At every stored orbit but the folds' and branch points' and those whose period has
    grown past twice the Hopf point's (near the homoclinic end; among them, at V = 15.9 m/s,
    the stable and the unstable cycle between the fold and the onset) the eigenvalues of the
    monodromy matrix, integrated with scipy over AUTO's orbit, are AUTO's multipliers: those
    that decide stability (|mu| >= 0.2) to 1e-3, the strongly contracting ones to 1e-2."""
    gimbal_law = _only(gimbal_law)
    branch = next(b for b in gimbal_law.branches if b.name == "periodic_1")
    hopf = min(_points(gimbal_law, PointType.HB, "main"), key=lambda p: p.parameters[0])
    largest = []
    for orbit in branch.orbits:
        if orbit.point_type in (PointType.LPC, PointType.BPC):
            continue  # a Jordan block at 1: its eigenvalues move by the root of the error
        if orbit.period > 2 * hopf.period:
            continue  # near a homoclinic orbit: the monodromy matrix is ill-conditioned
        ours = np.linalg.eigvals(_monodromy(float(orbit.parameters[0]), orbit.states[0] * FRAME,
                                            orbit.period))
        auto = branch.eigenvalues[orbit.index]
        print(f"\n  V = {orbit.parameters[0]:.4f}: |mu| ours {np.round(np.sort(np.abs(ours)), 4)}, "
              f"AUTO {np.round(np.sort(np.abs(auto)), 4)}")
        for mu in auto[np.isfinite(auto)]:
            assert np.min(np.abs(ours - mu)) < (1e-3 * max(1.0, abs(mu)) if abs(mu) >= 0.2
                                                else 1e-2)
        largest.append(np.abs(ours).max())
    assert max(largest) > 1.05 and min(largest) < 1 + 1e-3


def test_the_period_doubled_family_starts_where_a_multiplier_is_minus_one(gimbal_law):
    """The family's period-doubling point: the monodromy matrix of AUTO's orbit there has an
    eigenvalue at -1 (1e-2), and the doubled family (``period_doubling: true``) starts at its
    airspeed with twice its period (1e-3)."""
    gimbal_law = _only(gimbal_law)
    (doubling,) = [p for p in _points(gimbal_law, PointType.PD) if p.branch == "periodic_1"]
    family = next(b for b in gimbal_law.branches if b.name == "periodic_1")
    orbit = next(o for o in family.orbits if o.index == doubling.index)
    ours = np.linalg.eigvals(_monodromy(float(orbit.parameters[0]), orbit.states[0] * FRAME,
                                        orbit.period))
    print(f"\n  PD at V = {doubling.parameters[0]:.5f}: multipliers {np.round(ours, 4)}")
    assert np.min(np.abs(ours + 1)) < 1e-2
    doubled = next(b for b in gimbal_law.branches if b.name == "periodic_1_pd1")
    assert doubled.parameters[0, 0] == pytest.approx(doubling.parameters[0], rel=1e-5)
    assert doubled.period[0] == pytest.approx(2 * doubling.period, rel=1e-3)


def _first_onset(values: dict) -> float:
    """V where the numpy eigenvalues' largest real part first crosses zero on 0.2-25 m/s."""
    return _roots(lambda v, values: np.linalg.eigvals(_linear(v, values)).real.max(),
                  0.2, 25.0, values)[0]


def test_each_onset_locus_point_is_a_numpy_critical_point(onset):
    """From 1.02/rev to beyond the thesis' K_beta = 10 (11/rev), each point of a Hopf locus in
    (V, K_beta) has a pair of eigenvalues of opposite sign (a Hopf point, or past a
    Bogdanov-Takens point a neutral saddle), a pair on the imaginary axis at the locus' period
    where that is below 5 s (1e-3); each point of a branch-point locus has a singular K (its
    smallest eigenvalue below 1e-5 of its largest). The Hopf loci span the K_beta range, with
    points enough to draw over 1.02-1.10/rev alone."""
    loci = _loci(onset)
    checked = 0
    for branch in loci["hopf"]:
        for (v, k_beta), period in zip(branch.parameters[::4, :2], branch.period[::4],
                                       strict=True):
            eigenvalues = np.linalg.eigvals(_linear(v, {**VALUES, "K_beta": k_beta}))
            sums = np.abs(eigenvalues[:, None] + eigenvalues[None, :])
            np.fill_diagonal(sums, np.inf)
            assert sums.min() < 1e-4 * np.abs(eigenvalues).max()
            if period < 5.0:
                omega = 2 * np.pi / period
                assert np.abs(eigenvalues - 1j * omega).min() < 1e-3 * omega
            checked += 1
    for branch in loci["branch_point"]:
        for v, k_beta in branch.parameters[::4, :2]:
            stiffness = np.abs(np.linalg.eigvals(
                matrices({**VALUES, "K_beta": k_beta, "V": v}, shaft=True)[2]))
            assert stiffness.min() < 1e-5 * stiffness.max()
            checked += 1
    assert checked > 100
    k_beta = np.concatenate([b.parameters[:, 1] for b in loci["hopf"]])
    assert k_beta.min() == pytest.approx(K_BETA_RANGE[0], abs=1e-6)
    assert k_beta.max() == pytest.approx(K_BETA_RANGE[1], abs=1e-6)
    assert np.count_nonzero(k_beta <= K_BETA_ENDS[1]) > 20


def test_the_first_onset_is_the_lowest_locus_crossing_at_each_gimbal(onset):
    """At K_beta log-spaced over the study's range and at 1.02, 1.05 and 1.10/rev the lowest V
    where a locus crosses that K_beta (interpolated between locus points) is where the numpy
    eigenvalues' largest real part first crosses zero (1e-3), above 7.3 m/s everywhere. At
    1.02/rev the first onset is flutter (an oscillatory pair crosses), at 1.10/rev divergence
    (det K = 0, no Hopf point below it); the slice at K_beta = 10 has its first Hopf point at the
    numpy onset (1e-4), between 7.3 and a rigid rotor's (K_beta = 1e6)."""
    loci = _loci(onset)
    branches = loci["hopf"] + loci["branch_point"]
    for k_beta in (*K_BETA_ENDS, VALUES["K_beta"], *np.geomspace(*K_BETA_RANGE, 7)[1:-1]):
        values = {**VALUES, "K_beta": k_beta}
        first = _first_onset(values)
        crossings = np.concatenate([_at_k_beta(b.parameters[:, :2], k_beta) for b in branches])
        assert crossings.size
        print(f"\n  K_beta = {k_beta:.5g}: lowest locus crossing {crossings.min():.5f}, "
              f"numpy {first:.5f} m/s")
        assert crossings.min() == pytest.approx(first, rel=1e-3)
        assert first > 7.3
    low, high = ({**VALUES, "K_beta": k} for k in K_BETA_ENDS)
    assert _hopf_speeds(10.0, 25.0, low)[0] == pytest.approx(_first_onset(low), rel=1e-6)
    divergence = _roots(_stiffness_determinant, 10.0, 25.0, high)[0]
    assert divergence == pytest.approx(_first_onset(high), rel=1e-6)
    assert not _hopf_speeds(10.0, divergence, high)
    thesis = {**VALUES, "K_beta": 10.0}
    (hopf, *_) = sorted((p for p in _points(onset, PointType.HB, "slice_1")),
                        key=lambda p: p.parameters[0])
    assert hopf.parameters[1] == pytest.approx(10.0)
    assert hopf.parameters[0] == pytest.approx(_first_onset(thesis), rel=1e-4)
    assert 7.3 < hopf.parameters[0] < _first_onset({**VALUES, "K_beta": 1e6})


def test_the_onset_map_draws_k_beta_on_a_log_axis_over_the_stored_log_grid(onset_study):
    """The study's grid samples K_beta log from 1.02/rev to beyond 11/rev: its map draws K_beta
    (y) on a log axis over that range and V (x) linear, the loci drawn across it (in pieces: they
    cross at tiltrotor gimbals), more than 20 of their points over 1.02-1.10/rev."""
    import matplotlib.pyplot as plt

    grid = onset_study.linear_grid
    assert grid.x_parameter == "K_beta" and grid.x_spacing == Spacing.LOG
    ratios = grid.x[1:] / grid.x[:-1]
    np.testing.assert_allclose(ratios, ratios[0], rtol=1e-12)
    ((_, figure), *_) = study_figures(onset_study, ("boundary",), "s")
    try:
        ax = figure.axes[0]
        assert (ax.get_xscale(), ax.get_yscale()) == ("linear", "log")
        low, high = ax.get_ylim()
        assert low == pytest.approx(K_BETA_RANGE[0]) and high == pytest.approx(K_BETA_RANGE[1])
        drawn = np.concatenate([np.asarray(line.get_ydata(), dtype=float) for line in ax.lines])
        assert drawn.min() < 0.0034 and drawn.max() > 10.0
        assert np.count_nonzero(drawn <= K_BETA_ENDS[1]) > 20
    finally:
        plt.close(figure)


def _loci(onset) -> dict:
    return {kind: [b for b in onset.branches if b.name.startswith(kind)]
            for kind in ("hopf", "branch_point")}


def _at_k_beta(points: np.ndarray, k_beta: float) -> np.ndarray:
    """V where the locus through ``points`` (rows V, K_beta) crosses or touches ``k_beta``,
    linearly interpolated."""
    v, k = points[:, 0], points[:, 1] - k_beta
    found = [v[i] if k[i] == 0 else v[i] + (v[i + 1] - v[i]) * k[i] / (k[i] - k[i + 1])
             for i in range(len(k) - 1) if k[i] * k[i + 1] <= 0 and k[i] != k[i + 1]]
    return np.array(found + ([v[-1]] if k[-1] == 0 else []))


def _benettin(v: float, transient: float, steps: int, laws=PITCH_LAWS) -> float:
    """Largest Lyapunov exponent (1/s, Benettin: a tangent vector renormalised every 1 s) from
    the explore's default start, pitch at 2 deg."""
    f, jac = _field(v, laws)
    y = np.zeros(8)
    y[0] = np.radians(2.0)
    y = solve_ivp(f, (0, transient), y, method="DOP853", rtol=1e-8, atol=1e-11).y[:, -1]
    d = np.full(8, 8 ** -0.5)
    total = 0.0

    def tangent(t, z):
        return np.concatenate([f(t, z[:8]), jac(z[:8]) @ z[8:]])
    for _ in range(steps):
        z = solve_ivp(tangent, (0, 1.0), np.concatenate([y, d]), method="DOP853", rtol=1e-8,
                      atol=1e-11).y[:, -1]
        y, growth = z[:8], np.linalg.norm(z[8:])
        total, d = total + np.log(growth), z[8:] / growth
    return total / steps


def _explored(continuation, value: float):
    return next(e for e in continuation.explorations if e.value == pytest.approx(value))


def test_explore_finds_rest_at_the_origins_decay_rate_below_the_onset(pitch_law):
    """At 5, 10 and 15 m/s the explore finds rest, its Lyapunov exponent the largest real part
    of the numpy eigenvalues at the origin (within three of its standard errors and 1 %)."""
    for value in (5.0, 10.0, 15.0):
        found = _explored(pitch_law, value)
        ours = np.linalg.eigvals(_linear(value)).real.max()
        print(f"\n  V = {value}: whirl {found.kind}, {found.lyapunov:.4f} +- "
              f"{found.lyapunov_error:.2g}; numpy {ours:.4f} 1/s")
        assert found.kind == MotionKind.EQUILIBRIUM
        assert abs(found.lyapunov - ours) < 3 * found.lyapunov_error + 0.01 * abs(ours)


def _settled_period(v: float) -> tuple[float, float]:
    """(mean, relative spread) of the intervals between upward zero crossings of the gimbal
    rate dbeta_z over 30-60 s of a scipy simulation from the explore's start."""
    f, _ = _field(v, PITCH_LAWS)
    y0 = np.zeros(8)
    y0[0] = np.radians(2.0)
    t = np.arange(30.0, 60.0, 1e-3)
    rate = solve_ivp(f, (0, 60.0), y0, method="DOP853", rtol=1e-9, atol=1e-12,
                     t_eval=t).y[7]
    k = np.flatnonzero((rate[:-1] < 0) & (rate[1:] >= 0))
    crossings = t[k] - rate[k] * (t[k + 1] - t[k]) / (rate[k + 1] - rate[k])
    intervals = np.diff(crossings)
    return float(intervals.mean()), float(intervals.std() / intervals.mean())


def test_above_the_onset_the_motion_settles_on_the_cycle_auto_continues(pitch_law):
    """The Hopf point is supercritical (no cycle below it): at AUTO's stable cycle nearest
    16.2 m/s a scipy simulation from the explore's start settles on a cycle of AUTO's period
    (1e-3; crossing intervals equal to 1e-5); at 16.2 m/s the explore calls the motion
    periodic at the simulated cycle's frequency (1 %), and a Benettin estimate written here
    (10 s transient, 30 s of tangent growth) finds no positive exponent beyond its finite-time
    bias (below 0.1 1/s; chaos here would be of order 1 1/s) where whirl's is 0 within three of
    its standard errors and 0.05 1/s."""
    family = next(b for b in pitch_law.branches if b.name == "periodic_1")
    hopf = min(_points(pitch_law, PointType.HB, "main"), key=lambda p: p.parameters[0])
    assert family.parameters[:, 0].min() >= hopf.parameters[0] - 1e-6
    stable = np.flatnonzero(family.stable)
    row = stable[np.argmin(np.abs(family.parameters[stable, 0] - 16.2))]
    v = float(family.parameters[row, 0])
    period, spread = _settled_period(v)
    found = _explored(pitch_law, 16.2)
    at_value, _ = _settled_period(16.2)
    ours = _benettin(16.2, 10.0, 30)
    print(f"\n  V = {v:.4f}: scipy period {period:.5f} s (spread {spread:.1e}), AUTO "
          f"{family.period[row]:.5f}; V = 16.2: scipy {1 / at_value:.4f} Hz, whirl "
          f"{found.kind} {found.frequencies}, lambda {found.lyapunov:.4f} +- "
          f"{found.lyapunov_error:.2g}; Benettin {ours:.4f}")
    assert abs(v - 16.2) < 0.1
    assert spread < 1e-5
    assert period == pytest.approx(family.period[row], rel=1e-3)
    assert found.kind == MotionKind.PERIODIC
    assert found.frequencies[0] == pytest.approx(1 / at_value, rel=0.01)
    assert ours < 0.1
    assert abs(found.lyapunov) < 3 * found.lyapunov_error + 0.05


def test_past_the_cycles_end_the_motion_diverges_and_nothing_is_chaotic(pitch_law):
    """From 17 m/s on the explore calls the motion diverged, and a scipy simulation from its
    start leaves 10 rad within 5 s at 17 and 25 m/s; no explored value is quasi-periodic or
    chaotic, and no family has a period-doubling or torus point."""
    for value in (17.0, 25.0):
        assert _explored(pitch_law, value).kind == MotionKind.DIVERGED
        f, _ = _field(value, PITCH_LAWS)

        def escaped(_t, y):
            return np.abs(y[:4]).max() - 10.0
        escaped.terminal = True
        y0 = np.zeros(8)
        y0[0] = np.radians(2.0)
        sol = solve_ivp(f, (0, 5.0), y0, method="LSODA", rtol=1e-8, atol=1e-11,
                        events=escaped)
        assert sol.status == 1
    kinds = {e.kind for e in pitch_law.explorations}
    assert not kinds & {MotionKind.QUASI_PERIODIC, MotionKind.CHAOTIC}
    assert not _points(pitch_law, PointType.PD) + _points(pitch_law, PointType.TR)
