"""Small synthetic results shared by the plot, sheet and exploration tests."""

from __future__ import annotations

import numpy as np

from whirl_cli.results import (
    Branch,
    BranchKind,
    ContinuationResult,
    LinearSweep,
    Origin,
    ParameterValue,
    PointType,
    SpecialPoint,
    StudyResult,
)

STATES = ("theta", "psi", "dtheta", "dpsi")
UNITS = ("rad", "rad", "rad/s", "rad/s")


def make_branch(name: str, kind: str, k1, theta_max, stable, theta_min=None,
                point_type=None) -> Branch:
    """A branch on K1 [N m/rad] whose theta max/min are given (rad); other states 0.1 * theta."""
    k1 = np.asarray(k1, dtype=float)
    n = len(k1)
    theta_max = np.asarray(theta_max, dtype=float)
    theta_min = theta_max if theta_min is None else np.asarray(theta_min, dtype=float)
    state_max = np.column_stack([theta_max] + [0.1 * theta_max] * 3)
    state_min = np.column_stack([theta_min] + [0.1 * theta_min] * 3)
    periodic = kind == BranchKind.PERIODIC
    return Branch(
        name=name, kind=kind, origin=Origin("test"),
        parameter_names=("K1", "V"), parameter_units=("N m/rad", "m/s"),
        state_names=STATES, state_units=UNITS,
        parameters=np.column_stack([k1, np.full(n, 6.7)]),
        state_max=state_max, state_min=state_min,
        l2_norm=np.abs(theta_max), period=np.full(n, 0.2 if periodic else np.nan),
        stable=np.asarray(stable, dtype=bool),
        point_type=np.zeros(n, int) if point_type is None else np.asarray(point_type),
        label=np.zeros(n, int), eigenvalues=np.full((n, 4), np.nan, complex),
    )


def make_point(branch: str, point_type: PointType, k1: float, theta: float) -> SpecialPoint:
    return SpecialPoint(branch=branch, index=0, point_type=int(point_type),
                        parameter_names=("K1", "V"), parameters=np.array([k1, 6.7]),
                        state=np.array([theta, 0.0, 0.0, 0.0]), period=np.nan, stable=False)


def hopf_continuation() -> ContinuationResult:
    """Equilibrium losing stability at a Hopf (K1 = 0.3) feeding a periodic branch with a fold."""
    equilibrium = make_branch("main_down", BranchKind.EQUILIBRIUM,
                              [0.5, 0.4, 0.3, 0.2, 0.1], [0.0] * 5, [1, 1, 0, 0, 0])
    periodic = make_branch("periodic_1", BranchKind.PERIODIC,
                           [0.3, 0.35, 0.4, 0.35, 0.3], [0.0, 0.1, 0.2, 0.3, 0.4],
                           [0, 0, 0, 1, 1], theta_min=[0.0, -0.1, -0.2, -0.3, -0.4])
    points = (make_point("main_down", PointType.HB, 0.3, 0.0),
              make_point("main_down", PointType.BP, 0.2, 0.0),
              make_point("periodic_1", PointType.LPC, 0.4, 0.2),
              make_point("periodic_1", PointType.EP, 0.3, 0.4))
    return ContinuationResult("hopf_K1", "one-parameter", (equilibrium, periodic), points)


def branch_lines(ax):
    return [line for line in ax.lines if line.get_linestyle() not in ("None", "none", "")]


def make_sweep() -> LinearSweep:
    values = np.linspace(0.1, 0.5, 5)
    bw = -0.1 + 0.05 * np.arange(5) + 1j * (10 - np.arange(5))
    fw = -0.2 + 1j * (20 + np.arange(5))
    eigenvalues = np.column_stack([bw, bw.conj(), fw, fw.conj()])
    modulus = np.abs(eigenvalues)
    whirl = np.array([["BW", "BW", "FW", "FW"]] * 5)
    return LinearSweep("K1", "N m/rad", values, eigenvalues, -eigenvalues.real / modulus,
                       np.abs(eigenvalues.imag), whirl)


#: A minimal study text of the classical model (sheet tests write it as a study file).
STUDY = "name: s\nmodel: classical\n"


def result_with(continuation, k2: float, name: str = "study") -> StudyResult:
    """A classical result holding ``continuation`` and a linear sweep, at K2_theta = ``k2``."""
    parameters = (ParameterValue("K_psi", 0.3, 0.4, "N m/rad"),
                  ParameterValue("K2_theta", k2, 0.0, "N m/rad^3"))
    return StudyResult(name, "classical", (continuation,), (make_sweep(),), (),
                       parameters=parameters)


ASYMPTOTE, SCALE, OFFSET = -0.08, 0.02, 0.3


def blowup_family() -> tuple[np.ndarray, np.ndarray]:
    """A family leaving its Hopf point, turning at a fold (p = -0.04 then back to -0.03),
    then approaching p = -0.08 with T = 0.3 + 0.02 / (p + 0.08) - 0.35 (a period jump at the
    fold, so the growth run starts there)."""
    first = np.linspace(0.3, -0.04, 40)
    back = np.linspace(-0.04, -0.03, 6)[1:]
    run = -0.08 + np.geomspace(0.05, 1e-4, 40)
    period = np.concatenate([0.26 + 0.001 * np.arange(40), 0.30 + 0.01 * np.arange(1, 6),
                             OFFSET + SCALE / (run - ASYMPTOTE)])
    return np.concatenate([first, back, run]), period


def blowup_continuation() -> ContinuationResult:
    parameter, period = blowup_family()
    family = make_branch("periodic_1", BranchKind.PERIODIC, parameter, 0.1 + 0 * parameter,
                         np.arange(len(parameter)) < 60)
    family = family.__class__(**{**family.__dict__, "period": period})
    homoclinic = make_point("periodic_1", PointType.HOMOCLINIC, -0.0801, 0.0)
    fold = make_point("periodic_1", PointType.LPC, -0.04, 0.0)
    return ContinuationResult("k1", "one-parameter", (family,),
                              (homoclinic, fold.__class__(**{**fold.__dict__, "index": 39})))
