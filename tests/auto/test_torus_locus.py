"""The torus (Neimark-Sacker, TR) locus in two parameters on the real AUTO-07p (issue 16),
checked against computations that do not use it.

Study ``studies/gimballed/torus_locus_kbeta.yaml``: the parameters of ``torus_airspeed.yaml``
(whose one-parameter run has its TR point at V = 11.785 m/s, K_beta = 0.67 N m/rad, the pair of
Floquet multipliers crossing the unit circle at 0.513 rad; ``tests/auto/test_torus.py``), with
the torus locus in (V, K_beta) traced from there and a second slice at K_beta = 0.62. The result
is written to HDF5 and read back, so the checks are on the stored file.

What is asserted:

* the locus passes through torus_airspeed's TR point (V = 11.785 m/s at K_beta = 0.67, to
  1e-3 m/s, the 4 digits stated) at its angle (0.513 rad, to 1e-3 rad);
* at K_beta = 0.62 the slice's own one-parameter periodic run (AUTO's Floquet multipliers, not
  the locus's extended system) has a TR point on the locus, within 2e-3 m/s (0.05 % of the
  range; measured ~1e-5), and the angle of its multiplier pair is the locus's stored angle
  there within 1e-3 rad (measured ~1e-5); that slice's start was not traced again;
* at the labelled ends of every torus locus (other values of both parameters) the monodromy
  matrix integrated with scipy (variational equation of the model's numpy right-hand side and
  Jacobian) over the stored orbit has a complex pair of multipliers on the unit circle (to
  1e-5) at the stored angle (to 1e-5 rad; measured ~1e-9), and the orbit closes;
* the angle varies along the locus (it is not a frozen start value) and the locus reaches the
  edge of the range at both ends.

Cost (measured): one study (four periodic families, two torus loci, each two stages in both
directions; ~9 s of AUTO runs), 24 s CPU for the three tests with pytest's start-up, 28-44 s
wall on the loaded 2-core machine (load 4-10); the scipy checks < 1 s.
"""

from __future__ import annotations

import tempfile
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from whirl_cli.continuation.branches import neimark_sacker_angle
from whirl_cli.output.store import read, write
from whirl_cli.pipeline import run_study
from whirl_cli.results import BranchKind, PointType
from whirl_cli.study import load_study

from ..conftest import ROOT

pytestmark = pytest.mark.auto

STUDY = ROOT / "studies" / "gimballed" / "torus_locus_kbeta.yaml"
#: torus_airspeed.yaml's TR point (README; tests/auto/test_torus.py): V [m/s], angle [rad]
AIRSPEED_TR, AIRSPEED_ANGLE, AIRSPEED_KBETA = 11.785, 0.513, 0.67


@cache
def computed():
    study = load_study(STUDY)
    folder = Path(tempfile.mkdtemp(prefix="whirl-test-"))
    result = run_study(study, folder, jobs=2)
    return study, read(write(result, folder / "torus_locus.h5"))


def _continuation():
    _, result = computed()
    (continuation,) = result.continuations
    return continuation


def _loci():
    return [b for b in _continuation().branches if b.kind == BranchKind.TORUS_LOCUS]


def _at(branch, k_beta: float) -> tuple[float, float]:
    """(V, angle) where ``branch`` (a torus locus) crosses K_beta = ``k_beta`` (linear
    interpolation between its points)."""
    v, second = branch.parameters[:, 0], branch.parameters[:, 1]
    for k in range(len(branch) - 1):
        lo, hi = sorted(second[k:k + 2])
        if lo <= k_beta <= hi and hi > lo:
            w = (k_beta - second[k]) / (second[k + 1] - second[k])
            return (float(v[k] + w * (v[k + 1] - v[k])),
                    float(branch.torus_angle[k] + w * (branch.torus_angle[k + 1]
                                                       - branch.torus_angle[k])))
    raise AssertionError(f"{branch.name} does not cross K_beta = {k_beta}")


def _crossing(k_beta: float) -> tuple[str, float, float]:
    """(locus, V, angle) of the torus loci crossing K_beta = ``k_beta``, nearest V first."""
    found = []
    for branch in _loci():
        try:
            found.append((branch.name, *_at(branch, k_beta)))
        except AssertionError:
            continue
    return found


def test_the_torus_locus_passes_through_the_airspeed_studys_torus_point():
    """torus_airspeed's TR (V = 11.785 m/s at K_beta = 0.67, angle 0.513 rad) is on a stored
    torus locus, which runs to the range edge both ways and carries its angle in the file."""
    _, result = computed()
    (boundary,) = result.boundaries
    assert {kind for kind, _ in boundary.loci.values()} == {"hopf", "torus"}
    crossings = [(abs(v - AIRSPEED_TR), name, v, angle)
                 for name, v, angle in _crossing(AIRSPEED_KBETA)]
    _, name, v, angle = min(crossings)
    print(f"\n  {name}: V = {v:.5f} m/s, angle {angle:.5f} rad at K_beta = {AIRSPEED_KBETA}")
    assert v == pytest.approx(AIRSPEED_TR, abs=1e-3)
    assert angle == pytest.approx(AIRSPEED_ANGLE, abs=1e-3)
    for branch in _loci():
        assert branch.end == "range", (branch.name, branch.end)
        assert boundary.loci[branch.name][0] == "torus"
        np.testing.assert_array_equal(boundary.loci[branch.name][1], branch.parameters[:, :2])
        assert np.all((branch.torus_angle > 0) & (branch.torus_angle < np.pi))
        assert np.ptp(branch.torus_angle) > 1e-3  # the angle is free along the locus
        assert np.ptp(branch.parameters[:, 1]) > 1e-3  # and so is K_beta


def test_the_slice_at_another_gimbal_stiffness_finds_its_torus_point_on_the_locus():
    """The one-parameter periodic run at K_beta = 0.62 (Floquet multipliers of the cycle, not
    the locus's extended system) finds a TR point on the locus traced from the slice at 0.67,
    at the locus's angle there; recognised as on that locus, it starts no locus of its own."""
    continuation = _continuation()
    slice_points = [p for p in continuation.special_points if p.point_type == PointType.TR
                    and p.branch.startswith("slice_1.") and p.parameters[1] == 0.62]
    from_first = [b for b in _loci() if b.origin.branch.startswith("slice_0.")]
    assert from_first and slice_points
    crossings = [c for b in from_first for c in _crossing(0.62) if c[0] == b.name]
    on_locus = []
    for point in slice_points:
        if any(b.origin.branch == point.branch for b in _loci()):
            continue  # it starts a locus of its own (the gimbal cycle's torus point)
        v, angle = point.parameters[0], point.torus_angle
        name, locus_v, locus_angle = min(crossings, key=lambda c: abs(c[1] - v))
        print(f"\n  slice TR at V = {v:.6f} m/s, angle {angle:.6f} rad; {name} there: V = "
              f"{locus_v:.6f} m/s, angle {locus_angle:.6f} rad")
        assert locus_v == pytest.approx(v, abs=2e-3)
        assert locus_angle == pytest.approx(angle, abs=1e-3)
        on_locus.append(point)
    assert len(on_locus) == 1  # the nacelle cycle's torus point


def test_monodromy_of_the_stored_orbits_has_its_pair_on_the_unit_circle_at_the_angle():
    """At every labelled point of a torus locus with a stored orbit (its ends: other V and
    K_beta than the start), the monodromy matrix integrated with scipy over one period has a
    complex pair on the unit circle at the stored angle, besides the trivial multiplier 1."""
    study, _ = computed()
    model = study.variant()
    overrides = study.parameter_values()
    scale = np.asarray(model.state_scale)
    n = model.n_states
    checked = 0
    for branch in _loci():
        for orbit in branch.orbits:
            values = dict(zip(branch.parameter_names, map(float, orbit.parameters), strict=True))
            params = model.parameter_vector({**overrides, **values})
            start = orbit.states[0]

            field, jacobian = model.field_at(params)  # the model's numpy f and df/dy

            def variational(_t, z, field=field, jacobian=jacobian):
                y, matrix = z[:n], z[n:].reshape(n, n)
                return np.concatenate([field(y), (jacobian(y) @ matrix).ravel()])

            end = solve_ivp(variational, (0.0, orbit.period),
                            np.concatenate([start, np.eye(n).ravel()]), method="DOP853",
                            rtol=1e-10, atol=1e-12).y[:, -1]
            assert np.abs((end[:n] - start) / scale).max() < 1e-6  # the orbit closes
            multipliers = np.linalg.eigvals(end[n:].reshape(n, n))
            stored = branch.torus_angle[orbit.index]
            upper = multipliers[multipliers.imag > 1e-6]
            pair = upper[np.argmin(np.abs(np.angle(upper) - stored))]
            print(f"\n  {branch.name} at V = {values['V']:.4f}, K_beta = {values['K_beta']:.4f}: "
                  f"|mu| = {abs(pair):.7f}, angle {np.angle(pair):.7f} (stored {stored:.7f})")
            assert abs(abs(pair) - 1) < 1e-5
            assert np.angle(pair) == pytest.approx(stored, abs=1e-5)
            assert neimark_sacker_angle(multipliers) == pytest.approx(stored, abs=1e-5)
            assert np.abs(multipliers - 1).min() < 1e-5  # the trivial multiplier
            checked += 1
    assert checked >= len(_loci())  # the far end of every locus (labelled UZ)
