"""whirl's freeplay law on the gimballed model (8 states; issue 16 item 2, the last to land adds
it), on the real AUTO-07p: pitch freeplay on the nacelle of a soft gimbal; the offset
equilibria past the origin's pitchfork (continued in K_in down to 0) checked against a Newton
solve of the model's numpy right-hand side from a crude guess, and their eigenvalues against
the linear model's with the pitch stiffness at K_out (beyond the gap the law is linear with
slope K_out; at K_in = 0 the origin is inside the gap)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq, fsolve

from whirl_cli.analysis import linear
from whirl_cli.models import get_model
from whirl_cli.pipeline import run_study
from whirl_cli.results import PointType
from whirl_cli.study import validate_text

from ..gimballed_exact import freeplay_simulation, matrices, maxima
from .helpers import offset_equilibria_at_zero

pytestmark = pytest.mark.auto

DELTA = math.radians(1.0)
K_OUT = 0.4
#: a soft gimbal (combined_case2_soft's); the K_in range holds the origin's pitchfork
PARAMETERS = {"K_psi": 0.3, "K_beta": 10.0}


def study(dof: str, k_out: float, k_in: float) -> str:
    return f"""
name: gimballed-freeplay-{dof}
model: gimballed
parameters: {{K_psi: 0.3, K_beta: 10.0}}
nonlinearity: {{type: freeplay, dof: {dof}, delta: {DELTA!r}, K_out: {k_out}, K_in: {k_in}}}
continuations:
  - {{name: kin, type: one-parameter, parameter: K_in_{dof}, range: [0.0, {k_in}],
      orbits_at: [0.0]}}
"""


@pytest.mark.parametrize("dof, datum", [("theta", "K_theta")])
def test_offset_equilibria_of_freeplay_on_the_gimballed_model(tmp_path, dof, datum):
    spec = validate_text(study(dof, K_OUT, 0.1))
    result = run_study(spec, tmp_path, jobs=2)
    assert [r.status for r in result.runs if ".shrink_" not in r.name] == \
        ["ok"] * len([r for r in result.runs if ".shrink_" not in r.name]), result.runs
    (continuation,) = result.continuations
    pitchforks = [p for p in continuation.special_points if p.point_type == PointType.BP]
    assert pitchforks, "no pitchfork of the origin in K_in"
    model = spec.variant()
    params = model.parameter_vector({**spec.parameter_values(), f"K_in_{dof}": 0.0})
    assert params[model.parameter_names.index(datum)] == K_OUT  # K_out is the dof's datum
    linear_model = get_model("gimballed")
    at_k_out = linear_model.parameter_vector({**PARAMETERS, datum: K_OUT})[:, None]
    expected = np.sort_complex(linear.analyse(linear_model, at_k_out)[0][0])
    index = model.state_names.index(dof)
    found = 0
    for branch, row in offset_equilibria_at_zero(continuation):
        state = np.where(np.abs(branch.state_max[row]) >= np.abs(branch.state_min[row]),
                         branch.state_max[row], branch.state_min[row])
        guess = np.zeros(model.n_states)
        guess[index] = 2 * DELTA * np.sign(state[index])  # past the gap, on AUTO's side
        newton = fsolve(lambda y: model.rhs_numpy(y, params), guess, xtol=1e-11)
        assert np.abs(model.rhs_numpy(newton, params)).max() < 1e-10
        np.testing.assert_allclose(state, newton, rtol=1e-6, atol=1e-9)
        assert abs(newton[index]) > DELTA  # beyond the gap, where the law is K_out's
        ours = np.sort_complex(branch.eigenvalues[row])
        np.testing.assert_allclose(ours, expected, rtol=1e-5, atol=1e-6)
        print(f"gimballed {dof} freeplay, K_in = 0: offset equilibrium {dof} = "
              f"{math.degrees(newton[index]):+.5f} deg (AUTO {math.degrees(state[index]):+.5f})"
              f", stable {bool(branch.stable[row])}")
        found += 1
    assert found == 2


GIMBAL_STUDY = f"""
name: gimballed-freeplay-gimbal
model: gimballed
parameters: {{K_psi: 0.3}}
nonlinearity: {{type: freeplay, dof: beta_y, delta: {DELTA!r}, K_out: 10.0, K_in: 2.0}}
continuations:
  - {{name: kin, type: one-parameter, parameter: K_in_beta_y, range: [0.0, 2.0]}}
"""


def test_freeplay_on_a_gimbal_dof_runs_on_auto_and_its_hopf_point_is_the_jacobians(tmp_path):
    """Freeplay on beta_y (K_out: the isotropic gimbal stiffness K_beta, which beta_z keeps):
    the law's parameters carry the dof's name, so its smoothing width epsilon_beta_y is
    longer than AUTO's 13 characters and reaches AUTO by a short name
    (:func:`whirl_cli.auto.constants.auto_name`). With the origin inside the gap, the Hopf
    point AUTO finds in K_in is where the numpy Jacobian of the model at the origin has a
    pair crossing the imaginary axis, at AUTO's period; and it persists as epsilon shrinks."""
    spec = validate_text(GIMBAL_STUDY)
    result = run_study(spec, tmp_path, jobs=2)
    assert all(r.status == "ok" for r in result.runs), result.runs
    (continuation,) = result.continuations
    (hopf,) = [p for p in continuation.special_points if p.point_type == PointType.HB]
    assert not hopf.artefact
    model = spec.variant()
    origin = np.zeros(model.n_states)

    def pair(k_in: float) -> complex:
        params = model.parameter_vector({**spec.parameter_values(), "K_in_beta_y": k_in})
        eigenvalues = np.linalg.eigvals(model.jacobian_numpy(origin, params))
        return eigenvalues[np.argmax(eigenvalues.real)]

    value = hopf.parameters[0]
    below, above = pair(value - 1e-3), pair(value + 1e-3)
    assert below.real * above.real < 0, (below, above)  # a pair crosses there
    crossing = pair(value)
    assert abs(crossing.real) < 1e-4 * abs(crossing.imag)
    np.testing.assert_allclose(2 * np.pi / abs(crossing.imag), hopf.period, rtol=1e-4)
    print(f"gimbal beta_y freeplay: Hopf at K_in = {value:.6f} N m/rad (AUTO), the Jacobian's "
          f"pair {crossing:.3g} there, period {hopf.period:.6f} s")


# ------------------------------------------------------------ the shipped pitch freeplay study
SHIPPED = Path(__file__).resolve().parents[2] / "studies" / "gimballed" / \
    "freeplay_pitch_airspeed.yaml"


def onset_at_k_out() -> float:
    """The flutter speed of the linear gimballed model with K_theta = K_out, from the
    eigenvalues of tests/gimballed_exact.py's matrices (bisection of the growth rate)."""
    def growth(speed: float) -> float:
        mass, damping, stiffness = matrices({"K_theta": K_OUT, "K_psi": 0.3, "V": speed})
        minv = np.linalg.inv(mass)
        system = np.block([[np.zeros((4, 4)), np.eye(4)], [-minv @ stiffness, -minv @ damping]])
        return float(np.linalg.eigvals(system).real.max())

    return float(brentq(growth, 6.0, 9.0, xtol=1e-10))


def test_the_shipped_gimballed_pitch_freeplay_study_against_the_exact_law(tmp_path):
    """studies/gimballed/freeplay_pitch_airspeed.yaml: its seeds at 4 and 8 delta settle on one
    cycle, continued in airspeed; at 6.7 m/s the family's stable orbit is the one an exact-law
    simulation from the 4-delta seed settles on (theta max to 2e-3, period to 1e-3); stable
    cycles reach below the linear onset at K_out, which whirl stores as the eigenvalues of the
    independent matrices give it; every stable cycle above that onset (near a fold of small
    cycles, theta about 1.8 delta, which the family reaches on its way back; four spread
    along them) is one the exact law keeps (from its stored orbit, theta max after 40 s
    within 2 % of AUTO's; not within 1e-3 of the family's span of a fold, which the smoothing
    moves about that); at 6.5 m/s,
    below the family's lowest fold, the exact law from the same seed finds no cycle (the
    motion leaves the 4-delta seed and decays). Run without its cross-checks (whirl's own
    simulations of the branches), which nothing here reads."""
    text = SHIPPED.read_text()
    assert "cross_check: true" in text  # whirl's own simulations: nothing here reads them
    study = validate_text(text.replace("cross_check: true", "cross_check: false"),
                          SHIPPED.name)
    result = run_study(study, tmp_path, jobs=2)
    (continuation,) = result.continuations
    assert [s.kind for s in continuation.seeds] == ["equilibrium", "periodic", "periodic"]
    family = next(b for b in continuation.branches if b.name == "periodic_o1")
    at = np.flatnonzero(family.stable & family.stability_known
                        & (np.abs(family.parameters[:, 0] - 6.7) < 2e-3))
    assert at.size
    row = at[np.argmin(np.abs(family.parameters[at, 0] - 6.7))]
    speed = float(family.parameters[row, 0])

    seed = np.zeros(8)
    seed[0] = 4 * DELTA
    t, y = freeplay_simulation({"K_psi": 0.3, "K_beta": 10.0, "V": speed}, "theta", DELTA,
                               K_OUT, seed, 80.0)
    times, peaks = maxima(t, y[:, 0])
    late = times > 70.0
    assert np.ptp(peaks[late]) < 1e-4 * peaks[late].max()  # settled
    assert abs(peaks[late].max() / family.state_max[row, 0] - 1) < 2e-3
    assert abs(np.diff(times[late]).mean() / family.period[row] - 1) < 1e-3

    onset = onset_at_k_out()
    (amplitudes,) = continuation.freeplay
    np.testing.assert_allclose(amplitudes.onset, [onset], rtol=1e-6)
    stable_speeds = family.parameters[family.stable & family.stability_known, 0]
    assert stable_speeds.min() < 6.6 and (stable_speeds < onset).any()
    folds = family.parameters[family.point_type == PointType.LPC, 0]
    margin = 1e-3 * np.ptp(family.parameters[:, 0])  # the smoothing moves a fold about that
    above = [orbit for orbit in family.orbits
             if family.stable[orbit.index] and family.stability_known[orbit.index]
             and orbit.parameters[0] > onset
             and np.abs(folds - orbit.parameters[0]).min() > margin]
    assert above
    # four spread along them (in storage order: both ends and two between), not each of ~80
    for k in sorted(set(np.linspace(0, len(above) - 1, 4).round().astype(int))):
        orbit = above[k]
        start = orbit.states[0] * np.tile([1.0, -1.0], 4)  # psi, beta_z negated
        t, y = freeplay_simulation({"K_psi": 0.3, "K_beta": 10.0,
                                    "V": float(orbit.parameters[0])}, "theta", DELTA,
                                   K_OUT, start, 40.0)
        kept = np.abs(y[t > 30.0, 0]).max() / np.abs(orbit.states[:, 0]).max()
        assert abs(kept - 1) < 2e-2, (orbit.parameters[0], kept)
    lowest = min(p.parameters[0] for p in continuation.special_points if p.type_name == "LPC")
    assert 6.5 < lowest < 6.6

    t, y = freeplay_simulation({"K_psi": 0.3, "K_beta": 10.0, "V": 6.5}, "theta", DELTA,
                               K_OUT, seed, 40.0)
    assert np.ptp(y[t > 30.0, 0]) < 0.1 * DELTA  # no cycle below the fold
    print(f"\ngimballed pitch freeplay: cycle at {speed:.5f} m/s, theta max "
          f"{family.state_max[row, 0] / DELTA:.5f} delta (AUTO), "
          f"{peaks[late].max() / DELTA:.5f} (exact law); lowest fold {lowest:.5f} m/s, "
          f"linear onset at K_out {onset:.5f} m/s")
