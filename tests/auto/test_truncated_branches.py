"""A branch that AUTO stops at the study's step limit (``auto: max_steps``) before the end of
its range is stored with that end, said on the console and in the summary, and fails the
study (exit 1, the result still written), on the real AUTO."""

from __future__ import annotations

import h5py
import pytest
from click.testing import CliRunner

from whirl_cli.cli import cli

from ..conftest import STUDIES

LOWER, UPPER = -0.3, 0.5
STUDY = f"""name: short
model: classical
parameters: {{K_psi: 0.3}}
nonlinearity: {{type: linear}}
continuations:
  - name: k1
    type: one-parameter
    parameter: K1
    start: {UPPER}
    range: [{LOWER}, {UPPER}]
    branch_points: false
auto: {{max_steps: %d}}
"""


def _run(tmp_path, max_steps: int):
    study = tmp_path / "short.yaml"
    study.write_text(STUDY % max_steps)
    output = tmp_path / "short.h5"
    return CliRunner().invoke(cli, ["run", str(study), "-o", str(output), "--no-plots"]), output


@pytest.mark.parametrize("max_steps", [1, 50])
def test_a_branch_stopped_by_max_steps_is_stored_said_and_fails(tmp_path, max_steps):
    ran, output = _run(tmp_path, max_steps)
    assert isinstance(ran.exception, SystemExit) and ran.exit_code == 1, ran.output
    with h5py.File(output) as handle:  # written all the same
        branch = handle["continuations/k1/branches/main_down"]
        assert branch.attrs["end"] == "step limit"  # not "range" (max_steps 1: at its start)
        assert len(branch["parameters"]) <= max_steps
        last = branch["parameters"][-1, 0]
    assert last > LOWER + 0.1 * (UPPER - LOWER)  # well short of the range's end
    said = [line for line in ran.output.splitlines() if "main_down" in line and
            "step limit" in line]
    assert said, ran.output
    summary = CliRunner().invoke(cli, ["summary", str(output)])
    assert summary.exit_code == 0, summary.output
    assert any("main_down" in line and "step limit" in line
               for line in summary.output.splitlines()), summary.output


def test_a_branch_that_reaches_its_range_is_no_failure(tmp_path):
    ran, output = _run(tmp_path, 2000)
    assert ran.exit_code == 0, ran.output
    with h5py.File(output) as handle:
        branch = handle["continuations/k1/branches/main_down"]
        assert branch.attrs["end"] == "range"
        assert branch["parameters"][-1, 0] == pytest.approx(LOWER)
    assert "step limit" not in ran.output


def test_a_shipped_study_with_periodic_families_is_no_failure(tmp_path):
    """Families that return to a Hopf point, and equilibria that reach the range."""
    output = tmp_path / "h.h5"
    ran = CliRunner().invoke(cli, ["run", str(STUDIES / "hardening_case2.yaml"), "-o",
                                   str(output), "--no-plots"])
    assert ran.exit_code == 0, ran.output
    assert "step limit" not in ran.output
