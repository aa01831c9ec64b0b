"""A genuine torus (Neimark-Sacker) bifurcation of the gimballed model (issue 16) on the real
AUTO-07p, checked independently of AUTO's TR label: the Floquet multipliers on either side of
it, and time simulation just past it.

Study ``studies/gimballed/torus_airspeed.yaml``: a light rotor on a soft gimbal with hardening
cubic springs on every dof, continued in airspeed. The nacelle whirl mode flutters first; its
stable limit cycle loses stability where the gimbal mode joins in. The expected values come
from AUTO's multipliers (the angle of the pair that crosses the unit circle) and are compared
with what the simulation (scipy, the model's numpy right-hand side) settles on.

What was found (and is asserted): at the TR point a complex pair of multipliers crosses the
unit circle at angle ~0.51 rad (|mu| < 1 before, > 1 after), far from 0 and pi; just past it
(V = 11.82 m/s) the simulation from the explore's default start is classified quasi-periodic,
its largest Lyapunov exponent zero within its threshold, and its spectrum holds the cycle's
frequency f_c and combinations m f_c + n f_2 with f_2 = angle / (2 pi) f_c, the second frequency
the multipliers predict. At V = 11.9 the same holds, though there the first window (20 periods
of the linear whirl mode, ~2.3 s) cannot tell the torus from a 1:12 resonance (f_c ~ 24.2 Hz ~
12 x 2.0 Hz within 1.5 frequency bins: the spectrum reads as harmonics of f_2) while its
section does not repeat; the classifier then doubles the window, which resolves the two base
frequencies.
"""

from __future__ import annotations

import tempfile
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from whirl_cli.analysis.motion import CURVE_DIMENSION
from whirl_cli.pipeline import run_study
from whirl_cli.results import PointType
from whirl_cli.study import load_study

from ..conftest import ROOT

pytestmark = pytest.mark.auto

STUDY = ROOT / "studies" / "gimballed" / "torus_airspeed.yaml"


@cache
def computed():
    return run_study(load_study(STUDY), Path(tempfile.mkdtemp(prefix="whirl-test-")), jobs=2)


def _torus_point():
    (continuation,) = computed().continuations
    torus = [p for p in continuation.special_points if p.point_type == PointType.TR]
    assert len(torus) == 1, [(p.branch, p.parameters) for p in torus]
    (point,) = torus
    branch = next(b for b in continuation.branches if b.name == point.branch)
    return point, branch


def _pair(multipliers: np.ndarray, angle: float) -> complex:
    """The multiplier of the upper half plane nearest the angle ``angle`` (rad)."""
    upper = multipliers[np.isfinite(multipliers) & (multipliers.imag > 0)]
    return complex(upper[np.argmin(np.abs(np.angle(upper) - angle))])


def test_the_torus_point_has_a_complex_pair_crossing_the_unit_circle():
    """Two rows before the TR point the pair is inside the unit circle, two rows after it
    outside, at an angle well away from 0 and pi; the cycle is stable before, unstable after."""
    point, branch = _torus_point()
    angle = point.torus_angle
    print(f"\n  TR at V = {point.parameters[0]:.5f} m/s, angle {angle:.4f} rad, period "
          f"{point.period:.5f} s")
    assert 0.3 < angle < np.pi - 0.3
    before, after = (_pair(branch.eigenvalues[point.index + k], angle) for k in (-2, 2))
    print(f"  multipliers: before {before:.4f} (|mu| {abs(before):.4f}), after {after:.4f} "
          f"(|mu| {abs(after):.4f})")
    assert abs(before) < 1 < abs(after)
    assert abs(np.angle(before) - angle) < 0.05 and abs(np.angle(after) - angle) < 0.05
    assert branch.stable[point.index - 2] and not branch.stable[point.index + 2]


def _window(value: float) -> float:
    """The classification window (s) at V = ``value``: 20 periods of the least damped
    oscillatory eigenvalue of the origin, as :func:`whirl_cli.analysis.motion.classify_model`
    takes it."""
    study = load_study(STUDY)
    model = study.variant()
    _, jacobian = model.field_at(model.parameter_vector({**study.parameter_values(), "V": value}))
    eigenvalues = np.linalg.eigvals(jacobian(np.zeros(model.n_states)))
    oscillatory = eigenvalues[np.abs(eigenvalues.imag) > 1e-9 * np.abs(eigenvalues).max()]
    return 20 * 2 * np.pi / abs(oscillatory[np.argmax(oscillatory.real)].imag)


def _combination(frequency: float, f_c: float, f_2: float, tolerance: float) -> tuple[int, int]:
    """(m, n), |m| <= 6, 0 <= n <= 6, with |m f_c + n f_2| within ``tolerance`` (Hz) of
    ``frequency``, the smallest |m| + |n|; (0, 0) if none."""
    best = (0, 0)
    for m in sorted(range(-6, 7), key=lambda m: (abs(m), -m)):
        for n in range(0, 7):
            if abs(abs(m * f_c + n * f_2) - frequency) <= tolerance and (
                    best == (0, 0) or abs(m) + n < abs(best[0]) + best[1]):
                best = (m, n)
    return best


def _assert_torus(found, point, window: float) -> None:
    """``found`` is quasi-periodic at the cycle frequency f_c, every spectral peak a
    combination of f_c and angle / (2 pi) f_c (within 2 bins of ``window`` s), one of them not
    a harmonic, lambda zero within the threshold."""
    print(f"\n  V = {found.value}: {found.evidence}")
    assert found.kind == "quasi-periodic", found.evidence
    f_c = float(found.frequencies[0])  # the section's return frequency: the cycle's
    assert f_c == pytest.approx(1 / point.period, rel=0.02)
    f_2 = point.torus_angle / (2 * np.pi) * f_c
    combos = [_combination(p, f_c, f_2, 2 / window) for p in found.peaks]
    print(f"  f_c = {f_c:.3f} Hz, f_2 = {f_2:.3f} Hz (from the angle); peaks "
          + ", ".join(f"{p:.3f} = |{m} f_c + {n} f_2|"
                      for p, (m, n) in zip(found.peaks, combos, strict=True)))
    assert all(c != (0, 0) for c in combos)
    assert any(n != 0 for _, n in combos)
    assert abs(found.lyapunov) < 0.01 * 2 * np.pi * f_c + 3 * found.lyapunov_error


def test_just_past_the_torus_point_the_motion_is_quasi_periodic_at_the_predicted_frequency():
    """At V = 11.82 m/s (0.3 % past the TR point) the simulation settles on a two-frequency
    motion: class quasi-periodic, lambda zero within the threshold, every spectral peak a
    combination of the cycle frequency and angle / (2 pi) times it, one of them not a harmonic
    (the first window suffices: section and spectrum agree)."""
    point, _ = _torus_point()
    near, _farther = computed().continuations[0].explorations
    assert near.value > point.parameters[0]
    assert "did not repeat" not in near.evidence
    _assert_torus(near, point, _window(near.value))


def test_farther_past_it_the_doubled_window_resolves_the_torus():
    """At V = 11.9 m/s the first window's spectrum reads as harmonics of f_2 (near 1:12) while
    the section does not repeat: the window is doubled, and the motion is quasi-periodic as
    at 11.82, its section a closed curve (no lag-k repeat, correlation dimension < 1.5), twice
    as many section points as returns in one window."""
    point, _ = _torus_point()
    farther = computed().continuations[0].explorations[1]
    window = 2 * _window(farther.value)
    _assert_torus(farther, point, window)
    assert "window doubled" in farther.evidence
    assert farther.multiplicity == 0
    assert farther.section_dimension < CURVE_DIMENSION
    returns = window * float(farther.frequencies[0])
    assert len(farther.section) == pytest.approx(returns, abs=2)
