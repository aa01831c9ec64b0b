"""``whirl sweep``: planning (no AUTO), parallel runs on the real AUTO, resuming, failures,
Ctrl-C, and the same results through a Dask cluster."""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import pytest
from click.testing import CliRunner

from whirl_cli import __version__
from whirl_cli.auto.toolchain import auto_version
from whirl_cli.cli import cli
from whirl_cli.errors import WhirlError
from whirl_cli.output import atomic, store
from whirl_cli.output.compare import compare_files
from whirl_cli.output.provenance import code_sha256
from whirl_cli.sweep.executors import dask_pool
from whirl_cli.sweep.plan import INVALID, RUN, SKIP, find_studies, plan

from ..conftest import ROOT, STUDIES
from .helpers import SMALL, copy_studies


def renamed(path: Path, name: str, **replace: str) -> Path:
    """A copy of the study at ``path`` under another study name (and other text changes)."""
    text = path.read_text()
    old = next(line for line in text.splitlines() if line.startswith("name:"))
    text = text.replace(old, f"name: {name}")
    for before, after in replace.items():
        text = text.replace(before, after)
    target = path.with_name(f"{name}.yaml")
    target.write_text(text)
    return target


def fake_output(path: Path, sha: str, version: str = __version__, code: str | None = None,
                auto: str | None = None) -> None:
    """A result file that has only the root attributes a sweep's plan reads (by default the
    ones of an output of this very code and AUTO engine)."""
    with h5py.File(path, "w") as handle:
        handle.attrs.update(whirl_schema=1, study_sha256=sha, whirl_version=version,
                            whirl_code_sha256=code_sha256() if code is None else code,
                            auto_version=auto_version() if auto is None else auto)


# ------------------------------------------------------------------------------ plan (no AUTO)
def test_plan_decides_run_skip_and_invalid(tmp_path):
    studies = tmp_path / "studies"
    first, second = copy_studies(studies / "nested")
    (studies / "broken.yaml").write_text("name: broken\nmodel: classical\ncolour: red\n")
    renamed(first, "linear-datum-airspeed")  # a second file claiming the same study name
    out = tmp_path / "results"
    out.mkdir()
    items = {item.source.name: item for item in plan([studies], out)}
    assert sorted(items) == ["broken.yaml", "linear-datum-airspeed.yaml", "linear_case2.yaml",
                             "linear_datum_airspeed.yaml"]
    assert items["broken.yaml"].action == INVALID
    assert "broken.yaml:3: colour: unknown key" in items["broken.yaml"].reason
    duplicate = [i for i in items.values() if "also used by" in i.reason]
    assert len(duplicate) == 1 and duplicate[0].action == INVALID
    assert items["linear_case2.yaml"].action == RUN
    assert items["linear_case2.yaml"].reason == "new"
    assert items["linear_case2.yaml"].output == out / "linear-case2.h5"

    study = items["linear_case2.yaml"].study
    fake_output(out / "linear-case2.h5", study.sha256)
    assert {i.source.name: (i.action, i.reason) for i in plan([first], out, plots=False)} == {
        "linear_case2.yaml": (SKIP, "up to date")}
    # with plots, the fake file's result cannot be read to find the plots it should have
    assert plan([first], out)[0].reason == "unreadable output (OutputError)"
    fake_output(out / "linear-case2.h5", study.sha256, code="0" * 64)
    assert plan([first], out, plots=False)[0].reason == "whirl's code changed"
    assert plan([first], out, force=True)[0].action == RUN
    fake_output(out / "linear-case2.h5", study.sha256, auto="0.9.1")
    assert plan([first], out, plots=False)[0].reason == f"AUTO engine 0.9.1 -> {auto_version()}"
    fake_output(out / "linear-case2.h5", "0" * 64)
    assert plan([first], out)[0].reason == "study changed"
    fake_output(out / "linear-case2.h5", study.sha256, version="0.0.1")
    assert plan([first], out)[0].reason == f"whirl 0.0.1 -> {__version__}"
    (out / "linear-case2.h5").write_text("not HDF5")
    assert plan([first], out)[0].reason.startswith("unreadable output")
    assert second.name == "linear_datum_airspeed.yaml"


def test_plan_reruns_an_up_to_date_output_that_is_not_whole(tmp_path):
    """An output whose continuations were deleted is not an up-to-date result read as
    empty: the study runs again."""
    studies = tmp_path / "studies"
    first, _ = copy_studies(studies)
    out = tmp_path / "results"
    out.mkdir()
    study = plan([first], out)[0].study
    fake_output(out / "linear-case2.h5", study.sha256)
    with h5py.File(out / "linear-case2.h5", "r+") as handle:
        handle.create_group("runs").create_group("k1.main_down")
    assert [(i.action, i.reason) for i in plan([first], out, plots=False)] == [
        (RUN, "unreadable output (Damaged)")]


def test_find_studies_errors_and_order(tmp_path):
    with pytest.raises(WhirlError, match="no such file or directory"):
        find_studies([tmp_path / "missing"])
    (tmp_path / "empty").mkdir()
    with pytest.raises(WhirlError, match="no study files"):
        find_studies([tmp_path / "empty"])
    paths = copy_studies(tmp_path / "s")
    assert find_studies([tmp_path / "s", paths[0]]) == sorted(paths)  # each file once


def test_missing_dask_says_how_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "dask.distributed", None)
    with pytest.raises(WhirlError, match=r"pip install 'whirl\[dask\]'"):
        with dask_pool("tcp://127.0.0.1:1"):
            pass


# ------------------------------------------------------------------------------ real AUTO
def test_sweep_runs_in_parallel_resumes_and_reports_failures(tmp_path):
    studies = tmp_path / "studies"
    copy_studies(studies)
    (studies / "broken.yaml").write_text("name: broken\nmodel: classical\ncolour: red\n")
    out = tmp_path / "results"
    runner = CliRunner()
    first = runner.invoke(cli, ["sweep", str(studies), "-o", str(out), "-j", "2"])
    assert first.exit_code == 1, first.output  # the broken study; the others still ran
    assert "broken.yaml:3: colour: unknown key" in first.output
    # the summary is the result (stdout: `> log` keeps it), a line per study progress
    assert first.stdout.startswith("sweep: 2 ok, 0 up to date, 1 invalid of 3 studies")
    assert "broken.yaml:3: colour: unknown key" in first.stdout
    assert "ok       linear-case2" in first.stderr and "ok       linear" not in first.stdout
    assert sorted(p.name for p in out.iterdir()) == [
        "linear-case2.h5", "linear-case2_k1_bifurcation.png", "linear-datum-airspeed.h5",
        "linear-datum-airspeed_airspeed_bifurcation.png", "linear-datum-airspeed_linear_V.png"]

    # the same physics as `whirl run` of the same study
    single = tmp_path / "single.h5"
    assert runner.invoke(cli, ["run", str(STUDIES / "linear_case2.yaml"), "-o", str(single),
                               "--no-plots"]).exit_code == 0
    assert compare_files(single, out / "linear-case2.h5") == []

    (studies / "broken.yaml").unlink()
    stamps = {p: p.stat().st_mtime_ns for p in out.glob("*.h5")}
    again = runner.invoke(cli, ["sweep", str(studies), "-o", str(out)])
    assert again.exit_code == 0, again.output
    assert again.output.count("up to date") == 3  # two lines and the summary
    assert {p: p.stat().st_mtime_ns for p in out.glob("*.h5")} == stamps

    forced = runner.invoke(cli, ["sweep", str(studies / "linear_case2.yaml"), "-o", str(out),
                                 "--force", "--no-plots"])
    assert forced.exit_code == 0, forced.output
    assert (out / "linear-case2.h5").stat().st_mtime_ns != stamps[out / "linear-case2.h5"]


def test_sweep_exits_1_on_a_failed_branch_and_keeps_its_result(tmp_path):
    source = copy_studies(tmp_path / "studies", ("linear_case2",))[0]
    # Newton cannot converge to 1e-30: AUTO spins until the 2 s timeout, keeping one point
    source.write_text(source.read_text()
                      + "auto: {tolerance: 1.0e-30, newton_max_iterations: 1, timeout: 2}\n")
    out = tmp_path / "results"
    result = CliRunner().invoke(cli, ["sweep", str(source), "-o", str(out), "--no-plots"])
    assert result.exit_code == 1, result.output
    assert "1 of 1 studies failed" in result.output
    stored = store.read(out / "linear-case2.h5")
    assert {b.status for c in stored.continuations for b in c.branches} - {"ok"}
    # resuming reports the stored failure again instead of hiding it
    again = CliRunner().invoke(cli, ["sweep", str(source), "-o", str(out), "--no-plots"])
    assert again.exit_code == 1 and "up to date" in again.output


def test_a_full_disk_leaves_no_plot_without_its_result_file(tmp_path, monkeypatch):
    """The disk fills up at the HDF5 file, after the plots are published (ENOSPC on the write
    of its bytes): the study is an error with the reason, and none of its new files stays,
    in a fresh directory and beside the old result a --force rerun was to replace (whose
    plots the next sweep completes)."""
    source = copy_studies(tmp_path / "studies", ("linear_case2",))[0]
    out = tmp_path / "results"
    write_all = atomic._write_all

    def full(fd: int, data: bytes) -> None:
        if data.startswith(b"\x89HDF"):  # the result file, not a PNG
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        write_all(fd, data)

    runner = CliRunner()
    with monkeypatch.context() as patched:
        patched.setattr(atomic, "_write_all", full)
        failed = runner.invoke(cli, ["sweep", str(source), "-o", str(out), "-j", "1"])
    assert failed.exit_code == 1, failed.output
    assert "No space left on device" in failed.output
    assert sorted(p.name for p in out.iterdir()) == []

    assert runner.invoke(cli, ["sweep", str(source), "-o", str(out)]).exit_code == 0
    old = (out / "linear-case2.h5").read_bytes()
    with monkeypatch.context() as patched:
        patched.setattr(atomic, "_write_all", full)
        failed = runner.invoke(cli, ["sweep", str(source), "-o", str(out), "--force"])
    assert failed.exit_code == 1, failed.output
    assert sorted(p.name for p in out.iterdir()) == ["linear-case2.h5"]
    assert (out / "linear-case2.h5").read_bytes() == old
    completed = runner.invoke(cli, ["sweep", str(source), "-o", str(out)])
    assert completed.exit_code == 0 and "plots completed" in completed.output, completed.output
    assert (out / "linear-case2_k1_bifurcation.png").is_file()


def start_interruptible_sweep(tmp_path: Path, jobs: int = 1):
    """A ``whirl sweep`` of six small studies in its own session, and (out, scratch) dirs,
    returned once the first output exists (or the sweep has ended)."""
    source = copy_studies(tmp_path / "studies", ("linear_case2",))[0]
    for k in range(6):
        renamed(source, f"copy-{k}")
    source.unlink()
    out, scratch = tmp_path / "results", tmp_path / "tmp"
    scratch.mkdir()
    env = dict(os.environ, TMPDIR=str(scratch))
    process = subprocess.Popen(
        [sys.executable, "-m", "whirl_cli", "sweep", str(tmp_path / "studies"), "-o", str(out),
         "-j", str(jobs), "--no-plots"], cwd=ROOT, env=env, stderr=subprocess.PIPE, text=True,
        start_new_session=True)
    while not list(out.glob("*.h5")) and process.poll() is None:
        time.sleep(0.1)
    return process, out, scratch


def session_processes(session: int) -> list[int]:
    """PIDs still alive in a session (the sweep, its workers and their AUTO runs)."""
    alive = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                if os.getsid(int(entry.name)) == session:
                    alive.append(int(entry.name))
            except (ProcessLookupError, PermissionError):
                pass
    return alive


def assert_finished_outputs_kept(out: Path, scratch: Path) -> None:
    finished = sorted(out.glob("*.h5"))
    assert 1 <= len(finished) < 6
    assert [p.name for p in out.iterdir() if p.suffix != ".h5"] == []  # no temporary files
    for path in finished:
        assert store.read(path).continuations


@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_interrupt_keeps_finished_outputs_and_leaves_no_process(tmp_path, signum, code):
    process, out, scratch = start_interruptible_sweep(tmp_path, jobs=2)
    process.send_signal(signum)  # the parent only (Ctrl-C on a terminal reaches the workers too)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == code, stderr
    assert "interrupted" in stderr
    assert_finished_outputs_kept(out, scratch)
    assert list(scratch.iterdir()) == []  # work directories removed
    deadline = time.monotonic() + 120  # a guard against a hang: ends once all are gone
    while session_processes(process.pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert session_processes(process.pid) == []


def test_sigkill_of_the_sweep_takes_its_workers_and_auto_runs_along(tmp_path):
    process, out, _ = start_interruptible_sweep(tmp_path, jobs=2)
    process.kill()
    process.communicate(timeout=30)
    deadline = time.monotonic() + 120  # a guard against a hang: ends once all are gone
    while session_processes(process.pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert session_processes(process.pid) == []  # no orphaned worker or AUTO process
    assert_finished_outputs_kept(out, out)


def test_dask_cluster_gives_the_same_results_as_the_local_pool(tmp_path):
    from dask import distributed  # in the dev extra: a missing dask is a failure, not a skip
    studies = tmp_path / "studies"
    copy_studies(studies)
    runner = CliRunner()
    local = runner.invoke(cli, ["sweep", str(studies), "-o", str(tmp_path / "local"), "-j", "2",
                                "--no-plots"])
    assert local.exit_code == 0, local.output
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        remote = runner.invoke(cli, ["sweep", str(studies), "-o", str(tmp_path / "dask"),
                                     "--dask", cluster.scheduler_address, "--no-plots"])
    assert remote.exit_code == 0, remote.output
    for name in ("linear-case2.h5", "linear-datum-airspeed.h5"):
        compared = runner.invoke(cli, ["compare", str(tmp_path / "local" / name),
                                       str(tmp_path / "dask" / name)])
        assert compared.exit_code == 0, compared.output


def test_each_outcome_says_how_many_studies_are_still_to_finish(tmp_path):
    """``run_sweep``'s ``on_outcome`` (what ``whirl figures`` draws by): after each study,
    how many are still running or waiting; up-to-date studies leave nothing to wait for."""
    from whirl_cli.sweep.run import run_sweep

    studies = tmp_path / "studies"
    copy_studies(studies)
    seen: list[tuple[str, int]] = []
    run_sweep([studies], tmp_path / "out", jobs=2, plots=False,
              on_outcome=lambda outcome, left: seen.append((outcome.status, left)))
    assert seen == [("ok", left) for left in range(len(SMALL) - 1, -1, -1)]
    seen.clear()
    run_sweep([studies], tmp_path / "out", jobs=2, plots=False,
              on_outcome=lambda outcome, left: seen.append((outcome.status, left)))
    assert seen == [("skipped", 0)] * len(SMALL)
