"""The tiltrotor gimbal (1.05/rev) with blade pitch held relative to the shaft on the real
AUTO-07p: study ``studies/gimballed/tiltrotor_shaft_pitch.yaml`` (``pitch_on_disc: 0``), every
critical point against numpy eigenvalues of the strip theory derived in
tests/gimbal_strip_theory.py, never against whirl's own output.
"""

from __future__ import annotations

import tempfile
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from whirl_cli.pipeline import run_study
from whirl_cli.results import PointType
from whirl_cli.study import load_study

from ..conftest import ROOT
from ..gimbal_strip_theory import matrices

pytestmark = pytest.mark.auto

STUDY = ROOT / "studies" / "gimballed" / "tiltrotor_shaft_pitch.yaml"
VALUES = {"K_psi": 0.3, "K_beta": 0.008446}


@cache
def computed():
    return run_study(load_study(STUDY), Path(tempfile.mkdtemp(prefix="whirl-test-")), jobs=2)


def _first_order(v: float) -> np.ndarray:
    mass, damping, stiffness = matrices({**VALUES, "V": v}, shaft=True)
    minv = np.linalg.inv(mass)
    return np.block([[np.zeros((4, 4)), np.eye(4)], [-minv @ stiffness, -minv @ damping]])


def _oscillatory_growth(v: float) -> float:
    values = np.linalg.eigvals(_first_order(v))
    return float(values[np.abs(values.imag) > 1e-9].real.max())


def _on_the_axis(v: float) -> bool:
    """True if a complex pair sits on the imaginary axis at ``v`` (a Hopf point, not the jump
    of :func:`_oscillatory_growth` where a pair turns real)."""
    values = np.linalg.eigvals(_first_order(v))
    return bool(np.abs(values[np.abs(values.imag) > 1e-3].real).min() < 1e-7)


def _stiffness_determinant(v: float) -> float:
    return float(np.linalg.det(matrices({**VALUES, "V": v}, shaft=True)[2]))


def _roots(function, lower: float, upper: float, points: int = 2001) -> list[float]:
    grid = np.linspace(lower, upper, points)
    signs = np.sign([function(v) for v in grid])
    return [brentq(function, grid[k], grid[k + 1], xtol=1e-12)
            for k in np.flatnonzero(signs[:-1] != signs[1:])]


def test_the_critical_points_are_the_numpy_ones():
    """Along V in [0.1, 20] m/s AUTO's Hopf points are where the derived model's oscillatory
    eigenvalues cross the imaginary axis and its branch points where det K = 0 (1e-4), each
    Hopf point at the crossing pair's frequency (1e-3); none below 15 m/s, where the built-in
    model's gimbal mode flutters from 0.964 m/s."""
    (continuation,) = computed().continuations
    main = [p for p in continuation.special_points if p.branch.startswith("main")]
    hopfs = [p for p in main if p.point_type == PointType.HB]
    branch_points = [p for p in main if p.point_type == PointType.BP]
    expected_hopfs = [v for v in _roots(_oscillatory_growth, 0.1, 20.0) if _on_the_axis(v)]
    expected_branch_points = _roots(_stiffness_determinant, 0.1, 20.0)
    print(f"\n  numpy Hopf {np.round(expected_hopfs, 5)}, BP {np.round(expected_branch_points, 5)}")
    assert len(hopfs) == len(expected_hopfs) >= 1
    assert len(branch_points) == len(expected_branch_points) >= 1
    for point, v in zip(sorted(hopfs, key=lambda p: p.parameters[0]), expected_hopfs,
                        strict=True):
        assert point.parameters[0] == pytest.approx(v, rel=1e-4)
        values = np.linalg.eigvals(_first_order(v))
        omega = abs(values[np.argmin(np.abs(values.real))].imag)
        assert point.period == pytest.approx(2 * np.pi / omega, rel=1e-3)
    for point, v in zip(sorted(branch_points, key=lambda p: p.parameters[0]),
                        expected_branch_points, strict=True):
        assert point.parameters[0] == pytest.approx(v, rel=1e-4)
    assert min(p.parameters[0] for p in hopfs + branch_points) > 15.0
