"""The command line through click's CliRunner, on the real AUTO."""

from __future__ import annotations

import h5py
import numpy as np
from click.testing import CliRunner

from whirl_cli.auto import runner
from whirl_cli.cli import cli
from whirl_cli.output import store

from ..conftest import STUDIES


def test_run_writes_hdf5_and_plot_then_refuses_to_overwrite(tmp_path):
    output = tmp_path / "out" / "linear_case2.h5"
    runner = CliRunner()
    result = runner.invoke(cli, ["run", str(STUDIES / "linear_case2.yaml"), "-o", str(output)])
    assert result.exit_code == 0, result.output
    assert output.exists()
    assert (tmp_path / "out" / "linear_case2_k1_bifurcation.png").read_bytes()[:4] == b"\x89PNG"
    assert sorted(p.name for p in output.parent.iterdir()) == [
        "linear_case2.h5", "linear_case2_k1_bifurcation.png"]
    with h5py.File(output) as handle:
        assert handle.attrs["whirl_schema"] == store.SCHEMA
        assert handle.attrs["study_yaml"] == (STUDIES / "linear_case2.yaml").read_text()
        branch = handle["continuations/k1/branches/main_down"]
        assert branch["parameters"].attrs["names"].tolist() == ["K_theta"]
        assert branch["eigenvalues"].attrs["units"] == "1/s"
        hopf = branch["parameters"][:, 0][branch["point_type"][()] == 3]
        np.testing.assert_allclose(sorted(hopf), [0.0807, 0.2888], atol=1e-4)
        assert set(handle["runs"]) == {"k1.main_down", "k1.secondary_1a", "k1.secondary_1b"}
    before = output.read_bytes()
    again = runner.invoke(cli, ["run", str(STUDIES / "linear_case2.yaml"), "-o", str(output)])
    assert again.exit_code == 1
    assert "output exists; pass --overwrite" in again.output
    assert output.read_bytes() == before


def test_store_round_trip(tmp_path):
    output = tmp_path / "r.h5"
    runner = CliRunner()
    ran = runner.invoke(cli, ["run", str(STUDIES / "linear_datum_airspeed.yaml"), "-o",
                              str(output), "--no-plots"])
    assert ran.exit_code == 0, ran.output
    # whirl run ends with the table whirl summary prints from the file, on stdout (a result:
    # `> log` keeps it), its progress on stderr
    table = runner.invoke(cli, ["summary", str(output)]).stdout
    assert table.startswith("airspeed (one-parameter): 1 special point\n")
    assert ran.stdout.endswith(table) and table not in ran.stderr
    assert " points " in ran.stderr and " points " not in ran.stdout  # a line per AUTO run
    first = store.read(output)
    copy = store.write(first, tmp_path / "copy.h5")
    second = store.read(copy)
    assert first.study_name == second.study_name == "linear-datum-airspeed"
    for a, b in zip(first.continuations[0].branches, second.continuations[0].branches,
                    strict=True):
        for field in ("parameters", "state_max", "stable", "point_type", "eigenvalues"):
            np.testing.assert_array_equal(getattr(a, field), getattr(b, field))
    (sweep,) = second.linear_sweeps
    assert sweep.parameter == "V" and sweep.eigenvalues.shape == (201, 4)
    assert set(sweep.whirl.ravel()) == {"FW", "BW"}
    plotted = runner.invoke(cli, ["plot", str(copy), "-o", str(tmp_path / "plots")])
    assert plotted.exit_code == 0, plotted.output
    assert sorted(p.name for p in (tmp_path / "plots").iterdir()) == [  # every kind it has
        "copy_airspeed_bifurcation.png", "copy_airspeed_projections.png",
        "copy_damping_multiples.png", "copy_linear_V.png", "copy_root_locus_V.png"]


def test_run_reports_paths_as_written(tmp_path):
    """Brackets in a path are text, not console markup ("[b]" once vanished as "bold")."""
    folder = tmp_path / "[b] draft"
    folder.mkdir()
    study = folder / "airspeed.yaml"
    study.write_text((STUDIES / "linear_datum_airspeed.yaml").read_text())
    output = folder / "[v2].h5"
    ran = CliRunner().invoke(cli, ["run", str(study), "-o", str(output), "--no-plots"])
    assert ran.exit_code == 0, ran.output
    assert ran.stderr.splitlines()[0].endswith(f": {study} -> {output}")
    assert f"wrote {output}" in ran.stdout.splitlines()


def test_validate_models_and_doctor():
    runner = CliRunner()
    ok = runner.invoke(cli, ["validate", str(STUDIES / "combined_case3.yaml")])
    assert ok.exit_code == 0 and "ok (model classical_poly," in ok.output
    listing = runner.invoke(cli, ["models"])
    assert listing.exit_code == 0
    assert "K_theta" in listing.output and "N m/rad" in listing.output
    doctor = runner.invoke(cli, ["doctor"])
    assert doctor.exit_code == 0, doctor.output
    assert "everything needed is installed" in doctor.output


def test_validate_reports_bad_study_word_for_word(tmp_path):
    bad = tmp_path / "case2.yaml"
    bad.write_text("name: case2\nmodel: classical\nnonlinearity:\n  type: polynomial\n"
                   "  K2: ten\n")
    result = CliRunner().invoke(cli, ["validate", str(bad)])
    assert result.exit_code == 1
    assert result.output == "case2.yaml:5: nonlinearity.K2: expected a number, got 'ten'\n"
    run = CliRunner().invoke(cli, ["run", str(bad), "-o", str(tmp_path / "x.h5")])
    assert run.exit_code == 1 and not (tmp_path / "x.h5").exists()


def test_a_run_stuck_until_its_timeout_says_so_meanwhile(tmp_path, monkeypatch):
    """Newton cannot converge to 1e-30: AUTO spins until the 2 s timeout. Meanwhile a line
    on stderr says which run is still running (the first after SLOW_NOTICE, here 0.5 s),
    before the line of its end."""
    monkeypatch.setattr(runner, "SLOW_NOTICE", 0.5)
    study = tmp_path / "stuck.yaml"
    study.write_text((STUDIES / "linear_case2.yaml").read_text()
                     + "auto: {tolerance: 1.0e-30, newton_max_iterations: 1, timeout: 2}\n")
    ran = CliRunner().invoke(cli, ["run", str(study), "-o", str(tmp_path / "r.h5"),
                                   "--no-plots", "-j", "1"])
    assert ran.exit_code == 1, ran.output
    lines = ran.stderr.splitlines()
    notices = [k for k, line in enumerate(lines) if "still running after 0.5 s" in line]
    assert notices and "still running after 1 s" in lines[notices[0] + 1], lines
    name = lines[notices[0]].split()[0]
    ended = next(k for k, line in enumerate(lines) if line.split()[:2] == [name, "TIMEOUT"])
    assert ended > notices[0] + 1
    assert "still running" not in ran.stdout


def test_slow_notices_double_up_to_the_timeout():
    assert runner.slow_notices(60) == [10, 20, 40]
    assert runner.slow_notices(10) == []
