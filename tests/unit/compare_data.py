"""A small synthetic study result (an equilibrium branch with a Hopf point feeding a folding
periodic family, and a linear sweep) shared by the compare and store tests."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from whirl_cli.results import (
    Branch,
    ContinuationResult,
    LinearSweep,
    PointType,
    Provenance,
    RunRecord,
    SpecialPoint,
    StudyResult,
)

STATES = ("theta", "psi", "dtheta", "dpsi")
HOPF = 0.2


def equilibrium_branch(values: np.ndarray) -> Branch:
    """The origin along K1 (stable above the Hopf point at K1 = 0.2), HB marked at its row."""
    n = len(values)
    zeros = np.zeros((n, 4))
    point_type = np.zeros(n, dtype=int)
    point_type[np.argmin(np.abs(values - HOPF))] = PointType.HB
    return Branch("main_down", "equilibrium", "start at K1 = 0.5", ("K1",), ("N m/rad",),
                  STATES, ("rad", "rad", "rad/s", "rad/s"), values[:, None], zeros, zeros,
                  np.zeros(n), np.full(n, np.nan), values > HOPF, point_type,
                  np.zeros(n, dtype=int), np.full((n, 4), -1.0 + 2j), end="range")


def periodic_branch(s: np.ndarray) -> Branch:
    """A family born at the Hopf point, folding back at K1 = 0.3 (LPC), amplitude ~ s."""
    k1 = HOPF + 0.1 * (1 - (1 - s) ** 2)  # up to 0.3 at s = 1, back down after
    amplitude = 0.2 * s
    high = np.column_stack([amplitude, 0.5 * amplitude, 3 * amplitude, 2 * amplitude])
    point_type = np.zeros(len(s), dtype=int)
    point_type[np.argmin(np.abs(s - 1))] = PointType.LPC
    return Branch("periodic_1", "periodic", "HB of main_down", ("K1",), ("N m/rad",), STATES,
                  ("rad", "rad", "rad/s", "rad/s"), k1[:, None], high, -high,
                  np.zeros(len(s)), 0.3 + 0.1 * s, s > 1, point_type,
                  np.zeros(len(s), dtype=int), np.ones((len(s), 4), dtype=complex),
                  end="range")


def special_points() -> tuple[SpecialPoint, ...]:
    return (
        SpecialPoint("main_down", 10, PointType.HB, ("K1",), np.array([HOPF]), np.zeros(4),
                     0.3, False, criticality="subcritical"),
        SpecialPoint("periodic_1", 40, PointType.LPC, ("K1",), np.array([0.3]),
                     np.array([0.2, 0.1, 0.6, 0.4]), 0.4, False),
    )


def make_result(main_points: int = 201, periodic_points: int = 161, **changes) -> StudyResult:
    """A small study result; ``main_points``/``periodic_points`` change only the sampling."""
    branches = (equilibrium_branch(np.linspace(0.5, -0.3, main_points)),
                periodic_branch(np.linspace(0.0, 1.6, periodic_points)))
    continuation = ContinuationResult("k1", "one-parameter", branches, special_points())
    values = np.linspace(0.0, 10.0, 11)
    eigenvalues = np.column_stack([-1 + values * 0.1 + 2j, -1 + values * 0.1 - 2j])
    sweep = LinearSweep("V", "m/s", values, eigenvalues, -eigenvalues.real / 2.2,
                        np.abs(eigenvalues.imag), np.array([["FW", "BW"]] * 11))
    found = Provenance(study_sha256="abc", study_yaml="name: x\n", whirl_version="0.1.0",
                       created="2026-01-01T00:00:00Z", auto_version="0.9.2")
    result = StudyResult("x", "classical_poly_theta", (continuation,), (sweep,),
                         (RunRecord("k1.main_down", "ok", "ok", "", 0, 0.1, main_points),),
                         provenance=found)
    return replace(result, **changes)
