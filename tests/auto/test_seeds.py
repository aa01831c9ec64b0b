"""Limit cycles not born at a Hopf point, found from seeds (issue 15, item 3), on the real
AUTO-07p: the classical model with pitch freeplay of 1 degree (K_out = 0.4, K_psi = 0.3) at
V = 6.7 m/s, where the linear model with K_theta = K_out is stable."""

from __future__ import annotations

import tempfile
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from whirl_cli.analysis import linear, seeds, simulate
from whirl_cli.models import get_model
from whirl_cli.pipeline import run_study
from whirl_cli.study import validate_text

pytestmark = pytest.mark.auto

DELTA = float(np.radians(1.0))
STUDY = f"""
name: freeplay-seeds
model: classical
parameters: {{K_psi: 0.3, V: 6.7}}
nonlinearity: {{type: freeplay, dof: theta, delta: {DELTA!r}, K_out: 0.4}}
continuations:
  - {{name: v, type: one-parameter, parameter: V, start: 6.7, range: [6.0, 9.0],
      branch_points: false, seeds: auto}}
auto: {{step_max: 0.0005, step_initial: 0.0001, max_steps: 4000}}
"""


@cache
def computed():
    study = validate_text(STUDY)
    return study, run_study(study, Path(tempfile.mkdtemp(prefix="whirl-test-")))


def linear_onset() -> float:
    """The flutter speed of the linear model with K_theta = K_out (eigenvalues)."""
    hopfs = [p.value for p in linear.critical_points(
        get_model("classical"), {"K_theta": 0.4, "K_psi": 0.3}, "V", 0.5, 30.0)
        if p.kind == "hopf"]
    return min(hopfs)


def test_seeds_settle_on_the_offset_equilibrium_or_on_one_limit_cycle():
    _, result = computed()
    outcomes = result.continuations[0].seeds
    assert [s.kind for s in outcomes] == ["equilibrium", "periodic", "periodic"]  # 2, 4, 8 delta
    assert outcomes[1].branch == outcomes[2].branch == "periodic_o1"  # continued once
    assert [b.name for b in result.continuations[0].branches if b.is_periodic] == ["periodic_o1"]


def test_a_seeded_lco_below_the_linear_onset_is_stable_and_matches_both_simulations():
    study, result = computed()
    model = study.variant()
    branch = next(b for b in result.continuations[0].branches if b.name == "periodic_o1")
    start = next(o for o in branch.orbits if abs(o.parameters[0] - 6.7) < 1e-9)
    row = start.index
    assert branch.stable[row] and branch.stability_known[row]  # by its Floquet multipliers
    auto_theta = branch.state_max[row, 0]

    params = model.parameter_vector({**study.parameter_values(), "V": 6.7})
    seed = np.zeros(model.n_states)
    seed[0] = 4 * DELTA
    smoothed = seeds.settle(model, params, seed)
    assert smoothed.kind == "periodic"
    assert abs(smoothed.orbit.states[:, 0].max() / auto_theta - 1) < 5e-3

    exact = simulate.integrate_exact(model, params, start.states[0], 200 * start.period,
                                     samples=200 * 100)
    exact_theta = exact.states[-20 * 100:, 0].max()
    assert abs(exact_theta / auto_theta - 1) < 5e-3

    onset = linear_onset()
    lowest = branch.parameters[:, 0].min()
    print(f"\nLCO from a seed at V = 6.7 m/s: theta max {np.degrees(auto_theta):.4f} deg "
          f"(AUTO), {np.degrees(smoothed.orbit.states[:, 0].max()):.4f} (smoothed simulation), "
          f"{np.degrees(exact_theta):.4f} (exact law); LCOs from V = {lowest:.4f} m/s, "
          f"linear onset at K_theta = K_out: {onset:.4f} m/s")
    assert lowest < 6.7 < onset


def test_bad_seeds_are_refused():
    from whirl_cli.errors import StudyError

    for bad, reason in (("[{tehta: 4}]", "expected one of theta, psi"),
                        ("3", "expected `auto` or a list of mappings")):
        text = STUDY.replace("seeds: auto", f"seeds: {bad}")
        with pytest.raises(StudyError, match=reason):
            validate_text(text)
