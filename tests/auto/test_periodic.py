"""Periodic branches from every Hopf point (real AUTO-07p), checked independently: closed forms
of the equilibria they hang off, eigenvalue-based Hopf criticality, and time simulation."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from whirl_cli.analysis import linear, simulate
from whirl_cli.models import get_model
from whirl_cli.pipeline import run_study
from whirl_cli.results import BranchKind, PointType
from whirl_cli.study import load_study, validate_text

from ..conftest import STUDIES

NONLINEAR = [f"{v}_case{c}" for v in ("hardening", "softening", "combined") for c in range(1, 6)]


def _periodic(result):
    return [b for b in result.continuations[0].branches if b.kind == BranchKind.PERIODIC]


def _points(result, kind):
    return [p for p in result.continuations[0].special_points if p.point_type == kind]


def _hopf(result, value, branch="main_down"):
    (point,) = [p for p in _points(result, PointType.HB)
                if p.branch == branch and abs(p.parameters[0] - value) < 2e-3]
    return point


def _equilibrium(model, params, guess):
    """The equilibrium nearest ``guess`` by Newton's method on the numpy right-hand side."""
    state = np.asarray(guess, dtype=float)
    for _ in range(50):
        step = np.linalg.solve(model.jacobian_numpy(state, params), model.rhs_numpy(state, params))
        state = state - step
        if np.abs(step).max() < 1e-15:
            break
    assert np.abs(model.rhs_numpy(state, params)).max() < 1e-10, state
    return state


def _pitch_amplitude(branch):
    """(N,) half the peak-to-peak pitch of each orbit, rad."""
    return (branch.state_max[:, 0] - branch.state_min[:, 0]) / 2


def test_hardening_case2_flutter_branch_joins_the_two_hopf_points(run_thesis):
    result = run_thesis("hardening_case2")
    main = [b for b in _periodic(result) if b.origin.branch == "main_down"]
    assert len(main) == 1  # reached from both Hopf points, stored once
    (flutter,) = main
    # both ends at the Hopf points of the eigenvalues (models.md 4: 0.0807 and 0.2888)
    left, right = (c.value for c in linear.critical_points(
        get_model("classical"), {"K_psi": 0.3}, "K_theta", -0.3, 0.5) if c.kind == "hopf")
    k1, amplitude = flutter.parameter("K_theta"), _pitch_amplitude(flutter)
    assert k1[0] == pytest.approx(right, abs=1e-6) and amplitude[0] < 1e-9
    # the other end: the orbit has shrunk onto the left Hopf point; with the Hopf normal form
    # (K1 - K1_H proportional to the squared amplitude) the last two orbits extrapolate to it
    assert amplitude[-1] < 0.05 * amplitude.max()
    assert k1[-1] == pytest.approx(left, abs=5e-4)
    squared = amplitude[-2:] ** 2
    at_zero = k1[-1] - squared[-1] * (k1[-1] - k1[-2]) / (squared[-1] - squared[-2])
    assert at_zero == pytest.approx(left, abs=3e-5), (at_zero, left)
    # a fold of cycles left of the left Hopf point, and an unstable part there
    folds = [p for p in _points(result, PointType.LPC) if p.branch == flutter.name]
    assert any(p.parameters[0] < 0.0807 - 0.01 for p in folds)
    k1, stable = flutter.parameter("K_theta"), flutter.stable
    assert not stable[k1 < 0.075].all()
    # the rest (well right of the left Hopf) is stable
    assert stable[(k1 > 0.09) & (np.arange(len(k1)) > 0)].all()
    assert _hopf(result, 0.2888).criticality == "supercritical"
    assert _hopf(result, 0.0807).criticality == "subcritical"


def test_hardening_case2_secondary_flutter(run_thesis):
    """Each stable secondary equilibrium branch has its own Hopf pair and secondary-flutter
    branch joining them."""
    result = run_thesis("hardening_case2")
    for side in ("secondary_1a", "secondary_1b"):
        hopfs = sorted(p.parameters[0] for p in _points(result, PointType.HB)
                       if p.branch == side)
        assert len(hopfs) == 2
        (family,) = [b for b in _periodic(result) if b.origin.branch == side]
        assert family.end.startswith("returns to HB") and family.end.endswith(side)
        ends = sorted([family.parameter("K_theta")[0], family.parameter("K_theta")[-1]])
        np.testing.assert_allclose(ends, hopfs, atol=2e-3)
        assert family.stable[1:-1].mean() > 0.9


@pytest.mark.parametrize("case", ["hardening_case2", "softening_case2", "combined_case2"])
def test_all_flutter_is_backward_whirl(run_thesis, case):
    orbits = [(b, o) for b in _periodic(run_thesis(case)) for o in b.orbits
              if np.ptp(o.states[:, 0]) > 1e-3]
    assert len(orbits) >= 5
    model = get_model("classical")
    assert {simulate.whirl_sense(model, o.states) for _, o in orbits} == {"BW"}


@pytest.fixture(scope="module")
def softening_at_04(tmp_path_factory):
    """Softening case 2 with the orbits at K1 = 0.4 stored."""
    text = (STUDIES / "softening_case2.yaml").read_text().replace(
        "    branch_points: true", "    branch_points: true\n    orbits_at: [0.4]")
    study = validate_text(text, "softening_case2.yaml")
    return study, run_study(study, tmp_path_factory.mktemp("soft"), jobs=2)


def _fold_of_cycles_by_simulation(model, overrides, family, fold, d, periods):
    """Bracket the fold of cycles ``fold`` of ``family`` by time simulation: start on AUTO's
    orbit at the fold (its point of largest pitch, enlarged 1 %) at ``d`` on the side where
    the family's stable cycles lie and at ``d`` beyond, simulate ``periods`` periods and
    return the largest pitch over the last ten periods relative to the start's, for both."""
    name = family.parameter_names[0]
    orbit = next(o for o in family.orbits if o.index == fold.index)
    start = 1.01 * orbit.states[int(np.argmax(orbit.states[:, 0]))]
    k, value = fold.index, float(fold.parameters[0])
    assert family.stable[k + 2] and not family.stable[k - 2]
    lco_side = float(np.sign(family.parameters[k + 2, 0] - value))
    left = []
    for side in (lco_side, -lco_side):
        params = model.parameter_vector({**overrides, name: value + side * d})
        _, states = simulate.integrate(model, params, start, periods * orbit.period,
                                       samples=periods * 40)
        left.append(float(np.abs(states[-400:, 0]).max() / abs(start[0])))
    return lco_side, left[0], left[1]


def test_softening_case2_overhang(softening_at_04, capsys):
    """The flutter branch leaves the right Hopf unstable and turns stable at a fold of cycles
    to the right of that Hopf point (thesis reads ~0.42 off its figure). The fold, by time
    simulation: 1e-3 of the K1 range (8e-4) on its stable side a start on AUTO's fold orbit
    stays on a cycle for 150 periods; as far beyond it, it decays to the origin (in about 40
    periods: the ghost of the vanished cycles)."""
    study, result = softening_at_04
    (flutter,) = [b for b in _periodic(result) if b.origin.branch == "main_down"
                  and "0.288" in str(b.origin)]
    assert not flutter.stable[1:6].any()
    (fold,) = [p for p in _points(result, PointType.LPC) if p.branch == flutter.name]
    d = 1e-3 * 0.8
    side, inside, beyond = _fold_of_cycles_by_simulation(
        get_model("classical"), study.parameter_values(), flutter, fold, d, periods=150)
    with capsys.disabled():
        print(f"\nsoftening case 2 fold of cycles: AUTO K1 = {fold.parameters[0]:.6f}; by "
              f"simulation in [{fold.parameters[0] - d:.6f}, {fold.parameters[0] + d:.6f}]: "
              f"pitch left after 150 periods {inside:.3f} (stable side) and {beyond:.1e} "
              "(beyond) of the start's")
    assert side == -1.0  # the stable cycles overhang to lower K1
    assert inside > 0.9 and beyond < 0.01
    row = fold.index
    assert not flutter.stable[row - 2] and flutter.stable[row + 2]
    assert _hopf(result, 0.2888).criticality == "subcritical"


def test_softening_case2_coexisting_limit_cycle_by_simulation(softening_at_04, capsys):
    """At K1 = 0.4 the origin is stable and a stable LCO coexists. A 2 degree pitch
    perturbation decays; a start on AUTO's stable orbit stays on it; a start just outside
    AUTO's unstable orbit (the separatrix) ends on the stable one, just inside it decays."""
    study, result = softening_at_04
    model = get_model("classical")
    params = model.parameter_vector({**study.parameter_values(), "K_theta": 0.4})
    (flutter,) = [b for b in _periodic(result) if "0.288" in str(b.origin)]
    at = [o for o in flutter.orbits if abs(o.parameters[0] - 0.4) < 1e-6]
    stable = [o for o in at if flutter.stable[o.index]]
    unstable = [o for o in at if not flutter.stable[o.index]]
    assert len(stable) == 1 and len(unstable) == 1
    (outer,), (inner,) = stable, unstable
    big, small = (np.degrees(flutter.state_max[o.index, 0]) for o in (outer, inner))
    assert big > small > 2.0

    _, decay = simulate.integrate(model, params, np.radians([2.0, 0, 0, 0]), 20.0, 400)
    assert np.abs(decay[-1, :2]).max() < np.radians(0.02)
    assert simulate.check_orbit(model, study.parameter_values(), flutter, outer).passed

    start = inner.states[np.argmax(inner.states[:, 0])]
    _, out = simulate.integrate(model, params, 1.05 * start, 60.0, 6000)
    assert np.degrees(out[-600:, 0].max()) == pytest.approx(big, rel=0.01)
    _, inside = simulate.integrate(model, params, 0.95 * start, 60.0, 600)
    assert np.abs(inside[-1, :2]).max() < np.radians(0.05)
    with capsys.disabled():
        print(f"\nsoftening case 2 at K1 = 0.4: stable LCO max pitch {big:.2f} deg, unstable "
              f"LCO (separatrix) {small:.2f} deg; thesis: 2 deg decays, 3 deg reaches the LCO")


@pytest.mark.parametrize("case", NONLINEAR)
def test_cross_checks_pass_on_every_stable_periodic_branch(run_thesis, case):
    """The time-simulation cross-check of every stable periodic branch of the 15 chapter-3
    cases (the studies ask for it with cross_check: true)."""
    result = run_thesis(case)
    (continuation,) = result.continuations
    checks = continuation.cross_checks
    assert all(c.passed for c in checks), [c for c in checks if not c.passed]
    for branch in _periodic(result):
        checkable = [o for o in branch.orbits if 0 < o.index < len(branch) - 1
                     and branch.stable[o.index - 1: o.index + 2].all()
                     and o.period < 3 * branch.period[0]]  # outside any period blow-up
        if checkable:
            assert any(c.branch == branch.name and c.kind == "orbit" for c in checks), branch.name
    assert all(b.status == "ok" for b in continuation.branches), [
        (b.name, b.message) for b in continuation.branches if b.status != "ok"]


def _family_sides(hopf, families, scale):
    """The sides of the parameter (+1/-1) on which the periodic families at ``hopf`` lie:
    families that start there (their origin names it) and families whose last orbit has
    shrunk onto it: small (pitch amplitude below 0.01 rad and falling), centred on its
    equilibrium (non-dimensional states, ``scale``) and extrapolating to zero amplitude within
    1e-3 of it, with K1 - K1_H proportional to the squared amplitude (Hopf normal form)."""
    value, sides = float(hopf.parameters[0]), []
    for family in families:
        start = family.origin
        if start.point == PointType.HB and start.branch == hopf.branch and abs(
                start.value - value) <= 5e-6 * abs(value):  # 6 significant digits (read back)
            sides.append(float(np.sign(family.parameters[1, 0] - value)))
        amplitude, k1 = _pitch_amplitude(family), family.parameters[:, 0]
        if len(family) < 4 or not 0 < amplitude[-1] < min(amplitude[-2], 0.01):
            continue
        squared = amplitude[-2:] ** 2
        at_zero = k1[-1] - squared[1] * (k1[-1] - k1[-2]) / (squared[1] - squared[0])
        centre = (family.state_max[-1] + family.state_min[-1]) / 2
        if abs(at_zero - value) < 1e-3 and np.allclose(
                centre / scale, hopf.state / scale, rtol=0, atol=1e-3 + 2 * amplitude[-1]):
            sides.append(float(np.sign(k1[-1] - value)))
    return sides


def _growth_direction(model, overrides, name, hopf, delta=1e-6):
    """Sign of d(Re lambda)/dp of the critical pair: numpy eigenvalues of the Jacobian at the
    equilibrium (re-solved by Newton from the Hopf state) at p -/+ delta; the pair is the one
    nearest i omega_H."""
    omega, value = 2 * np.pi / hopf.period, float(hopf.parameters[0])

    def critical(p):
        params = model.parameter_vector({**overrides, name: p})
        state = _equilibrium(model, params, hopf.state)
        eigenvalues = np.linalg.eigvals(model.jacobian_numpy(state, params))
        return float(eigenvalues[np.argmin(np.abs(eigenvalues - 1j * omega))].real)

    low, at, high = critical(value - delta), critical(value), critical(value + delta)
    assert abs(at) < 1e-6 * omega  # the pair is on the imaginary axis at the Hopf point
    assert np.sign(high - at) == np.sign(at - low) != 0
    return float(np.sign(high - low))


@pytest.mark.parametrize("case", NONLINEAR)
def test_criticality_from_the_family_agrees_with_the_lyapunov_coefficient(run_thesis, case,
                                                                           capsys):
    """Two independent verdicts on every Hopf point. The family's, computed here: the side of
    the parameter its periodic family lies on (starting or ending there), against the side
    where the equilibrium is unstable (the critical pair's real part grows towards it, by numpy
    eigenvalues at the re-solved equilibrium): supercritical iff the same. The normal form's:
    the sign of the first Lyapunov coefficient (l1 < 0 supercritical). Every Hopf point of the
    chapter-3 cases has a family, so every one gets both verdicts, and whirl's label agrees."""
    result = run_thesis(case)
    model = get_model("classical")
    overrides = load_study(STUDIES / f"{case}.yaml").parameter_values()
    families = _periodic(result)
    hopfs = _points(result, PointType.HB)
    verdicts = []
    for hopf in hopfs:
        assert np.isfinite(hopf.lyapunov) and hopf.lyapunov != 0, hopf
        sides = _family_sides(hopf, families, np.asarray(model.state_scale))
        if not sides:
            continue
        assert len(set(sides)) == 1, (hopf, sides)
        growth = _growth_direction(model, overrides, hopf.parameter_names[0], hopf)
        family = "supercritical" if sides[0] == growth else "subcritical"
        lyapunov = "supercritical" if hopf.lyapunov < 0 else "subcritical"
        verdicts.append((hopf.branch, round(float(hopf.parameters[0]), 6), family, lyapunov,
                         hopf.criticality))
    with capsys.disabled():
        print(f"\n{case}: {len(verdicts)} of {len(hopfs)} Hopf points with a family: "
              + ", ".join(f"{v[1]:g} {v[2][:3]}" for v in verdicts))
    assert len(verdicts) == len(hopfs)
    assert [v for v in verdicts if not v[2] == v[3] == v[4]] == []


def test_lyapunov_coefficient_without_periodic_branches(tmp_path):
    """``periodic: false``: the criticality comes from l1 alone; the hardening case 2 verdicts
    match the families' (right Hopf supercritical, left subcritical)."""
    text = (STUDIES / "hardening_case2.yaml").read_text()
    text = text.replace("periodic: true", "periodic: false").replace("cross_check: true",
                                                                      "cross_check: false")
    study = validate_text(text, "hardening_case2.yaml")
    result = run_study(study, tmp_path)
    assert not _periodic(result)
    assert _hopf(result, 0.2888).criticality == "supercritical"
    assert _hopf(result, 0.0807).criticality == "subcritical"


def test_parallel_cross_check_equals_the_serial_one(run_thesis):
    result = run_thesis("combined_case2")
    (continuation,) = result.continuations
    model = get_model("classical")
    parameters = {"K2_theta": -10.0, "K3_theta": 350.0, "K_psi": 0.3}
    serial = simulate.cross_check(model, parameters, continuation.branches, jobs=1)
    parallel = simulate.cross_check(model, parameters, continuation.branches, jobs=2)
    assert len(serial) >= 4
    assert serial == parallel


def test_a_family_reaching_another_hopf_point_is_not_computed_again(run_thesis):
    """Combined case 2: the families of the secondary Hopf points at K_theta = 0.0846
    (periodic_4, periodic_6) run to the ones at 0.106 where periodic_3 and periodic_5 started,
    and are dropped as found already. They used to be taken for families back on their own Hopf
    point, and run again on twice the mesh (periodic_4m, periodic_6m): "grown" was judged on SI
    sizes, where the rates (34 rad/s times the angles) dominate, and "on a Hopf point" in AUTO's
    units (rates over 40 rad/s), so the fifth point was both. The families of secondary_1b
    are the mirror images of secondary_1a's, mapped, not run."""
    result = run_thesis("combined_case2")
    names = {run.name for run in result.runs}
    assert "k1.periodic_4.1" in names
    assert not [name for name in names if "m." in name or "periodic_5" in name
                or "periodic_6" in name]
    ends = {b.name: b.end for b in _periodic(result)}
    assert ends["periodic_3"] == ends["periodic_5"].replace("1b", "1a") == \
        "returns to HB at K_theta = 0.0845882 on secondary_1a"


def test_cross_check_fails_for_a_wrong_orbit(run_thesis):
    from dataclasses import replace

    result = run_thesis("hardening_case2")
    model = get_model("classical")
    parameters = {"K_psi": 0.3, "K2_theta": 10.0, "K3_theta": 0.0}
    (flutter,) = [b for b in _periodic(result) if "0.288" in str(b.origin)]
    orbit = next(o for o in flutter.orbits if 0 < o.index and flutter.stable[o.index])
    assert simulate.check_orbit(model, parameters, flutter, orbit).passed
    wrong = replace(orbit, states=orbit.states * 1.3)
    assert not simulate.check_orbit(model, parameters, flutter, wrong).passed


def test_period_blow_up_is_bracketed(run_thesis):
    """Hardening case 3 ends in a homoclinic approach and combined case 3 in a heteroclinic
    one (thesis figures 3.24, 3.26): a bracketed global special point on the main family. Where
    the connection is, is checked by simulation below."""
    for case, kind in (("hardening_case3", PointType.HOMOCLINIC),
                       ("combined_case3", PointType.HETEROCLINIC)):
        result = run_thesis(case)
        (main,) = [b for b in _periodic(result) if b.origin.branch == "main_down"]
        assert main.end.startswith("period blow-up")
        found = [p for p in result.continuations[0].special_points
                 if p.branch == main.name and p.point_type in (PointType.HOMOCLINIC,
                                                               PointType.HETEROCLINIC)]
        assert [p.point_type for p in found] == [kind]
        (point,) = found
        assert point.status == "bracketed"  # symmetric / heteroclinic: HomCont not applicable
        assert main.period.max() > 3 * main.period[0]
        assert "saddle" in point.note


def _unstable_direction(model, params, state):
    """Unit unstable eigenvector of a saddle with one unstable eigenvalue, pitch component > 0."""
    values, vectors = np.linalg.eig(model.jacobian_numpy(state, params))
    vector = np.real(vectors[:, np.argmax(values.real)])
    return vector * np.sign(vector[0]) / np.linalg.norm(vector)


def _departure(model, params, source, target, sign, start=1e-7, duration=4.0):
    """Follow the unstable manifold of the saddle ``source`` (side ``sign`` of its unstable
    eigenvector) to its first close approach to the saddle ``target`` (the first minimum of
    the distance below 0.03, non-dimensional states, after leaving the source; the manifold
    of a saddle-focus may swirl by it at 0.035 first) and on until it leaves again. Returns
    (the side, +1/-1 along the target's unstable eigenvector, on which it leaves; the closest
    distance), or (NaN, inf) if it does not come that close. A connection source -> target is
    where the side flips."""
    scale = np.asarray(model.state_scale)
    source, target = _equilibrium(model, params, source), _equilibrium(model, params, target)
    out = _unstable_direction(model, params, target)
    begin = source + start * sign * _unstable_direction(model, params, source)
    _, states = simulate.integrate(model, params, begin, duration, samples=40001, rtol=1e-11)
    from_source = np.linalg.norm((states - source) / scale, axis=1)
    distance = np.linalg.norm((states - target) / scale, axis=1)
    gone = int(np.flatnonzero(from_source > 0.05)[0])
    minima = gone + 1 + np.flatnonzero((distance[gone + 1:-1] < distance[gone:-2])
                                       & (distance[gone + 1:-1] <= distance[gone + 2:])
                                       & (distance[gone + 1:-1] < 0.03))
    if not len(minima):
        return float("nan"), float("inf")
    closest = int(minima[0])
    away = np.flatnonzero(distance[closest:] > 0.05)
    leave = closest + int(away[0]) if len(away) else len(states) - 1
    side = float(np.sign(np.dot((states[leave] - target) / scale, out)))
    return side, float(distance[closest])


GLOBAL_CASES = {"hardening_case3": {"K2_theta": 10.0, "K3_theta": 0.0, "K_psi": 0.2},
                "combined_case3": {"K2_theta": -10.0, "K3_theta": 350.0, "K_psi": 0.2}}


@cache
def _simulated_connection(case: str, estimate: float, saddle: tuple[float, ...]):
    """The connection of the main family's saddle(s) by simulation: bisection (to 1e-9) of
    the side on which the unstable manifold leaves the target saddle, over estimate +/- 1.5e-3
    (0.19 % of the K1 range). Homoclinic (saddle at the origin): the origin to itself;
    heteroclinic (a +/- pair): the saddle to its mirror image, on the side of the manifold that
    comes closer. Returns (K1, closest distance there, distance function)."""
    model = get_model("classical")
    source = np.asarray(saddle)
    target = source if not source.any() else -source

    def at(k1, sign):
        params = model.parameter_vector({**GLOBAL_CASES[case], "K_theta": k1})
        return _departure(model, params, source, target, sign)

    sign = 1.0 if at(estimate, 1.0)[1] <= at(estimate, -1.0)[1] else -1.0
    low, high = estimate - 1.5e-3, estimate + 1.5e-3
    low_side, high_side = at(low, sign)[0], at(high, sign)[0]
    assert low_side != high_side, "no connection within 1.5e-3 of the estimate"
    while high - low > 1e-9:
        middle = 0.5 * (low + high)
        if at(middle, sign)[0] == low_side:
            low = middle
        else:
            high = middle
    value = 0.5 * (low + high)
    return value, at(value, sign)[1], lambda k1: at(k1, sign)[1]


def _main_global_point(result):
    (main,) = [b for b in _periodic(result) if b.origin.branch == "main_down"]
    (point,) = [p for p in result.continuations[0].special_points if p.branch == main.name
                and p.point_type in (PointType.HOMOCLINIC, PointType.HETEROCLINIC)]
    return point


@pytest.mark.parametrize("case", sorted(GLOBAL_CASES))
def test_period_blow_up_is_a_connection_of_the_saddles_near_the_estimate(run_thesis, case,
                                                                          capsys):
    """Simulated: the unstable manifold of the origin returns to it (hardening case 3, the
    symmetric figure-eight homoclinic), or that of one saddle of the +/- pair reaches the other
    (combined case 3, heteroclinic), at a K1 within 1e-5 (1/80000 of the range) of whirl's
    estimate (the side on which it leaves the saddle flips there). There it passes the saddle
    over ten times closer than 5e-4 to either side."""
    point = _main_global_point(run_thesis(case))
    estimate = float(point.parameters[0])
    value, closest, distance = _simulated_connection(case, estimate, tuple(point.state))
    offsets = {f"{k:+.0e}": distance(value + k) for k in (-5e-4, 5e-4)}
    at_estimate = distance(estimate)
    with capsys.disabled():
        print(f"\n{case}: whirl {estimate:.9f} in [{point.bracket[0]:.9f}, "
              f"{point.bracket[1]:.9f}]; simulated connection {value:.9f} "
              f"({value - estimate:+.2e} from the estimate), closest approach {closest:.1e} "
              f"there, {at_estimate:.1e} at the estimate, "
              + ", ".join(f"{v:.1e} at {k}" for k, v in offsets.items()))
    assert abs(value - estimate) < 1e-5
    assert closest < 0.1 * min(offsets.values())  # a connection, not a jump


@pytest.mark.parametrize("case", sorted(GLOBAL_CASES))
def test_the_bracket_holds_the_simulated_connection(run_thesis, case):
    """whirl's bracket of the global bifurcation holds the connection found by simulation
    (1e-6 of numerical slack; the simulated value moves by 1e-9 with the integrator tolerance
    from 1e-8 to 1e-12 and the start on the manifold from 1e-6 to 1e-8)."""
    point = _main_global_point(run_thesis(case))
    value, _, _ = _simulated_connection(case, float(point.parameters[0]), tuple(point.state))
    low, high = point.bracket
    assert low - 1e-6 <= value <= high + 1e-6, (value, low, high)


def _return_distance(model, params, sign: float, duration: float = 1.5) -> float:
    """How close the unstable manifold of the origin comes back to it (non-dimensional
    states): leave along the unstable eigenvector on side ``sign``, integrate, and take the
    smallest distance after the trajectory has gone round (beyond half its reach)."""
    values, vectors = np.linalg.eig(model.jacobian_numpy(np.zeros(model.n_states), params))
    unstable = np.real(vectors[:, np.argmax(values.real)])
    start = 1e-7 * sign * unstable / np.linalg.norm(unstable)
    _, states = simulate.integrate(model, params, start, duration, samples=60000, rtol=1e-11)
    scaled = np.linalg.norm(states / np.asarray(model.state_scale), axis=1)
    far = np.flatnonzero(scaled > 0.5 * scaled.max())
    return float(scaled[far[-1]:].min()) / float(scaled.max())


def test_homoclinic_orbit_located_by_homcont_and_by_simulation(run_thesis):
    """Hardening case 3: the secondary families end at a homoclinic orbit to the origin
    (a saddle-focus, so the family snakes); HomCont locates it inside the fitted bracket, and
    the origin's unstable manifold, simulated, returns to the origin there far closer than
    5e-4 to either side."""
    result = run_thesis("hardening_case3")
    located = [p for p in result.continuations[0].special_points
               if p.point_type == PointType.HOMOCLINIC and p.status == "located"]
    assert sorted(p.branch for p in located) == ["periodic_2", "periodic_3"]
    value = located[0].parameters[0]
    assert located[1].parameters[0] == pytest.approx(value, abs=1e-9)  # mirror images
    low, high = located[0].bracket
    assert low - 1e-4 <= value <= high + 1e-4
    assert "located by HomCont" in located[0].note
    model = get_model("classical")
    secondary = next(b for b in result.continuations[0].branches if b.name == "secondary_1a")
    side = float(np.sign(secondary.state_max[-1, 0]))  # the loop circles this focus

    def distance(k1: float) -> float:
        params = model.parameter_vector({"K_theta": k1, "K2_theta": 10.0, "K3_theta": 0.0,
                                         "K_psi": 0.2})
        return _return_distance(model, params, side)

    at, left, right = distance(value), distance(value - 5e-4), distance(value + 5e-4)
    assert at < 0.01 * min(left, right), (at, left, right)


def test_airspeed_continuation_overhang(run_thesis, capsys):
    """Combined variant at datum in airspeed (thesis fig. 3.30): the flutter branch from the
    linear onset bends back to lower airspeed (a fold of cycles below 7.76 m/s)."""
    result = run_thesis("combined_airspeed")
    hopf = _hopf(result, 7.764, branch="main_up")
    assert hopf.criticality == "subcritical"
    (fold,) = _points(result, PointType.LPC)
    assert fold.parameters[0] < hopf.parameters[0]
    # the fold by simulation: 2e-3 of the airspeed range (2.6e-3 m/s) above it a start on
    # AUTO's fold orbit stays on a cycle for 600 periods; as far below it, it decays (the
    # ghost of the cycles holds it for about 400 periods there)
    family = next(b for b in result.continuations[0].branches if b.name == fold.branch)
    d = 2e-3 * 1.3
    side, inside, beyond = _fold_of_cycles_by_simulation(
        get_model("classical"), {"K2_theta": -10.0, "K3_theta": 350.0}, family, fold, d,
        periods=600)
    with capsys.disabled():
        print(f"\ncombined airspeed fold of cycles: AUTO V = {fold.parameters[0]:.5f} m/s; by "
              f"simulation in [{fold.parameters[0] - d:.5f}, {fold.parameters[0] + d:.5f}]: "
              f"pitch left after 600 periods {inside:.3f} (stable side) and {beyond:.1e} "
              "(beyond) of the start's")
    assert side == 1.0 and inside > 0.9 and beyond < 0.01
    assert all(c.passed for c in result.continuations[0].cross_checks)
