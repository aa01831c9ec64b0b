"""The example model file beyond the thesis (studies/nacelle_on_wing): its shipped study on the
real AUTO against an independent computation written here. The test reads the model file's
expressions itself and evaluates them with numpy (trusted test code, none of whirl's parser or
generated code): the Hopf point against the eigenvalues of its own Jacobian, and the stable
limit cycle's amplitude against a scipy time simulation."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from whirl_cli import api
from whirl_cli.results import PointType
from whirl_cli.study import load_study

FOLDER = Path(__file__).resolve().parents[2] / "studies" / "nacelle_on_wing"
K2 = 10.0  # the study's hardening cubic on pitch (airspeed_hardening.yaml)
V_CYCLE = 8.0  # m/s, on the stable family past the Hopf point


class Equations:
    """dy/dt of the model file with the cubic pitch law, from its own text, with numpy."""

    def __init__(self, path: Path) -> None:
        self.declared = yaml.safe_load(path.read_text())
        self.dofs = [d["name"] for d in self.declared["dofs"]]
        self.datum = {p["name"]: float(p["value"]) for p in self.declared["parameters"]}
        self.functions = {"sqrt": np.sqrt, "asinh": np.arcsinh}
        code = {name: compile(str(text), name, "eval") for name, text in
                self.declared["definitions"].items()}
        self.definitions = list(code.items())
        self.mass = [[compile(str(e), "mass", "eval") for e in row]
                     for row in self.declared["mass"]]
        self.forces = [compile(str(self.declared["forces"][d]), d, "eval") for d in self.dofs]

    def rhs(self, y: np.ndarray, values: dict) -> np.ndarray:
        n = len(self.dofs)
        scope = dict(self.functions, **values)
        scope.update({d: y[i] for i, d in enumerate(self.dofs)})
        scope.update({f"d{d}": y[n + i] for i, d in enumerate(self.dofs)})
        empty = {"__builtins__": {}}
        for name, code in self.definitions:  # the test's own trusted file
            scope[name] = eval(code, empty, scope)  # noqa: S307
        mass = np.array([[eval(e, empty, scope) for e in row] for row in self.mass])  # noqa: S307
        forces = np.array([eval(f, empty, scope) for f in self.forces])  # noqa: S307
        stiffness = np.array([values[dof["stiffness"]] * y[i] for i, dof in
                              enumerate(self.declared["dofs"])])
        stiffness[0] += K2 * y[0] ** 3
        return np.concatenate([y[n:], np.linalg.solve(mass, forces - stiffness)])

    def max_growth(self, speed: float) -> float:
        values = {**self.datum, "V": speed}
        size, step = 2 * len(self.dofs), 1e-7
        jacobian = np.column_stack([
            (self.rhs(step * e, values) - self.rhs(-step * e, values)) / (2 * step)
            for e in np.eye(size)])
        return float(np.linalg.eigvals(jacobian).real.max())


def test_example_study_against_eigenvalues_and_simulation():
    equations = Equations(FOLDER / "nacelle_on_wing.model.yaml")
    result = api.run(load_study(FOLDER / "airspeed_hardening.yaml"))
    (continuation,) = result.continuations
    hopf = [p for p in continuation.special_points if p.point_type == PointType.HB]
    assert len(hopf) == 1
    onset = brentq(equations.max_growth, 5.0, 9.0, xtol=1e-12)
    assert hopf[0].parameters[0] == pytest.approx(onset, rel=1e-7)

    family = next(b for b in continuation.branches if b.kind == "periodic")
    assert family.stable[np.argmin(abs(family.parameters[:, 0] - V_CYCLE))]
    order = np.argsort(family.parameters[:, 0])
    expected = float(np.interp(V_CYCLE, family.parameters[order, 0],
                               family.state_max[order, 0]))
    values = {**equations.datum, "V": V_CYCLE}
    start = np.zeros(6)
    start[0] = math.radians(3.0)
    settled = solve_ivp(lambda t, y: equations.rhs(y, values), (0.0, 60.0), start,
                        method="DOP853", rtol=1e-9, atol=1e-12, dense_output=True)
    assert settled.success
    late = settled.sol(np.linspace(55.0, 60.0, 10001))[0]
    assert abs(late.max() - expected) <= 0.005 * expected
    assert abs(late.max() + late.min()) <= 1e-3 * late.max()  # settled: a symmetric cycle
