"""``whirl check`` says what it compares: for an equilibrium the initial perturbation and the
final deviation (not "AUTO" and "simulation"), for an orbit AUTO's and the simulated maximum
of the stiffness law's degree of freedom."""

from __future__ import annotations

import inspect
import re

from click.testing import CliRunner

from whirl_cli.analysis import simulate
from whirl_cli.cli import cli

from ..conftest import ROOT

REFERENCE = ROOT / "tests" / "regression" / "references" / "hardening_case2.h5"
NUMBER = r"-?\d[\d.e+-]*"


def test_check_labels_each_kind_of_cross_check_truthfully():
    result = CliRunner().invoke(cli, ["check", str(REFERENCE)])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    equilibria = [line for line in lines if " equilibrium " in line]
    orbits = [line for line in lines if " orbit " in line]
    assert len(equilibria) == 6 and len(orbits) == 6 and len(lines) == 12, result.output
    for line in equilibria:
        assert re.fullmatch(rf"ok   k1/\w+\[\d+\] equilibrium K_theta = {NUMBER}: "
                            rf"perturbation {NUMBER}, final deviation {NUMBER} \(typical "
                            r"amplitudes\)", line), line
    for line in orbits:
        assert re.fullmatch(rf"ok   k1/periodic_\d+\[\d+\] orbit +K_theta = {NUMBER}: max theta "
                            rf"AUTO {NUMBER} rad, simulation {NUMBER} rad", line), line
    assert "AUTO" not in "".join(equilibria)
    # the perturbation of main_down[1] is whirl's default, decayed by orders of magnitude
    default = inspect.signature(simulate.check_equilibrium).parameters["perturbation"].default
    first = re.search(rf"perturbation ({NUMBER}), final deviation ({NUMBER})", lines[0])
    assert float(first.group(1)) == default and float(first.group(2)) < 1e-2 * default


def test_check_does_not_validate_the_stored_study_again(tmp_path):
    """The model and parameters come from the result's provenance: a stored study that
    today's schema rejects (a key it no longer knows) checks all the same."""
    import h5py

    from whirl_cli.output import store

    path = store.write(store.read(REFERENCE), tmp_path / "r.h5")
    with h5py.File(path, "r+") as handle:
        handle.attrs["study_yaml"] = handle.attrs["study_yaml"] + "retired_key: 1\n"
    result = CliRunner().invoke(cli, ["check", str(path)])
    assert result.exit_code == 0, result.output
    assert len(result.output.splitlines()) == 12
    assert all(line.startswith("ok ") for line in result.output.splitlines())
