"""Bad freeplay laws through ``whirl run``: refused before anything runs (exit 1, no output
file, AUTO never started), each as ``file:line: key.path: reason``."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from whirl_cli import pipeline
from whirl_cli.cli import cli

HEAD = "name: fp\nmodel: classical\nparameters: {K_psi: 0.3}\n"
TAIL = ("continuations:\n"
        "  - {name: v, type: one-parameter, parameter: V, range: [6.0, 8.0]}\n")

CASES = [
    ("delta: 0.0", "nonlinearity.delta: delta_theta must be > 0 rad, got 0.0"),
    ("delta: -0.01", "nonlinearity.delta: delta_theta must be > 0 rad, got -0.01"),
    ("delta: 0.01, epsilon: 0.0",
     "nonlinearity.epsilon: epsilon_theta must be > 0 rad, got 0.0"),
    ("delta: 0.01, epsilon: -1.0e-4",
     "nonlinearity.epsilon: epsilon_theta must be > 0 rad, got -0.0001"),
    ("delta: 0.01, epsilon: 0.01",
     "nonlinearity.epsilon: epsilon must be < delta = 0.01 (the smoothing width below the "
     "half-gap), got 0.01"),
    ("delta: 0.01, epsilon: 0.05",
     "nonlinearity.epsilon: epsilon must be < delta = 0.01 (the smoothing width below the "
     "half-gap), got 0.05"),
    ("delta: 0.01, K_in: -0.1",
     "nonlinearity.K_in: K_in_theta must be >= 0 N m/rad, got -0.1"),
    ("delta: 0.01, K_in: 0.2, K_out: 0.2",
     "nonlinearity.K_out: K_out must be > K_in = 0.2 (stiffer outside the gap than inside), "
     "got K_out = 0.2"),
    ("delta: 0.01, K_in: 0.2, K_out: 0.1",
     "nonlinearity.K_out: K_out must be > K_in = 0.2 (stiffer outside the gap than inside), "
     "got K_out = 0.1"),
    # K_out unset is K_theta's datum, 0.4: a larger K_in is blamed where it is written
    ("delta: 0.01, K_in: 0.5",
     "nonlinearity.K_in: K_out must be > K_in = 0.5 (stiffer outside the gap than inside), "
     "got K_out = 0.4"),
]


@pytest.mark.parametrize(("law", "reason"), CASES, ids=[c[0] for c in CASES])
def test_bad_freeplay_law_is_refused_before_anything_runs(law, reason, tmp_path, monkeypatch):
    def never(*args, **kwargs):
        raise AssertionError("a bad study reached the runs")

    monkeypatch.setattr(pipeline, "run_and_draw", never)  # run_study calls it too
    study = tmp_path / "bad.yaml"
    study.write_text(HEAD + f"nonlinearity: {{type: freeplay, dof: theta, {law}}}\n" + TAIL)
    output = tmp_path / "out.h5"
    result = CliRunner().invoke(cli, ["run", str(study), "-o", str(output), "--no-plots"])
    assert result.exit_code == 1, result.output
    assert f"bad.yaml:4: {reason}" in result.output.splitlines(), result.output
    assert not output.exists()


def test_a_freeplay_law_in_a_list_is_checked_at_its_item(tmp_path):
    study = tmp_path / "list.yaml"
    study.write_text("name: fp\nmodel: classical\nnonlinearity:\n"
                     "  - {type: polynomial, dof: theta, K2: 10.0}\n"
                     "  - {type: freeplay, dof: psi, delta: 0.01, epsilon: 0.02}\n" + TAIL)
    result = CliRunner().invoke(cli, ["validate", str(study)])
    assert result.exit_code == 1
    assert result.output.splitlines() == [
        "list.yaml:5: nonlinearity[1].epsilon: epsilon must be < delta = 0.01 (the smoothing "
        "width below the half-gap), got 0.02"]


def test_the_stiffness_outside_the_gap_is_set_in_the_law_only(tmp_path):
    study = tmp_path / "twice.yaml"
    study.write_text("name: fp\nmodel: classical\nparameters: {K_theta: 0.3}\n"
                     "nonlinearity: {type: freeplay, dof: theta, delta: 0.01}\n" + TAIL)
    result = CliRunner().invoke(cli, ["validate", str(study)])
    assert result.exit_code == 1
    assert result.output.splitlines() == [
        "twice.yaml:3: parameters.K_theta: set K_theta under nonlinearity (type: freeplay, "
        "dof: theta) as K_out"]


@pytest.mark.parametrize(("continuation", "reason"), [
    ("{name: e, type: one-parameter, parameter: epsilon_theta, range: [1.0e-5, 0.02]}",
     "the range reaches 0.02 where epsilon must be < delta = 0.01 (the smoothing width below "
     "the half-gap), got 0.02"),
    ("{name: k, type: one-parameter, parameter: K_out_theta, range: [-0.3, 0.5]}",
     "the range reaches -0.3 where K_out must be > K_in = 0.0 (stiffer outside the gap than "
     "inside), got K_out = -0.3"),
    ("{name: k, type: one-parameter, parameter: K_in_theta, range: [0.0, 0.4]}",
     "the range reaches 0.4 where K_out must be > K_in = 0.4 (stiffer outside the gap than "
     "inside), got K_out = 0.4"),
], ids=["epsilon", "K_out", "K_in"])
def test_a_continuation_may_not_leave_the_valid_freeplay_laws(continuation, reason, tmp_path):
    study = tmp_path / "range.yaml"
    study.write_text("name: fp\nmodel: classical\n"
                     "nonlinearity: {type: freeplay, dof: theta, delta: 0.01}\n"
                     f"continuations:\n  - {continuation}\n")
    result = CliRunner().invoke(cli, ["validate", str(study)])
    assert result.exit_code == 1
    assert result.output.splitlines() == [f"range.yaml:5: continuations[0].range: {reason}"]
