"""Ctrl-C at any moment of a real ``whirl run``: it stops with exit 130 (or, signalled after
its work was done, finishes it) and leaves no process and no half set of outputs.

A terminal's Ctrl-C sends SIGINT to the whole foreground process group (whirl and the
cross-check workers it forked); ``kill -INT`` reaches whirl alone. Both are sent, at moments
spread over a whole run and, because the cross-check pool is where interrupts used to hang
(issue 13), at moments just after whirl's first worker appears (the standby worker of the
cross-checks, forked as AUTO starts, importing scipy meanwhile).

"A whole run" begins once the interpreter can run a program's first line: before that, in
Python's own start-up and the ``.pth`` files of site-packages (the editable install's import
hook among them), a SIGINT meets Python's default handler, which raises KeyboardInterrupt inside
``site`` and reports it as a fatal error; no program can handle it there. That moment is
measured (:func:`interpreter_start`), with a margin.

A batch system's cancel sends SIGTERM to the whole process group: a ``whirl sweep`` (its
workers and their AUTO runs) gets one at moments spread over a whole sweep, and ``run``,
``sweep`` and ``figures`` at moments early in their start.
"""

from __future__ import annotations

import os
import random
import signal
import subprocess
import time
from pathlib import Path

import pytest

from .helpers import ROOT, STUDIES, WHIRL, auto_processes, environment

pytestmark = pytest.mark.auto

STUDY = STUDIES / "combined_case2.yaml"  # periodic families, cross-checks, three plot kinds
SPREAD, TARGETED = 10, 10
SEED = 20261201
#: A guard against a hang, not a measure: a whirl that has not ended this long after the
#: signal has hung (the whole study runs in seconds); what is asserted is how it ended.
HANG_SECONDS = 120.0


def session_processes(session: int) -> list[int]:
    """PIDs alive in a session (whirl and what it forked; AUTO runs have their own)."""
    alive = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                if os.getsid(int(entry.name)) == session and "zombie" not in \
                        (entry / "status").read_text():
                    alive.append(int(entry.name))
            except (OSError, ProcessLookupError):
                pass
    return alive


def interpreter_start(env: dict[str, str], repeats: int = 5) -> float:
    """Seconds from starting this environment's Python (``site`` and its ``.pth`` files
    included) to the end of an empty program: the longest of ``repeats`` starts."""
    seconds = []
    for _ in range(repeats):
        started = time.monotonic()
        subprocess.run([str(WHIRL.with_name("python")), "-c", "pass"], env=env, check=True)
        seconds.append(time.monotonic() - started)
    return max(seconds)


def outputs(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir()) if directory.exists() else []


def signalled(arguments: list[str], env: dict[str, str], delay: float, send,
              ready=lambda process: True) -> tuple[subprocess.Popen, str, str]:
    """Start whirl with ``arguments`` in a session of its own, wait until ``ready(process)``
    (or the process has ended), then ``delay`` s, call ``send(process)`` (the signal), and
    return (process, stdout, stderr) once it has ended: a test failure naming the processes
    left if it hangs for HANG_SECONDS; the session killed if anything in between fails."""
    process = subprocess.Popen([str(WHIRL), *arguments], env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        while not ready(process) and process.poll() is None:
            time.sleep(0.005)
        time.sleep(delay)
        send(process)
        try:
            stdout, stderr = process.communicate(timeout=HANG_SECONDS)
        except subprocess.TimeoutExpired:
            pytest.fail(f"whirl {arguments[0]} hung after the signal at {delay:.2f} s; "
                        f"alive: {session_processes(process.pid)}")
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    return process, stdout, stderr


def wait_gone(process: subprocess.Popen, cache: Path) -> None:
    """Until every process of ``process``'s session and every AUTO run of ``cache`` has
    ended (a guard: at most HANG_SECONDS)."""
    deadline = time.monotonic() + HANG_SECONDS
    while (session_processes(process.pid) or auto_processes(cache)) and \
            time.monotonic() < deadline:
        time.sleep(0.02)


def interrupt(cache: Path, scratch: Path, out: Path, delay: float, after_workers: bool,
              group: bool, reference: list[str]) -> str:
    """Run the study, send SIGINT ``delay`` s after the start (``after_workers``: after its
    first forked worker appears), and check how it ended; returns a word for it."""
    env = environment(cache, TMPDIR=str(scratch))
    process, _, stderr = signalled(
        ["run", str(STUDY), "-o", str(out / "r.h5")], env, delay,
        (lambda p: os.killpg(p.pid, signal.SIGINT)) if group
        else (lambda p: p.send_signal(signal.SIGINT)),
        ready=lambda p: not after_workers or len(session_processes(p.pid)) >= 2)
    assert "Traceback" not in stderr, stderr
    wait_gone(process, cache)
    assert session_processes(process.pid) == [], "a forked worker outlived whirl"
    assert auto_processes(cache) == [], "an AUTO process outlived whirl"
    left = sorted(scratch.rglob("*"))[:5]
    assert not left, f"the work directory was not removed: {left}"
    written = outputs(out)
    if process.returncode == 130:
        assert stderr.rstrip().endswith("interrupted"), stderr
        assert written in ([], reference), written  # nothing, or every output (see below)
        return "interrupted" if not written else "interrupted after publishing"
    # the signal came after the work was done: the run finished (0), or SIGINT reached it
    # in the interpreter's shutdown, after the outputs were complete (killed by the signal)
    assert process.returncode in (0, -signal.SIGINT), (process.returncode, stderr)
    assert written == reference, written
    return "finished"


def test_sigint_at_any_moment_stops_at_once_without_a_trace(tmp_path):
    cache = Path(os.environ["WHIRL_CACHE_DIR"])
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    env = environment(cache, TMPDIR=str(scratch))
    for _ in range(2):  # the second as the runs below: the study's program compiled already
        started = time.monotonic()
        done = subprocess.run([str(WHIRL), "run", str(STUDY), "-o",
                               str(tmp_path / "ref" / "r.h5"), "--overwrite"],
                              env=env, capture_output=True, text=True, timeout=300)
        duration = time.monotonic() - started
        assert done.returncode == 0, done.stderr
    reference = outputs(tmp_path / "ref")
    assert "r.h5" in reference and len(reference) > 3  # the HDF5 file and its plots

    first = 1.5 * interpreter_start(env)  # whirl's own code runs from here on (module doc)
    rng = random.Random(SEED)
    plan = [(first + (k + rng.random()) / SPREAD * (duration - first), False, k % 2 == 0)
            for k in range(SPREAD)]
    plan += [(rng.uniform(0.0, 0.3), True, k % 2 == 0) for k in range(TARGETED)]
    endings = []
    for k, (delay, after_workers, group) in enumerate(plan):
        endings.append(interrupt(cache, scratch, tmp_path / f"run{k}", delay, after_workers,
                                 group, reference))
    counts = {word: endings.count(word) for word in sorted(set(endings))}
    print(f"\n  {len(plan)} SIGINTs over a {duration:.1f} s run of {STUDY.name} from "
          f"{first:.3f} s (half to the process group): {counts}")
    # sent while the first worker is young, long before the run's end, whatever the load
    assert endings[SPREAD:] == ["interrupted"] * TARGETED, endings
    assert "interrupted" in endings[:SPREAD]  # the spread reached the run mid-way


# ------------------------------------------------------------------ sweep, process-group SIGTERM
SWEEP_STUDY = STUDIES / "linear_case2.yaml"  # three short AUTO runs
SWEEP_COPIES, SWEEP_SIGNALS = 3, 32


def sweep_studies(directory: Path) -> Path:
    """Copies of a short study under other names: a sweep of ``SWEEP_COPIES`` studies."""
    directory.mkdir()
    text = SWEEP_STUDY.read_text()
    old = next(line for line in text.splitlines() if line.startswith("name:"))
    for k in range(SWEEP_COPIES):
        (directory / f"copy{k}.yaml").write_text(text.replace(old, f"name: copy-{k}"))
    return directory


def terminate_sweep(cache: Path, scratch: Path, studies: Path, out: Path, delay: float) -> str:
    """A ``whirl sweep -j 2`` (with plots) sent SIGTERM as a process group ``delay`` s after
    its start, as a batch system's cancel does; checks how it ended, returns a word for it."""
    env = environment(cache, TMPDIR=str(scratch))
    process, _, stderr = signalled(["sweep", str(studies), "-o", str(out), "-j", "2"], env,
                                   delay, lambda p: os.killpg(p.pid, signal.SIGTERM))
    assert "Traceback" not in stderr and "internal error" not in stderr, (delay, stderr)
    wait_gone(process, cache)
    assert session_processes(process.pid) == [], "a worker outlived the sweep"
    assert auto_processes(cache) == [], "an AUTO process outlived the sweep"
    left = sorted(p.name for p in scratch.iterdir())
    assert not left, f"SIGTERM at {delay:.2f} s left work directories: {left}"
    names = outputs(out)
    assert not [n for n in names if n.startswith(".") or "tmp" in n], names
    for name in names:  # a result file and its plots, or nothing of a study
        study = name.split("_")[0].removesuffix(".h5")
        assert f"{study}.h5" in names, f"{name} without its result file ({names})"
    if process.returncode == 143:
        assert stderr.rstrip().endswith("interrupted"), (delay, stderr)
        return "interrupted"
    # finished (0), or the signal's default action once the command is over (cli.main):
    # whirl's handler is in place from the first line of entry.main on
    assert process.returncode in (0, -signal.SIGTERM), (delay, process.returncode, stderr)
    assert len([n for n in names if n.endswith(".h5")]) == SWEEP_COPIES, (delay, names)
    return "finished"


def test_a_process_group_sigterm_at_any_moment_of_a_sweep_leaves_nothing_behind(tmp_path):
    cache = Path(os.environ["WHIRL_CACHE_DIR"])
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    studies = sweep_studies(tmp_path / "studies")
    env = environment(cache, TMPDIR=str(scratch))
    started = time.monotonic()  # compiles the study's AUTO program once, for every run below
    done = subprocess.run([str(WHIRL), "sweep", str(studies), "-o", str(tmp_path / "ref"),
                           "-j", "2"], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    started = time.monotonic()
    subprocess.run([str(WHIRL), "sweep", str(studies), "-o", str(tmp_path / "ref2"), "-j", "2"],
                   env=env, capture_output=True, text=True, timeout=120, check=True)
    duration = time.monotonic() - started
    first = 1.5 * interpreter_start(env)  # whirl's own code runs from here on (module doc)
    rng = random.Random(SEED)
    delays = [first + (k + rng.random()) / SWEEP_SIGNALS * (duration - first)
              for k in range(SWEEP_SIGNALS)]
    endings = [terminate_sweep(cache, scratch, studies, tmp_path / f"out{k}", delay)
               for k, delay in enumerate(delays)]
    counts = {word: endings.count(word) for word in sorted(set(endings))}
    print(f"\n  {len(delays)} process-group SIGTERMs over a {duration:.1f} s sweep: {counts}")
    assert "interrupted" in endings  # the spread reached the sweep mid-way


SHEET = ROOT / "sheets" / "thesis_ch3" / "fig3_13.yaml"
EARLY_SIGNALS, EARLY_SECONDS = 8, 0.5


@pytest.mark.parametrize("command", ["run", "sweep", "figures"])
def test_a_sigterm_early_in_a_command_ends_it_as_an_interrupt(tmp_path, command):
    """SIGTERM while the command line is imported and the command sets out (before any AUTO
    run): whirl's handler, not the signal's default action, ends it: exit 143, "interrupted",
    no traceback, nothing left in TMPDIR."""
    cache = Path(os.environ["WHIRL_CACHE_DIR"])
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    env = environment(cache, TMPDIR=str(scratch))
    first = 1.5 * interpreter_start(env)  # whirl's own code runs from here on (module doc)
    arguments = {"run": ["run", str(SWEEP_STUDY), "-o", str(tmp_path / "out" / "r.h5")],
                 "sweep": ["sweep", str(SWEEP_STUDY), "-o", str(tmp_path / "out")],
                 "figures": ["figures", str(SHEET), "-o", str(tmp_path / "out"),
                             "--results", str(tmp_path / "results")]}[command]
    for k in range(EARLY_SIGNALS):
        delay = first + k / EARLY_SIGNALS * EARLY_SECONDS
        process, stdout, stderr = signalled(arguments, env, delay,
                                            lambda p: os.killpg(p.pid, signal.SIGTERM))
        assert process.returncode == 143, (command, delay, process.returncode, stderr)
        assert stderr.rstrip().endswith("interrupted") and "Traceback" not in stdout + stderr
        assert list(scratch.iterdir()) == [], (command, delay)
        assert not list(tmp_path.glob("out/*.h5")), (command, delay)
