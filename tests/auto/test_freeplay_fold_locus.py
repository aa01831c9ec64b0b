"""The locus of the lowest airspeed of freeplay LCOs, their fold of cycles, against K_psi
(issue 15, item 6; studies/freeplay/pitch_fold_kpsi.yaml), on the real AUTO-07p: a
two-parameter continuation whose slice finds the cycles from seeds (no Hopf point leads to
them). Checked against the one-parameter study at K_psi = 0.3 and, at two other K_psi, by
simulating the exact (unsmoothed) law just above and just below the locus' airspeed."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pytest

from whirl_cli import api
from whirl_cli.analysis import seeds, simulate
from whirl_cli.errors import StudyError
from whirl_cli.results import BranchKind
from whirl_cli.study import load_study, validate_text

from ..conftest import ROOT

pytestmark = pytest.mark.auto

FREEPLAY = ROOT / "studies" / "freeplay"
DELTA = float(np.radians(1.0))
#: Airspeeds simulated, as fractions above and below the locus' airspeed.
MARGIN = 0.01


@cache
def fold_study():
    study = load_study(FREEPLAY / "pitch_fold_kpsi.yaml")
    return study, api.run(study, jobs=2)


@cache
def airspeed_study():
    return api.run(load_study(FREEPLAY / "pitch_airspeed.yaml"), jobs=2)


def locus(result) -> np.ndarray:
    """(V, K_psi) rows of the fold-of-cycles locus, ordered by K_psi (its two sides)."""
    (continuation,) = result.continuations
    sides = [b for b in continuation.branches if b.kind == BranchKind.FOLD_OF_CYCLES_LOCUS]
    assert len(sides) == 2, [b.name for b in sides]
    rows = np.concatenate([b.parameters[:, :2] for b in sides])
    return rows[np.argsort(rows[:, 1])]


def lowest_lpc(continuation) -> float:
    return min(p.parameters[0] for p in continuation.special_points if p.type_name == "LPC")


def test_the_locus_spans_the_range_and_passes_through_the_one_parameter_fold():
    """Both sides of the locus reach the edges of K_psi's range, V rises with K_psi, and at
    K_psi = 0.3 the locus' airspeed is the lowest fold of cycles of pitch_airspeed.yaml's
    one-parameter continuation (its own seeds, mesh and steps) to 1e-3 relative."""
    study, result = fold_study()
    rows = locus(result)
    (continuation,) = result.continuations
    sides = [b for b in continuation.branches if b.kind == BranchKind.FOLD_OF_CYCLES_LOCUS]
    assert sorted(b.end for b in sides) == ["range", "range"]
    assert rows[0, 1] == pytest.approx(0.2) and rows[-1, 1] == pytest.approx(0.42)
    assert np.all(np.diff(rows[:, 0]) >= -1e-9)  # monotone: one fold per K_psi
    on_locus = float(np.interp(0.3, rows[:, 1], rows[:, 0]))
    one_parameter = lowest_lpc(airspeed_study().continuations[0])
    print(f"\nfold of cycles at K_psi = 0.3: {on_locus:.6f} m/s on the locus, "
          f"{one_parameter:.6f} m/s in pitch_airspeed.yaml; locus from V = {rows[0, 0]:.4f} "
          f"(K_psi = {rows[0, 1]:.3g}) to {rows[-1, 0]:.4f} m/s (K_psi = {rows[-1, 1]:.3g})")
    assert abs(on_locus / one_parameter - 1) < 1e-3


def settled_pitch(model, params, seed) -> tuple[float, float]:
    """Peak-to-peak pitch over the last 40 and the 40 before of 300 periods of the exact law
    (rad)."""
    period = seeds.reference_period(model, params)
    per = 50
    trajectory = simulate.integrate_exact(model, params, seed, 300 * period, samples=300 * per)
    theta = trajectory.states[:, 0]
    return float(np.ptp(theta[-40 * per:])), float(np.ptp(theta[-80 * per:-40 * per]))


@pytest.mark.parametrize("k_psi", [0.25, 0.35])
def test_the_exact_law_has_an_lco_just_above_the_locus_and_none_just_below(k_psi):
    """Independent of AUTO: the exact piecewise law simulated from 8 delta of pitch at the
    locus' airspeed +- 1 %: above, it settles on a limit cycle (peak-to-peak pitch over the
    last 40 periods > 2 delta, the same as over the 40 before to 1e-3); below, the motion dies
    out (peak to peak < 1e-3 delta: on an offset equilibrium)."""
    study, result = fold_study()
    model = study.variant()
    rows = locus(result)
    speed = float(np.interp(k_psi, rows[:, 1], rows[:, 0]))
    seed = np.zeros(model.n_states)
    seed[0] = 8 * DELTA
    found = {}
    for side, factor in (("above", 1 + MARGIN), ("below", 1 - MARGIN)):
        params = model.parameter_vector({**study.parameter_values(), "K_psi": k_psi,
                                         "V": speed * factor})
        found[side] = settled_pitch(model, params, seed)
    (last, before), (dead, _) = found["above"], found["below"]
    print(f"\nK_psi = {k_psi}: locus at V = {speed:.4f} m/s; exact law at "
          f"{speed * (1 + MARGIN):.4f} m/s: pitch peak to peak {last / DELTA:.4f} delta "
          f"(40 periods before: {before / DELTA:.4f}); at {speed * (1 - MARGIN):.4f} m/s: "
          f"{dead / DELTA:.2e} delta")
    assert last > 2 * DELTA and abs(last / before - 1) < 1e-3
    assert dead < 1e-3 * DELTA


def test_the_locus_and_the_seeds_are_stored_and_read_back(tmp_path):
    """The HDF5 file holds the locus (both sides) and what every seed of the slice became."""
    _, result = fold_study()
    path = Path(tmp_path) / "fold.h5"
    api.save(result, path)
    back = api.read(path)
    np.testing.assert_array_equal(locus(back), locus(result))
    outcomes = back.continuations[0].seeds
    assert [s.kind for s in outcomes] == ["equilibrium", "periodic", "periodic"]  # 2, 4, 8 delta
    assert {s.branch for s in outcomes if s.kind == "periodic"} == {"slice_0.periodic_o1"}


def test_bad_seeds_of_a_two_parameter_continuation_are_refused():
    text = (FREEPLAY / "pitch_fold_kpsi.yaml").read_text()
    line = 1 + text[:text.index("seeds: auto")].count("\n")
    for bad, reason in (("[{tehta: 4}]", "expected one of theta, psi"),
                        ("3", "expected `auto` or a list of mappings")):
        with pytest.raises(StudyError, match=reason) as error:
            validate_text(text.replace("seeds: auto", f"seeds: {bad}"), "fold.yaml")
        assert f"fold.yaml:{line}: continuations[0].seeds" in str(error.value)
