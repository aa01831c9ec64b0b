"""The gimballed hub's K1-K_psi stability boundary (``studies/gimballed/boundary_k1_kpsi.yaml``,
issue 16 item 6) on the real AUTO-07p.

The shipped study (five slices, K1 in [-0.3, 0.5], K_psi in [0, 0.5]) takes minutes (README
"Studies"); the tests run a reduced copy of it, made by editing its YAML: K1 in [0.28, 0.5],
K_psi in [0.25, 0.32], the slice K_psi = 0.3, Hopf and fold-of-cycles loci only. That keeps the
right Hopf point (K1 = 0.3137 at K_psi = 0.3) and the fold of cycles its family leans over to
(0.3778): the flutter overhang. Each claim is checked by an independent method:

* the Hopf locus against the linear onset from the eigenvalues of the model's Jacobian at the
  undeflected equilibrium (numpy, Brent's method in the test);
* the fold-of-cycles locus against the fold of a separate one-parameter K1 continuation at a
  fixed K_psi off the slice (the gimballed one-parameter path, its own AUTO runs);
* the unsafe interval at the slice by time simulation: just inside it (linearly stable) a large
  disturbance settles on a limit cycle of AUTO's amplitude, a small one decays; just outside it
  the same large disturbance decays;
* with a stiff gimbal (K_beta = 1e6) the unsafe interval at the slice equals the classical
  model's (boundary_combined reduced the same way).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq, fsolve

from whirl_cli.analysis import boundaries, simulate
from whirl_cli.models import get_model
from whirl_cli.pipeline import run_study
from whirl_cli.results import BranchKind, PointType
from whirl_cli.study import load_study, validate_text
from whirl_cli.verdict import verdict

from ..conftest import ROOT, STUDIES

SHIPPED = ROOT / "studies" / "gimballed" / "boundary_k1_kpsi.yaml"
MODEL = get_model("gimballed")
K1_RANGE, KPSI_RANGE, SLICE = (0.28, 0.5), (0.25, 0.32), 0.3
#: K_psi of the one-parameter check of the fold-of-cycles locus (off the slice).
OFF_SLICE = 0.27


def _edit(text: str, old: str, new: str) -> str:
    assert old in text, f"the shipped study no longer has {old!r}"
    return text.replace(old, new)


def reduced(text: str, k_psi: tuple[float, float] = KPSI_RANGE, auto: str = "",
            swaps: tuple[tuple[str, str], ...] = ()) -> str:
    """The boundary study ``text`` cut down to the test's window (see the module doc; K_psi
    over ``k_psi``), with ``auto`` settings appended and the text edits ``swaps`` made."""
    text = _edit(text, "K1: [-0.3, 0.5], K_psi: [0.0, 0.5]",
                 f"K1: {list(K1_RANGE)}, K_psi: {list(k_psi)}")
    text = _edit(text, "slices: [0.4, 0.3, 0.2, 0.05, 0.037]", f"slices: [{SLICE}]")
    text = _edit(text, "loci: [hopf, branch_point, fold, fold_of_cycles]",
                 "loci: [hopf, fold_of_cycles]\n    resolution: 15")
    text = _edit(text, "points: 321", "points: 31")
    text = _edit(text, "points: 201", "points: 15")
    for old, new in swaps:
        text = _edit(text, old, new)
    return text + (f"auto: {auto}\n" if auto else "")


@pytest.fixture(scope="module")
def soft(tmp_path_factory):
    """(study, result) of the reduced copy of the shipped study (K_beta = 10)."""
    study = validate_text(reduced(SHIPPED.read_text()), "boundary_k1_kpsi.yaml")
    return study, run_study(study, tmp_path_factory.mktemp("soft"), jobs=2)


def _loci(result, kind: str) -> list[np.ndarray]:
    (boundary,) = result.boundaries
    return [curve for k, curve in boundary.loci.values() if k == kind]


def _flutter(result, value: float):
    (boundary,) = result.boundaries
    return [i for i in boundary.intervals
            if abs(i.slice_value - value) < 1e-12 and i.cause == "flutter"]


def _onset(overrides: dict[str, float], k_psi: float, near: float) -> float:
    """The K1 nearest ``near`` where a complex pair of eigenvalues of the Jacobian at y = 0
    crosses the imaginary axis at ``k_psi`` (a sign change of the largest real part of the
    oscillatory eigenvalues, bracketed on a 1e-3 grid and refined by Brent's method)."""
    def growth(k1: float) -> float:
        params = MODEL.parameter_vector({**overrides, "K_psi": k_psi, "K_theta": k1})
        values = np.linalg.eigvals(MODEL.jacobian_numpy(np.zeros(8), params))
        return float(values[np.abs(values.imag) > 1e-6].real.max())

    grid = np.arange(near - 0.02, near + 0.02, 1e-3)
    rates = np.array([growth(k) for k in grid])
    (changes,) = np.nonzero(np.sign(rates[:-1]) != np.sign(rates[1:]))
    assert len(changes), f"no Hopf point within 0.02 of {near} at K_psi = {k_psi}"
    k = changes[np.argmin(np.abs(grid[changes] - near))]
    return brentq(growth, grid[k], grid[k + 1], xtol=1e-13)


def test_the_shipped_study_validates_and_its_reduced_copy_succeeds(soft):
    """The shipped study loads; the reduced copy runs without problems (every family and
    locus ends where whirl judges natural) and has both loci and a flutter overhang."""
    study = load_study(SHIPPED)
    assert study.model == "gimballed"
    assert study.parameter_values()["K_beta"] == 10.0
    _, result = soft
    assert not verdict(result).problems, verdict(result).problems
    assert _loci(result, "hopf") and _loci(result, "fold_of_cycles")
    assert _flutter(result, SLICE)


def test_hopf_locus_is_the_linear_onset_from_eigenvalues(soft):
    """At every 8th point of the Hopf loci inside the window (several K_psi from 0.25 to
    0.32), its K1 is the onset of the eigenvalues of the Jacobian at that K_psi, to 1e-4
    relative."""
    study, result = soft
    overrides = study.parameter_values()
    checked = set()
    for curve in _loci(result, "hopf"):
        inside = curve[(curve[:, 0] > K1_RANGE[0] + 0.02) & (curve[:, 0] < K1_RANGE[1] - 0.02)
                       & (curve[:, 1] > KPSI_RANGE[0]) & (curve[:, 1] < KPSI_RANGE[1])]
        for k1, k_psi in inside[::8]:
            assert k1 == pytest.approx(_onset(overrides, k_psi, k1), rel=1e-4), (k1, k_psi)
            checked.add(round(float(k_psi), 2))
    assert len(checked) >= 4, checked  # several K_psi


def test_fold_of_cycles_locus_is_the_fold_of_a_one_parameter_run(soft, tmp_path):
    """Where the fold-of-cycles locus crosses K_psi = 0.27 (off the slice it was started
    from), it is the fold of cycles of the main family of a one-parameter K1 continuation at
    that K_psi (the gimballed one-parameter path, its own AUTO runs) within 2e-4 in K1 (the
    locus is a polyline of AUTO's steps, about 1e-3 apart)."""
    _, result = soft
    crossings = [x for curve in _loci(result, "fold_of_cycles")
                 for x in boundaries.crossings(curve, OFF_SLICE)]
    text = (ROOT / "studies" / "gimballed" / "combined_case2_soft.yaml").read_text()
    text = _edit(text, "K_psi: 0.3,", f"K_psi: {OFF_SLICE},")
    text = _edit(text, "range: [-0.3, 0.5]", f"range: {list(K1_RANGE)}")
    text = _edit(text, "cross_check: true", "cross_check: false")
    single = run_study(validate_text(text, "k1.yaml"), tmp_path, jobs=2)
    (continuation,) = single.continuations
    main = {b.name for b in continuation.branches
            if b.kind == BranchKind.PERIODIC and b.origin.branch == "main_down"}
    folds = [float(p.parameters[0]) for p in continuation.special_points
             if p.point_type == PointType.LPC and p.branch in main]
    assert folds and crossings
    for fold in folds:
        nearest = min(crossings, key=lambda x: abs(x - fold))
        print(f"\n  LPC at K_psi = {OFF_SLICE}: one-parameter {fold:.6f}, locus {nearest:.6f}")
        assert nearest == pytest.approx(fold, abs=2e-4)


def _pitch_amplitude(study, k1: float, pitch_deg: float, duration: float
                     ) -> tuple[float, float]:
    """Largest |theta| (deg) over the last two fifths of a simulation from a pitch of
    ``pitch_deg`` at rest, at the slice's K_psi and K1 = ``k1``: (the fourth fifth, the last)."""
    params = MODEL.parameter_vector({**study.parameter_values(), "K_psi": SLICE,
                                     "K_theta": k1})
    start = np.zeros(8)
    start[0] = np.radians(pitch_deg)
    _, states = simulate.integrate(MODEL, params, start, duration, samples=3001, rtol=1e-6)
    pitch = np.degrees(np.abs(states[:, 0]))
    return float(pitch[-1200:-600].max()), float(pitch[-600:].max())


def _stable_amplitude(family, k1: float) -> float:
    """Pitch amplitude (deg) of the family's stable orbit at ``k1``, interpolated between the
    two stable points either side of it (the stable part passes ``k1`` once)."""
    p, theta = family.parameters[:, 0], np.degrees(family.state_max[:, 0])
    (rows,) = np.nonzero(((p[:-1] - k1) * (p[1:] - k1) <= 0) & family.stable[:-1]
                         & family.stable[1:])
    (k,) = rows
    return float(np.interp(k1, sorted(p[k:k + 2]), theta[k:k + 2][np.argsort(p[k:k + 2])]))


def test_unsafe_interval_by_time_simulation(soft):
    """The unsafe interval at K_psi = 0.3 runs from the Hopf locus (the linear onset) to the
    fold-of-cycles locus. 5e-3 below its upper end (linearly stable: every eigenvalue in the
    left half-plane) a 12 deg pitch disturbance settles on a limit cycle whose pitch amplitude
    is that of AUTO's stable family there (2 %; steady: the same over the last two fifths of
    20 s), while a 0.05 deg one decays; 5e-3 above its upper end the same 12 deg disturbance
    decays (to below 1 % of it in 30 s)."""
    study, result = soft
    (interval,) = _flutter(result, SLICE)
    assert interval.lower == pytest.approx(_onset(study.parameter_values(), SLICE, 0.31),
                                           rel=1e-6)
    inside, outside = interval.upper - 5e-3, interval.upper + 5e-3
    params = MODEL.parameter_vector({**study.parameter_values(), "K_psi": SLICE,
                                     "K_theta": inside})
    assert np.linalg.eigvals(MODEL.jacobian_numpy(np.zeros(8), params)).real.max() < 0
    (continuation,) = result.continuations
    (family,) = [b for b in continuation.branches if b.kind == BranchKind.PERIODIC
                 and b.origin.branch == "main_down"]
    expected = _stable_amplitude(family, inside)
    before, last = _pitch_amplitude(study, inside, 12.0, 20.0)
    print(f"\n  K1 = {inside:.5f}: simulated LCO {last:.4f} deg, AUTO {expected:.4f} deg")
    assert last == pytest.approx(expected, rel=0.02)
    assert before == pytest.approx(last, rel=1e-3)
    assert _pitch_amplitude(study, inside, 0.05, 10.0)[1] < 0.05 / 2
    assert _pitch_amplitude(study, outside, 12.0, 30.0)[1] < 0.12


def test_stiff_gimbal_unsafe_interval_is_the_classical(tmp_path):
    """K_beta = 1e6: the unsafe interval at K_psi = 0.3 of the gimballed boundary equals that
    of the classical boundary_combined (each reduced to K_psi in [0.29, 0.31], same AUTO step
    cap 0.003: see test_gimballed_auto) to 1e-3 relative at both ends."""
    window, cap = (0.29, 0.31), "{step_max: 0.003}"
    stiff = reduced(SHIPPED.read_text(), window, cap, (("K_beta: 10.0", "K_beta: 1.0e+6"),))
    classical = reduced((STUDIES / "boundary_combined.yaml").read_text(), window, cap)
    found = []
    for name, text in (("stiff", stiff), ("classical", classical)):
        result = run_study(validate_text(text, f"{name}.yaml"), tmp_path / name, jobs=2)
        (interval,) = _flutter(result, SLICE)
        found.append((interval.lower, interval.upper))
    print(f"\n  unsafe at K_psi = {SLICE}: stiff gimbal {found[0]}, classical {found[1]}")
    np.testing.assert_allclose(found[0], found[1], rtol=1e-3)


def test_case5_main_family_ends_at_a_heteroclinic_approach(tmp_path):
    """The boundary's slice K_psi = 0.037 (case 5) as a one-parameter run: the main family's
    period grows only to about 4 times the Hopf period before AUTO stops with MX (the saddles'
    unstable eigenvalue, 3.2 1/s, is small), yet its end is judged a period blow-up, a
    heteroclinic approach to the +/- pair of saddles (each, solved for by Newton's method from
    the stored state, an equilibrium of the model with one real positive eigenvalue), not a
    failure. By simulation, 2e-3 above the estimate p* a start
    on AUTO's stable orbit stays on it, while 2e-3 below p* (past the end of the family) the
    same start runs away in yaw (a dof beyond 100 typical amplitudes within 4 periods)."""
    text = (ROOT / "studies" / "gimballed" / "combined_case2_soft.yaml").read_text()
    text = _edit(text, "K_psi: 0.3,", "K_psi: 0.037,")
    text = _edit(text, "cross_check: true", "cross_check: false")
    study = validate_text(text, "case5.yaml")
    result = run_study(study, tmp_path, jobs=2)
    assert not verdict(result).problems, verdict(result).problems
    (continuation,) = result.continuations
    (family,) = [b for b in continuation.branches if b.kind == BranchKind.PERIODIC
                 and b.origin.branch == "main_down"]
    assert family.end == "period blow-up: heteroclinic approach"
    assert family.period.max() > 2 * family.period[0]
    (point,) = [p for p in continuation.special_points if p.branch == family.name
                and p.point_type == PointType.HETEROCLINIC]
    star = float(point.parameters[0])
    params = MODEL.parameter_vector({**study.parameter_values(), "K_theta": star})
    for stored in (point.state, -point.state):
        saddle = fsolve(lambda y: MODEL.rhs_numpy(y, params), stored, xtol=1e-13,
                        fprime=lambda y: MODEL.jacobian_numpy(y, params))
        assert np.abs(MODEL.rhs_numpy(saddle, params)).max() < 1e-9
        assert np.abs(saddle - stored).max() < 1e-3  # rad: the stored state interpolates
        values = np.linalg.eigvals(MODEL.jacobian_numpy(saddle, params))
        assert np.sum((values.real > 0) & (np.abs(values.imag) < 1e-9)) == 1
        assert np.sum(values.real > 0) == 1
    orbit = min(family.orbits, key=lambda o: abs(o.parameters[0] - (star + 2e-3)))
    assert family.stable[orbit.index] and abs(orbit.parameters[0] - star - 2e-3) < 1e-3
    assert simulate.check_orbit(MODEL, study.parameter_values(), family, orbit,
                                periods=6).passed
    beyond = MODEL.parameter_vector({**study.parameter_values(), "K_theta": star - 2e-3})
    run = simulate.simulation(MODEL, beyond, orbit.states[0], 4 * orbit.period, rtol=1e-6)
    assert run.status == 1 and "beyond" in run.message
