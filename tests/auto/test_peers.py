"""The peer cases of Gali, Goehmann & Riso (J. Fluids Struct. 2023; code
cristinariso/propeller-nacelle, source [RISO] of ../shared/models.md) as whirl studies
(``studies/peers/``), run once each with the real AUTO-07p and checked by independent methods:
eigenvalues for the Hopf point, the side of the periodic family against the eigenvalues' growth
direction and the first Lyapunov coefficient for its criticality, and time simulation of a
right-hand side written here from models.md section 2 (not whirl's generated one) for the
stable limit cycles and the fold of cycles."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import odeint
from scipy.optimize import brentq

from whirl_cli.analysis import linear
from whirl_cli.models import get_model
from whirl_cli.pipeline import run_study
from whirl_cli.results import BranchKind, PointType
from whirl_cli.study import load_study

from ..conftest import ROOT

PEERS = ROOT / "studies" / "peers"
CASES = {"supercritical": (10.0, 0.0), "subcritical": (-10.0, 350.0)}  # (K2, K3), both dofs
RANGE = (6.5, 8.3)

# models.md section 3 (thesis table 3.1 with C_l_alpha = 2 pi, rho = 1.225), as in Riso's
# load_parameters_*.m
R, OMEGA, BLADES, CHORD, CLA, A, I_X, I_Y, DAMPING, RHO, K = (
    0.152, 40.0, 4, 0.026, 2 * np.pi, 0.25, 0.000103, 0.000178, 0.001, 1.225, 0.4)


def _aerodynamics(v: float) -> tuple[float, float, float]:
    """(k_d, k_c, c_a) at airspeed ``v``: the closed-form radial integrals of models.md 2.2."""
    mu = v / (OMEGA * R)
    arsinh, root, ratio = np.arcsinh(1 / mu), np.sqrt(1 + mu * mu), CHORD / R
    a1 = ratio * mu * mu * arsinh
    a2 = ratio * mu / 2 * (root - mu * mu * arsinh)
    a3 = ratio * ((2 - 3 * mu * mu) * root + 3 * mu ** 4 * arsinh) / 8
    q = BLADES * RHO * CLA * R ** 5 * OMEGA ** 2 / 4
    return q * A * mu * a1, q * mu * a2, q * (a3 + A * A * a1) / OMEGA


def _field(v: float, k2: float, k3: float):
    """The first-order equations of models.md 2.3 with the law K x + K2 x^3 + K3 x^5 on pitch
    and on yaw, as Riso's dydt.m adds it to both (state theta, psi, theta', psi')."""
    k_d, k_c, c_a = _aerodynamics(v)

    def field(y, _t=0.0):
        theta, psi, dtheta, dpsi = y
        pitch = K * theta + k2 * theta ** 3 + k3 * theta ** 5
        yaw = K * psi + k2 * psi ** 3 + k3 * psi ** 5
        return [dtheta, dpsi,
                (-pitch + k_d * theta - k_c * psi - (DAMPING + c_a) * dtheta
                 + I_X * OMEGA * dpsi) / I_Y,
                (k_c * theta - yaw + k_d * psi - I_X * OMEGA * dtheta
                 - (DAMPING + c_a) * dpsi) / I_Y]

    return field


def _growth(v: float) -> float:
    """Largest real part of the eigenvalues of the linearisation at the origin (the laws add
    nothing there)."""
    k_d, k_c, c_a = _aerodynamics(v)
    damping = (DAMPING + c_a) / I_Y
    jacobian = np.array([[0, 0, 1, 0], [0, 0, 0, 1],
                         [(k_d - K) / I_Y, -k_c / I_Y, -damping, I_X * OMEGA / I_Y],
                         [k_c / I_Y, (k_d - K) / I_Y, -I_X * OMEGA / I_Y, -damping]])
    return float(np.linalg.eigvals(jacobian).real.max())


def _simulate(v, k2, k3, start, duration, samples):
    times = np.linspace(0.0, duration, samples)
    return times, odeint(_field(v, k2, k3), np.asarray(start, dtype=float), times,
                         rtol=1e-9, atol=1e-12, mxstep=100_000)


@pytest.fixture(scope="module")
def peers(tmp_path_factory):
    """{case: (study, result)}: each study run once."""
    runs = {}
    for case in CASES:
        study = load_study(PEERS / f"riso2023_{case}.yaml")
        runs[case] = study, run_study(study, tmp_path_factory.mktemp(case), jobs=2)
    return runs


def _periodic(result):
    return [b for b in result.continuations[0].branches if b.kind == BranchKind.PERIODIC]


def _points(result, kind):
    return [p for p in result.continuations[0].special_points if p.point_type == kind]


def _main_hopf(result):
    (hopf,) = [p for p in _points(result, PointType.HB) if p.branch.startswith("main")]
    return hopf


@pytest.mark.parametrize("case", CASES)
def test_the_study_is_riso_s_case(peers, case):
    """The same law on pitch and yaw, at the datum stiffnesses (Riso's K3t = K3p, K5t = K5p),
    and whirl's right-hand side is the one written here from models.md."""
    study, _ = peers[case]
    k2, k3 = CASES[case]
    values = study.parameter_values()
    assert {n: values[n] for n in ("K_theta", "K_psi", "K2_theta", "K3_theta", "K2_psi",
                                   "K3_psi")} == {"K_theta": K, "K_psi": K, "K2_theta": k2,
                                                  "K3_theta": k3, "K2_psi": k2, "K3_psi": k3}
    model = get_model("classical")
    rng = np.random.default_rng(7)
    for v in (6.5, 7.4, 8.3):
        params = model.parameter_vector({**values, "V": v})
        for y in rng.normal(scale=[0.2, 0.2, 2.0, 2.0], size=(5, 4)):
            np.testing.assert_allclose(model.rhs_numpy(y, params), _field(v, k2, k3)(y),
                                       rtol=1e-12, atol=1e-10)


@pytest.mark.parametrize("case", CASES)
def test_hopf_point_at_the_linear_onset(peers, case, capsys):
    """One Hopf point on the undeflected branch, at the eigenvalue onset (whirl's eigenvalue
    scan, and the closed-form matrix here: 7.764 m/s, models.md 4), to 1e-5 m/s."""
    study, result = peers[case]
    (onset,) = linear.critical_points(get_model("classical"), study.parameter_values(), "V",
                                      *RANGE)
    assert onset.kind == "hopf"
    by_hand = brentq(_growth, *RANGE, xtol=1e-12)
    assert onset.value == pytest.approx(by_hand, abs=1e-9)
    assert by_hand == pytest.approx(7.764, abs=5e-4)
    hopf = _main_hopf(result)
    assert np.abs(hopf.state).max() < 1e-9  # the undeflected branch
    with capsys.disabled():
        print(f"\nriso2023 {case}: AUTO Hopf V = {hopf.parameters[0]:.7f} m/s, eigenvalues "
              f"{onset.value:.7f} m/s (difference {hopf.parameters[0] - onset.value:.1e})")
    assert hopf.parameters[0] == pytest.approx(onset.value, abs=1e-5)
    assert [p.branch for p in _points(result, PointType.HB)] == [hopf.branch]


@pytest.mark.parametrize("case", CASES)
def test_criticality_by_the_family_and_by_the_lyapunov_coefficient(peers, case, capsys):
    """The family's verdict, found here: the side of V its periodic family leaves the Hopf
    point on, against the side where the origin is unstable (the sign of the growth rate of
    the closed-form matrix at V_H +/- 1e-4): supercritical iff the same. The normal form's:
    l1 < 0 supercritical. Both, and whirl's label, give the study's name. l1 depends on the
    cubic coefficient only, linearly (the origin is a symmetric equilibrium: no quadratic
    terms, and the quintic terms are of fifth order), so the two cases have opposite l1."""
    _, result = peers[case]
    hopf = _main_hopf(result)
    value = float(hopf.parameters[0])
    families = [b for b in _periodic(result)
                if (b.origin.point, b.origin.parameter) == (PointType.HB, "V")
                and b.origin.branch == hopf.branch]
    assert len(families) == 1
    (family,) = families
    assert family.parameters[0, 0] == pytest.approx(value, abs=1e-9)
    assert (family.state_max[0, 0] - family.state_min[0, 0]) < 1e-6
    side = np.sign(family.parameters[1:6, 0] - value)
    assert len(set(side)) == 1
    unstable = np.sign(_growth(value + 1e-4))
    assert unstable == -np.sign(_growth(value - 1e-4)) == 1.0  # unstable above the onset
    by_family = "supercritical" if side[0] == unstable else "subcritical"
    by_lyapunov = "supercritical" if hopf.lyapunov < 0 else "subcritical"
    with capsys.disabled():
        print(f"\nriso2023 {case}: family leaves V_H towards {'higher' if side[0] > 0 else 'lower'}"
              f" V -> {by_family}; l1 = {hopf.lyapunov:.6g} -> {by_lyapunov}; whirl: "
              f"{hopf.criticality}")
    assert by_family == by_lyapunov == hopf.criticality == case
    # the family is born unstable (subcritical) or stable (supercritical) beside the Hopf point
    assert bool(family.stable[1:4].all()) == (case == "supercritical")
    other = _main_hopf(peers["supercritical" if case == "subcritical" else "subcritical"][1])
    assert hopf.lyapunov == pytest.approx(-other.lyapunov, rel=1e-6)


@pytest.mark.parametrize("case", CASES)
def test_cross_checks_pass_on_every_stable_periodic_branch(peers, case):
    """The study's own time-simulation cross-checks all pass and cover every stable periodic
    branch (as for the chapter-3 cases in test_periodic.py); every branch ends ok."""
    _, result = peers[case]
    (continuation,) = result.continuations
    checks = continuation.cross_checks
    assert checks and all(c.passed for c in checks), [c for c in checks if not c.passed]
    families = _periodic(result)
    assert families
    for branch in families:
        checkable = [o for o in branch.orbits if 0 < o.index < len(branch) - 1
                     and branch.stable[o.index - 1: o.index + 2].all()
                     and o.period < 3 * branch.period[0]]
        assert checkable, branch.name  # both families have stable orbits
        assert any(c.branch == branch.name and c.kind == "orbit" for c in checks), branch.name
    assert all(b.status == "ok" for b in continuation.branches), [
        (b.name, b.message) for b in continuation.branches if b.status != "ok"]


# Riso's time-marching starts (load_parameters_*.m: pitch 6 and 15 degrees, the rest zero) and
# the stored stable orbit nearest the airspeed simulated
RISO_STARTS = {"supercritical": (6.0, 8.07), "subcritical": (15.0, 7.47)}


@pytest.mark.parametrize("case", CASES)
def test_a_stable_lco_is_reached_from_riso_s_start(peers, case, capsys):
    """From Riso's initial condition (pitch deflection only) at the airspeed of a stored stable
    orbit, the simulation here settles onto AUTO's cycle: its largest pitch over the last
    second within 1 % of AUTO's (and the motion over the last 5 s is periodic at that
    amplitude, not still growing or decaying)."""
    _, result = peers[case]
    degrees, near = RISO_STARTS[case]
    k2, k3 = CASES[case]
    (family,) = _periodic(result)
    orbit = min((o for o in family.orbits if family.stable[o.index]),
                key=lambda o: abs(o.parameters[0] - near))
    assert abs(orbit.parameters[0] - near) < 0.02
    expected = float(family.state_max[orbit.index, 0])
    times, states = _simulate(float(orbit.parameters[0]), k2, k3,
                              [np.radians(degrees), 0, 0, 0], 15.0, 15 * 2000)
    windows = [states[(times > t - 1) & (times <= t), 0].max() for t in (11.0, 13.0, 15.0)]
    with capsys.disabled():
        print(f"\nriso2023 {case}: from {degrees:g} deg pitch at V = {orbit.parameters[0]:.4f}"
              f" m/s: simulated max pitch {windows[-1]:.5f} rad, AUTO {expected:.5f} rad "
              f"({windows[-1] / expected - 1:+.1e})")
    assert windows[-1] == pytest.approx(expected, rel=0.01)
    assert np.ptp(windows) < 1e-3 * expected


def test_fold_of_cycles_bracketed_by_simulation(peers, capsys):
    """The subcritical family turns back at a fold of cycles below the onset, where it becomes
    stable. By simulation (the approach of test_periodic._fold_of_cycles_by_simulation, with
    the right-hand side here): a start on AUTO's fold orbit (its point of largest pitch,
    enlarged 1 %), 1e-3 m/s above the fold still oscillates at about its amplitude after 400
    periods; 1e-3 m/s below it decays to the origin. The supercritical family has no fold."""
    assert not _points(peers["supercritical"][1], PointType.LPC)
    _, result = peers["subcritical"]
    k2, k3 = CASES["subcritical"]
    (fold,) = _points(result, PointType.LPC)
    (family,) = [b for b in _periodic(result) if b.name == fold.branch]
    value, k = float(fold.parameters[0]), fold.index
    assert value < _main_hopf(result).parameters[0] - 0.5  # well below the onset
    assert family.stable[k + 2] and not family.stable[k - 2]
    lco_side = float(np.sign(family.parameters[k + 2, 0] - value))
    assert lco_side == 1.0  # the stable cycles lie above the fold
    orbit = next(o for o in family.orbits if o.index == k)
    start = 1.01 * orbit.states[int(np.argmax(orbit.states[:, 0]))]
    d, periods = 1e-3, 400
    left = {}
    for side in (1.0, -1.0):
        _, states = _simulate(value + side * d, k2, k3, start, periods * orbit.period,
                              periods * 40)
        left[side] = float(np.abs(states[-400:, 0]).max() / abs(start[0]))
    with capsys.disabled():
        print(f"\nriso2023 subcritical fold of cycles: AUTO V = {value:.5f} m/s; by simulation"
              f" in [{value - d:.5f}, {value + d:.5f}]: pitch left after {periods} periods "
              f"{left[1.0]:.3f} (above) and {left[-1.0]:.1e} (below) of the start's")
    assert 0.9 < left[1.0] < 1.1 and left[-1.0] < 0.01
