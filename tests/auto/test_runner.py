"""The AUTO runner on the real solver: compile cache, failure classification, the parser on
files AUTO has just written, and the generated analytic Jacobian."""

from __future__ import annotations

import numpy as np
import pytest

from whirl_cli.auto import codegen, runner, toolchain
from whirl_cli.auto.constants import par_layout
from whirl_cli.auto.parse import parse_b, parse_d, parse_s
from whirl_cli.continuation.engine import Numerics
from whirl_cli.continuation.equilibria import equilibrium_constants
from whirl_cli.models import get_model


@pytest.fixture(scope="module")
def model():
    return get_model("classical")


@pytest.fixture(scope="module")
def executable(model):
    return toolchain.compile_equations(lambda: codegen.fortran_source(model), model.name,
                                  codegen.source_key(model))


@pytest.fixture()
def constants(model):
    return equilibrium_constants(model, Numerics(), "K_theta", (-0.3, 0.5), -1) | {
        "PAR": {"K_theta": 0.5, "K_psi": 0.3, "K2_theta": 10.0}}


def test_compiled_once_then_cached(model, executable):
    again = toolchain.compile_equations(lambda: pytest.fail("source regenerated"), model.name,
                                   codegen.source_key(model))
    assert again.path == executable.path and not again.compiled


def test_successful_run_and_parser_round_trip(executable, constants, tmp_path, model):
    """Every labelled b-file row has its s-file solution with the same parameters and state,
    and every accepted point has its eigenvalue block in the d-file."""
    outcome = runner.run(executable.path, constants, tmp_path / "run", "ep")
    assert outcome.status == "ok" and outcome.returncode == 0
    assert not (tmp_path / "run" / "fort.2").exists()
    (segment,) = parse_b(outcome.file("b").read_text())
    solutions = parse_s(outcome.file("s").read_text())
    points, _ = parse_d(outcome.file("d").read_text())
    assert len(segment.pt) == outcome.n_points
    assert [s.lab for s in solutions] == [int(x) for x in segment.lab if x]
    layout = par_layout(model)
    for solution in solutions:
        row = int(np.flatnonzero(segment.lab == solution.lab)[0])
        assert solution.ty == segment.ty[row]
        assert solution.par[layout.parameters["K_theta"] - 1] == pytest.approx(
            segment.column("K_theta")[row], rel=1e-9, abs=1e-12)
        for i, name in enumerate(model.state_names):
            assert solution.u[0, i] == pytest.approx(segment.column(f"max_{name}")[row],
                                                     abs=1e-9)
    assert len(points) == len(segment.pt)
    assert all(p.kind == "eigenvalues" and len(p.values) == 4 for p in points)
    assert [p.pt for p in points] == list(segment.pt)
    regular = segment.ty == 0  # at a bifurcation itself the PT sign is borderline
    assert [p.n_stable == 4 for p, r in zip(points, regular, strict=True) if r] == list(
        segment.pt[regular] < 0)


def test_analytic_jacobian_agrees_with_finite_differences(executable, constants, tmp_path):
    """The generated DFDU/DFDP (JAC=1) and AUTO's finite differences (JAC=0) find the same
    Hopf and branch points."""
    found = {}
    for jac in (1, 0):
        outcome = runner.run(executable.path, constants | {"JAC": jac}, tmp_path / f"j{jac}", "j")
        (segment,) = parse_b(outcome.file("b").read_text())
        special = np.isin(segment.ty, (1, 3))
        found[jac] = segment.column("K_theta")[special]
    np.testing.assert_allclose(found[1], found[0], atol=1e-7)
    assert len(found[1]) == 3


#: The timeout of the runs that end by themselves: far longer than they take on any load.
ENDS = 120.0


@pytest.mark.parametrize(("change", "timeout", "status", "message"), [
    ({"IRS": 7}, ENDS, "error", "restart solution file could not be found"),
    ({"NDIM": 3}, ENDS, "crashed", "AUTO crashed with SIGSEGV"),
    ({"PAR": {"K_theta": 0.5, "R": float("nan")}}, ENDS, "error",
     "NaN or Inf in the equations"),
    ({"EPSL": 1e-17, "EPSU": 1e-17, "ITNW": 3, "U": {"theta": 1e-3}}, ENDS, "mx",
     "no convergence"),
    # 10**7 steps of 1e-9: a run no machine finishes, ended by its timeout
    ({"NMX": 10**7, "DS": -1e-9, "DSMIN": 1e-12, "DSMAX": 1e-9}, 0.5, "timeout",
     "did not finish within 0.5 s"),
])
def test_failures_are_reported_not_hidden(executable, constants, tmp_path, change, timeout,
                                          status, message):
    outcome = runner.run(executable.path, constants | change, tmp_path / "run", "bad",
                         timeout=timeout)
    assert outcome.status == status and not outcome.success
    assert message in outcome.message


def test_a_stale_fort2_cannot_leak_into_a_run(executable, constants, tmp_path):
    """Each run needs a fresh directory, and writes its own fort.2."""
    workdir = tmp_path / "run"
    workdir.mkdir()
    (workdir / "fort.2").write_text("NDIM = 3\n")
    with pytest.raises(FileExistsError):
        runner.run(executable.path, constants, workdir, "ep")
