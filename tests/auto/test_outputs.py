"""A study's outputs (HDF5 file + plots) as one unit, on the real AUTO and the real CLI
(issue 13, item 2), and the messages of ``whirl run`` and ``whirl sweep`` (item 7)."""

from __future__ import annotations

import os
import signal

import h5py
import pytest
from click.testing import CliRunner

from whirl_cli import publish
from whirl_cli.cli import cli
from whirl_cli.errors import OutputError
from whirl_cli.output import atomic, store
from whirl_cli.sweep.plan import PLOT, SKIP, plan

from ..conftest import STUDIES

AIRSPEED = STUDIES / "linear_datum_airspeed.yaml"  # plots: bifurcation, linear


def names(directory) -> list[str]:
    return sorted(p.name for p in directory.iterdir())


def run(*args: str):
    return CliRunner().invoke(cli, ["run", *map(str, args)])


@pytest.fixture(scope="module")
def airspeed(tmp_path_factory):
    """A finished run of the airspeed study: (its directory, the result)."""
    directory = tmp_path_factory.mktemp("airspeed")
    done = run(AIRSPEED, "-o", directory / "r.h5")
    assert done.exit_code == 0, done.output
    return directory, store.read(directory / "r.h5")


def test_the_hdf5_file_records_its_plots(airspeed):
    directory, result = airspeed
    assert names(directory) == ["r.h5", "r_airspeed_bifurcation.png", "r_linear_V.png"]
    assert publish.recorded_plots(directory / "r.h5") == ("r_airspeed_bifurcation.png",
                                                          "r_linear_V.png")


def test_without_overwrite_an_existing_plot_is_not_replaced(tmp_path):
    """Before: the plots of a run were overwritten even without --overwrite."""
    plot = tmp_path / "r_linear_V.png"
    plot.write_bytes(b"someone's figure")
    refused = run(AIRSPEED, "-o", tmp_path / "r.h5")
    assert refused.exit_code == 1
    assert f"{plot}: a file that is not PNG, not a PNG image; whirl never replaces it" \
        in refused.output  # not even with --overwrite
    assert plot.read_bytes() == b"someone's figure"
    assert names(tmp_path) == ["r_linear_V.png"]  # nothing else was written


def test_overwrite_removes_the_plots_of_the_old_result(tmp_path):
    """Before: --overwrite left the old result's PNGs beside the new one."""
    assert run(AIRSPEED, "-o", tmp_path / "r.h5").exit_code == 0
    fewer = tmp_path / "fewer.yaml"
    fewer.write_text(AIRSPEED.read_text().replace("plots: [bifurcation, linear]",
                                                  "plots: [linear]"))
    again = run(fewer, "-o", tmp_path / "r.h5", "--overwrite")
    assert again.exit_code == 0, again.output
    assert names(tmp_path) == ["fewer.yaml", "r.h5", "r_linear_V.png"]
    assert publish.recorded_plots(tmp_path / "r.h5") == ("r_linear_V.png",)


def test_an_interrupt_while_publishing_is_held_until_the_set_is_complete(
        airspeed, tmp_path, monkeypatch):
    """SIGINT arriving between the first plot and the HDF5 file: every output appears, then
    the interrupt is raised (whirl exits 130 with a complete set, not half of one)."""
    _, result = airspeed
    real = atomic.publish
    sent = []

    def publish_and_interrupt(*args, **kwargs):
        if not sent:
            sent.append(os.kill(os.getpid(), signal.SIGINT))
        return real(*args, **kwargs)

    monkeypatch.setattr(atomic, "publish", publish_and_interrupt)
    with pytest.raises(KeyboardInterrupt):
        publish.publish_study(result, tmp_path / "r.h5", ("bifurcation", "linear"))
    assert sent and names(tmp_path) == ["r.h5", "r_airspeed_bifurcation.png", "r_linear_V.png"]
    assert store.read(tmp_path / "r.h5").study_name == result.study_name


def test_a_file_appearing_meanwhile_leaves_no_plots_behind(airspeed, tmp_path, monkeypatch):
    """Without overwrite, the HDF5 file is refused if it appeared after the check; the plots
    published just before it are taken back."""
    _, result = airspeed
    real = store.write

    other = tmp_path / "other.h5"
    real(result, other)
    another_run = other.read_bytes()
    other.unlink()

    def appear_first(result, path, overwrite=False):
        path.write_bytes(another_run)
        return real(result, path, overwrite)

    monkeypatch.setattr(store, "write", appear_first)
    with pytest.raises(OutputError, match="output exists"):
        publish.publish_study(result, tmp_path / "r.h5", ("bifurcation", "linear"))
    assert names(tmp_path) == ["r.h5"] and (tmp_path / "r.h5").read_bytes() == another_run


@pytest.mark.parametrize("where", ["render_tasks", "_rendered"])  # planning, one figure
def test_a_drawing_error_keeps_the_result_and_is_a_problem(tmp_path, monkeypatch, where):
    from whirl_cli.plots import files

    def broken(*args, **kwargs):
        raise ZeroDivisionError("a bug in a plot")

    monkeypatch.setattr(files, where, broken)  # a figure is drawn in a forked worker
    failed = run(AIRSPEED, "-o", tmp_path / "r.h5", "--jobs", "2")
    assert failed.exit_code == 1
    assert "plots: ZeroDivisionError: a bug in a plot" in failed.output
    assert names(tmp_path) == ["r.h5"]
    assert publish.recorded_plots(tmp_path / "r.h5") == ()


def test_a_drawing_worker_that_dies_keeps_the_result_and_is_a_problem(tmp_path, monkeypatch):
    from whirl_cli.plots import files

    monkeypatch.setattr(files, "_rendered", lambda *args: os._exit(1))  # in a forked worker
    failed = run(AIRSPEED, "-o", tmp_path / "r.h5", "--jobs", "2")
    assert failed.exit_code == 1
    assert "plots: RuntimeError: a worker process ended before its result" in failed.output, \
        failed.output
    assert names(tmp_path) == ["r.h5"]
    assert store.read(tmp_path / "r.h5").continuations  # the result, whole


def test_a_sweep_completes_missing_plots_without_rerunning(tmp_path):
    """Before: a sweep interrupted after the HDF5 file left the plots missing for good (the
    rerun called the study up to date)."""
    studies = tmp_path / "studies"
    studies.mkdir()
    (studies / "a.yaml").write_text(AIRSPEED.read_text())
    out = tmp_path / "out"
    first = CliRunner().invoke(cli, ["sweep", str(studies), "-o", str(out), "-j", "1"])
    assert first.exit_code == 0, first.output
    h5 = out / "linear-datum-airspeed.h5"
    stored = h5.read_bytes()
    missing = out / "linear-datum-airspeed_linear_V.png"
    missing.unlink()
    (item,) = plan([studies], out)
    assert (item.action, item.reason) == (PLOT, "up to date, plots missing")
    again = CliRunner().invoke(cli, ["sweep", str(studies), "-o", str(out), "-j", "1"])
    assert again.exit_code == 0, again.output
    assert "1 plots completed" in again.output
    assert missing.read_bytes()[:4] == b"\x89PNG" and h5.read_bytes() == stored
    assert plan([studies], out)[0].action == SKIP
    # a file written with --no-plots records none: the plots its result draws are missing
    assert run(AIRSPEED, "-o", h5, "--overwrite", "--no-plots").exit_code == 0
    with h5py.File(h5) as handle:
        assert list(handle.attrs["plots"]) == []
    assert plan([studies], out)[0].action == PLOT
    assert plan([studies], out, plots=False)[0].action == SKIP


# ------------------------------------------------------------------------------ messages
def test_an_empty_or_directory_output_path_is_refused(tmp_path):
    """Before: ``-o ""`` said ".: output exists"."""
    empty = run(AIRSPEED, "-o", "")
    assert empty.exit_code == 1
    assert empty.output.strip() == "-o/--output: expected the path of the HDF5 file, got ''"
    folder = run(AIRSPEED, "-o", tmp_path)
    assert folder.exit_code == 1 and f"{tmp_path}: is a directory" in folder.output


def test_an_invalid_study_in_a_sweep_is_named_once(tmp_path):
    studies = tmp_path / "studies"
    studies.mkdir()
    broken = studies / "broken.yaml"
    broken.write_text("name: broken\nmodel: classical\ncolour: red\n")
    swept = CliRunner().invoke(cli, ["sweep", str(studies), "-o", str(tmp_path / "out")])
    assert swept.exit_code == 1
    lines = [line for line in swept.output.splitlines() if "colour" in line]
    assert len(lines) == 2  # the study's line and the summary's
    for line in lines:
        assert line.count("broken.yaml") == 1 + line.startswith("[")  # name column + path
        assert f"{broken}:3: colour: unknown key" in line


def test_an_expected_mx_at_a_period_blow_up_gives_no_advice(tmp_path):
    """Combined case 5's main family ends with MX at its period blow-up, where that is
    expected: no advice on step sizes is printed, and the study succeeds. (Before, every MX
    run printed "try a smaller step.min", a key that does not exist.)"""
    done = run(STUDIES / "combined_case5.yaml", "-o", tmp_path / "r.h5", "--no-plots")
    assert done.exit_code == 0, done.output
    assert "no convergence (MX)" in done.output
    assert "step" not in done.output.replace("steps", "")
    mx = [r for r in store.read(tmp_path / "r.h5").runs if r.status == "mx"]
    assert mx and all("try a smaller auto.step_min or more auto.mesh_intervals" in r.message
                      for r in mx)  # the run records keep the advice, with the study's keys
