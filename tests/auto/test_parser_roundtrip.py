"""The parser (``whirl_cli.auto.parse``) on the files real AUTO-07p has just written, checked
against facts that do not come from the parser: the b-file rows at labelled points against the
s-file solutions of the same label (parameters, type, the states of equilibria, and for
periodic orbits the max/min/amplitude PVLS columns against the max/min of the s-file profile),
AUTO's L2-NORM against the norm recomputed from the profile, the d-file eigenvalues against
numpy eigenvalues of the model Jacobian there and the d-file Floquet multipliers against a
monodromy matrix integrated with scipy along the s-file orbit. The runs: hardening case 2
(K2 = 10, K_psi = 0.3) in K1, its main branch, a secondary branch from the pitchfork and a
piece of the periodic family from the Hopf point at 0.2888. Edge cases of the formats are in
tests/unit/test_parser.py."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from whirl_cli.auto.constants import AMPLITUDE, PERIOD_INDEX, par_layout
from whirl_cli.auto.parse import parse_b, parse_d, parse_s, read_branch
from whirl_cli.continuation.engine import Engine, Numerics, RunSpec
from whirl_cli.continuation.equilibria import equilibrium_constants
from whirl_cli.continuation.periodic import periodic_constants
from whirl_cli.models import get_model
from whirl_cli.results import BranchKind, Origin, PointType

CASE = {"K2_theta": 10.0, "K3_theta": 0.0, "K_psi": 0.3}
BOUNDS = (-0.3, 0.5)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """(model, {"main" | "secondary" | "periodic": RunOutcome}) of three real AUTO runs."""
    model = get_model("classical")
    engine = Engine(model, tmp_path_factory.mktemp("roundtrip"), jobs=2)
    numerics = Numerics(orbits_at=(0.45, 0.35, 0.2, -0.1, -0.2))
    main = equilibrium_constants(model, numerics, "K_theta", BOUNDS, -1)
    main["PAR"] = {**CASE, "K_theta": 0.5}
    (first,) = engine.run_many([RunSpec("rt/main", main, BranchKind.EQUILIBRIUM, Origin("start"),
                                        ("K_theta",))])
    solutions = parse_s(first.file("s").read_text())
    (pitchfork,) = [s for s in solutions if PointType.from_auto(s.ty) == PointType.BP]
    (hopf,) = [s for s in solutions if PointType.from_auto(s.ty) == PointType.HB
               and abs(s.par[0] - 0.2888) < 1e-3]
    secondary = equilibrium_constants(model, numerics, "K_theta", BOUNDS, -1)
    secondary["ISW"] = -1
    periodic = periodic_constants(model, numerics, "K_theta", BOUNDS,
                                  float(hopf.par[PERIOD_INDEX - 1]))
    periodic.update(NMX=41, NPR=10)
    second, third = engine.run_many([
        RunSpec("rt/secondary", secondary, BranchKind.EQUILIBRIUM, Origin("BP"), ("K_theta",),
                restart=("rt.main", pitchfork.lab)),
        RunSpec("rt/periodic", periodic, BranchKind.PERIODIC, Origin("HB"), ("K_theta",),
                restart=("rt.main", hopf.lab))])
    outcomes = {"main": first, "secondary": second, "periodic": third}
    assert all(o.status == "ok" for o in outcomes.values()), outcomes
    return model, outcomes


def _files(outcome):
    """(the one b-file segment, s-file solutions, d-file diagnostics) of a run."""
    segments = parse_b(outcome.file("b").read_text())
    assert len(segments) == 1
    diagnostics, _ = parse_d(outcome.file("d").read_text())
    return segments[0], parse_s(outcome.file("s").read_text()), diagnostics


def _row(segment, label: int) -> int:
    (row,) = np.flatnonzero(segment.lab == label)
    return int(row)


def _parameters(model, solution) -> np.ndarray:
    """The model parameter vector of an s-file solution (its PAR array through the layout)."""
    layout = par_layout(model)
    return model.parameter_vector({name: solution.par[index - 1]
                                   for name, index in layout.parameters.items()})


def _l2_norm(solution) -> float:
    """sqrt(integral over [0, 1] of |u(t)|^2), as AUTO defines its L2-NORM, from the s-file
    profile: in every mesh interval the NCOL + 1 equally spaced points carry the collocation
    polynomial, integrated exactly by the closed Newton-Cotes rule of that order (for an
    equilibrium, a single point: its Euclidean norm)."""
    squares = (solution.u ** 2).sum(axis=1)
    if len(squares) == 1:
        return float(np.sqrt(squares[0]))
    n = solution.ncol
    nodes = np.linspace(0.0, 1.0, n + 1)
    weights = np.linalg.solve(np.vander(nodes, increasing=True).T, 1.0 / np.arange(1, n + 2))
    total = 0.0
    for j in range(solution.ntst):
        points = slice(j * n, j * n + n + 1)
        times = solution.t[points]
        np.testing.assert_allclose(np.diff(times), (times[-1] - times[0]) / n, rtol=1e-6)
        total += (times[-1] - times[0]) * float(weights @ squares[points])
    return float(np.sqrt(total))


def _match(found: np.ndarray, expected: np.ndarray, tolerance: float) -> None:
    """Every expected complex value has its own found value within ``tolerance``."""
    assert len(found) == len(expected), (found, expected)
    left = list(found)
    for value in expected:
        k = int(np.argmin([abs(value - x) for x in left]))
        assert abs(value - left[k]) <= tolerance, (value, found, expected)
        left.pop(k)


@pytest.mark.parametrize("run", ["main", "secondary"])
def test_equilibrium_rows_at_labels_are_the_s_file_solutions(runs, run):
    model, outcomes = runs
    segment, solutions, _ = _files(outcomes[run])
    assert sorted(segment.lab[segment.lab > 0]) == sorted(s.lab for s in solutions)
    assert len(solutions) >= 4
    for solution in solutions:
        k = _row(segment, solution.lab)
        assert segment.ty[k] == solution.ty and solution.ips == 1 and solution.u.shape == (1, 4)
        assert segment.column("K_theta")[k] == pytest.approx(solution.par[0], rel=1e-9, abs=1e-12)
        for i, name in enumerate(model.state_names):
            for column in (f"max_{name}", f"min_{name}"):
                assert segment.column(column)[k] == pytest.approx(solution.u[0, i], rel=1e-9,
                                                                  abs=1e-12)
        assert segment.column("L2-NORM")[k] == pytest.approx(_l2_norm(solution), rel=1e-9,
                                                             abs=1e-12)
        assert segment.column(AMPLITUDE)[k] == 0.0
    if run == "secondary":  # off the origin, so the states are a real test
        assert min(abs(s.u[0, 0]) for s in solutions if s.par[0] < 0) > 0.1


@pytest.mark.parametrize("run", ["main", "secondary"])
def test_d_file_eigenvalues_are_the_model_jacobian_eigenvalues(runs, run):
    """At every labelled equilibrium: the d-file eigenvalues (per unit tau) times the time
    scale, and the branch read_branch builds (1/s, SI states), are numpy's eigenvalues of
    the model's Jacobian at the s-file state (AUTO state times the state scale), to the 6
    digits AUTO prints; and the stability flag (PT < 0) says all real parts are negative."""
    model, outcomes = runs
    segment, solutions, diagnostics = _files(outcomes[run])
    branch = read_branch(outcomes[run], model, name=run, kind=BranchKind.EQUILIBRIUM,
                         origin=Origin(""), parameter_names=("K_theta",))
    scale = np.asarray(model.state_scale)
    for solution in solutions:
        k = _row(segment, solution.lab)
        state = solution.u[0] * scale
        np.testing.assert_allclose(branch.state_max[k], state, rtol=1e-9, atol=1e-12)
        expected = np.linalg.eigvals(model.jacobian_numpy(state, _parameters(model, solution)))
        tolerance = 2e-5 * np.abs(expected).max()
        (printed,) = [d for d in diagnostics if (abs(d.br), abs(d.pt)) == (
            abs(segment.br[k]), abs(segment.pt[k]))]
        assert printed.kind == "eigenvalues"
        _match(printed.values * model.time_scale, expected, tolerance)
        _match(branch.eigenvalues[k], expected, tolerance)
        if PointType.from_auto(int(segment.ty[k])) not in (PointType.HB, PointType.BP):
            assert (segment.pt[k] < 0) == (expected.real.max() < 0)
            assert branch.stable[k] == (expected.real.max() < 0)


def test_periodic_rows_at_labels_are_the_s_file_profiles(runs):
    """PERIOD, K1, the PVLS max/min of every state and the amplitude at each labelled orbit
    are those of the s-file profile; L2-NORM is its norm recomputed from the profile."""
    model, outcomes = runs
    segment, solutions, _ = _files(outcomes["periodic"])
    orbits = [s for s in solutions if s.ips == 2]
    assert len(orbits) >= 4 and all(s.u.shape == (s.ntst * s.ncol + 1, 4) for s in orbits)
    for solution in orbits:
        k = _row(segment, solution.lab)
        assert segment.br[k] < 0 and segment.ty[k] == solution.ty
        assert segment.column("K_theta")[k] == pytest.approx(solution.par[0], rel=1e-9)
        assert segment.column("PERIOD")[k] == pytest.approx(solution.par[PERIOD_INDEX - 1],
                                                            rel=1e-9)
        for i, name in enumerate(model.state_names):
            assert segment.column(f"max_{name}")[k] == pytest.approx(
                solution.u[:, i].max(), rel=1e-9, abs=1e-12)
            assert segment.column(f"min_{name}")[k] == pytest.approx(
                solution.u[:, i].min(), rel=1e-9, abs=1e-12)
        half = (solution.u.max(axis=0) - solution.u.min(axis=0)) / 2
        assert segment.column(AMPLITUDE)[k] == pytest.approx(half.max(), rel=1e-9)
        assert segment.column("L2-NORM")[k] == pytest.approx(_l2_norm(solution), rel=1e-8)
    assert max(segment.column(AMPLITUDE)) > 0.01  # grown orbits, not the Hopf point only


def test_d_file_multipliers_are_the_monodromy_eigenvalues(runs):
    """Integrated with scipy from the s-file orbit's first point over its period (SI, via the
    time and state scales), the orbit closes, and the eigenvalues of the monodromy matrix
    (variational equation with the model Jacobian) are the d-file Floquet multipliers, to the
    6 digits AUTO prints; read_branch stores the same multipliers and profiles."""
    model, outcomes = runs
    segment, solutions, diagnostics = _files(outcomes["periodic"])
    branch = read_branch(outcomes["periodic"], model, name="periodic",
                         kind=BranchKind.PERIODIC, origin=Origin(""), parameter_names=("K_theta",))
    scale = np.asarray(model.state_scale)
    orbits = [s for s in solutions if s.ips == 2]
    assert len(branch.orbits) == len(orbits)
    for solution, orbit in zip(orbits, branch.orbits, strict=True):
        k = _row(segment, solution.lab)
        params = _parameters(model, solution)
        period = solution.par[PERIOD_INDEX - 1] / model.time_scale
        assert orbit.period == pytest.approx(period, rel=1e-12) and orbit.index == k
        np.testing.assert_allclose(orbit.states, solution.u[:, :4] * scale, rtol=1e-12)
        start = solution.u[0, :4] * scale

        field, jacobian = model.field_at(params)  # the model's numpy f and df/dy

        def variational(_t, z, field=field, jacobian=jacobian):
            y, matrix = z[:4], z[4:].reshape(4, 4)
            return np.concatenate([field(y), (jacobian(y) @ matrix).ravel()])

        end = solve_ivp(variational, (0.0, period), np.concatenate([start, np.eye(4).ravel()]),
                        method="DOP853", rtol=1e-11, atol=1e-13).y[:, -1]
        assert np.abs((end[:4] - start) / scale).max() < 1e-7  # a periodic orbit
        monodromy = np.linalg.eigvals(end[4:].reshape(4, 4))
        (printed,) = [d for d in diagnostics if (abs(d.br), abs(d.pt)) == (
            abs(segment.br[k]), abs(segment.pt[k]))]
        assert printed.kind == "multipliers"
        _match(printed.values, monodromy, 2e-5)
        _match(branch.eigenvalues[k], monodromy, 2e-5)
        assert branch.stable[k] == (np.sort(np.abs(monodromy))[-2] < 1)
