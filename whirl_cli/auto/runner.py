"""Running AUTO-07p: each job in its own directory, its outcome classified.

* Every run gets a fresh working directory, its constants written as ``fort.2`` (and as
  ``c.<name>`` for inspection), ``OMP_NUM_THREADS=1`` and a wall-clock timeout. The process is
  started from an argument list (never a shell string) with an explicit environment.
* AUTO exits 0 on most errors, so success is: exit status 0, none of AUTO's error texts on
  stdout, at least one solution point in ``b.<name>``, and no MX (no convergence) ending.
  Anything else becomes a :class:`RunOutcome` with a status and a message, never an exception.
* No AUTO process outlives whirl: each gets the parent-death signal SIGKILL (``setpriv
  --pdeathsig``, util-linux, when available), so even a SIGKILLed whirl leaves none running;
  inside :func:`interruptible` (what ``run_study`` uses) SIGINT and SIGTERM kill every running
  AUTO process group at once, refuse new runs and raise :class:`Interrupted`.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

from ..kinds import RunStatus
from ..runtime import Interrupted, catching
from .constants import START_FILE, constants_text

#: stdout texts meaning AUTO did not do what was asked, although it exits 0 -> message shown.
FATAL_PATTERNS = (
    (r"Restart label \S+ not found", "restart label not found"),
    (r"could not be found", "the restart solution file could not be found"),
    (r"Unknown AUTO constant \S+", "unknown AUTO constant"),
    (r"bad value on line \d+", "malformed constants file"),
    (r"Name '[^']*' not found", "unknown parameter name"),
    (r"Insufficient number of parameters", "too few continuation parameters (ICP)"),
    (r"Invalid parameter index", "invalid parameter index"),
    (r"Initialization Error", "initialisation error"),
    (r"On entry to \w+ parameter number\s+\d+ had an illegal value",
     "NaN or Inf in the equations (LAPACK rejected the Jacobian)"),
)
_LABEL_LINE = re.compile(r"^\s*-?\d+\s+-?\d+\s+([A-Z][A-Z0-9]{1,2})\s+(\d+)\s")

#: Running AUTO processes, and whether new runs are refused (after an interrupt).
_LIVE: set[subprocess.Popen] = set()
_LIVE_LOCK = threading.RLock()
_STOPPING = threading.Event()


def stop_all() -> None:
    """Refuse new AUTO runs and kill (SIGKILL, whole process group) every running one."""
    with _LIVE_LOCK:
        _STOPPING.set()
        for process in list(_LIVE):
            kill_group(process.pid)


def kill_group(pid: int) -> None:
    """SIGKILL the process group of the AUTO run ``pid``; one that has ended is no error."""
    try:
        os.killpg(pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):  # ended (and reaped) meanwhile
        pass


@contextmanager
def interruptible() -> Iterator[None]:
    """While inside (main thread only): SIGINT and SIGTERM kill the AUTO runs and raise
    :class:`Interrupted` (a KeyboardInterrupt) in the main thread (:func:`whirl_cli.runtime.
    catching`, so an interrupt is never lost), and no new AUTO run starts."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _STOPPING.clear()
    try:
        with catching(on_first=stop_all):
            yield
    finally:
        _STOPPING.clear()


@cache
def _pdeathsig_prefix() -> tuple[str, ...]:
    """``setpriv --pdeathsig KILL`` if it works here, else nothing."""
    setpriv, true = shutil.which("setpriv"), shutil.which("true")
    if not setpriv or not true:
        return ()
    prefix = (setpriv, "--pdeathsig", "KILL", "--")
    try:
        probe = subprocess.run([*prefix, true], capture_output=True, timeout=10, check=False)
    except (OSError, subprocess.TimeoutExpired):
        return ()
    return prefix if probe.returncode == 0 else ()


@dataclass(frozen=True)
class RunOutcome:
    """What one AUTO run did, and how it ended (``status``)."""

    name: str
    status: RunStatus
    message: str
    workdir: Path
    constants: str
    returncode: int | None
    wall_seconds: float
    n_points: int
    labels: tuple[tuple[str, int], ...] = field(default=())  # (type, label) from stdout

    @property
    def success(self) -> bool:
        return self.status == RunStatus.OK

    @property
    def has_output(self) -> bool:
        """True if AUTO wrote solution points that can be parsed (also after MX)."""
        return self.n_points > 0 and self.status in (RunStatus.OK, RunStatus.MX, RunStatus.TIMEOUT)

    def file(self, kind: str) -> Path:
        """Path of AUTO's ``b``, ``s`` or ``d`` output file of this run."""
        return self.workdir / f"{kind}.{self.name}"


def _auto_env() -> dict[str, str]:
    return {
        "PATH": os.environ.get("PATH", "/usr/bin:/bin"),
        "OMP_NUM_THREADS": "1",
        "OMP_WAIT_POLICY": "PASSIVE",
        "LC_ALL": "C",
    }


def _count_points(path: Path) -> int:
    if not path.exists():
        return 0
    with path.open(errors="replace") as handle:
        return sum(1 for line in handle if line.split()[:1] not in ([], ["0"]))


def _describe_signal(returncode: int) -> str:
    number = -returncode if returncode < 0 else returncode - 128
    try:
        return f"{signal.Signals(number).name} (exit {returncode})"
    except ValueError:
        return f"exit {returncode}"


def run(executable: Path, constants: dict, workdir: Path, name: str,
        restart: Path | None = None, timeout: float = 120.0,
        data: str | None = None, on_slow: Callable[[str, float], None] | None = None,
        start_state: str | None = None) -> RunOutcome:
    """Run AUTO once in the fresh directory ``workdir``.

    ``constants`` are complete (whirl never relies on AUTO defaults it did not choose); ``sv`` is
    set to ``name`` here. ``restart`` is the ``s.`` file to restart from; it is copied into
    ``workdir`` and named through the ``s`` constant. ``data``: the text of an AUTO data file
    to start from instead (rows ``t u1 .. uNDIM``, used with IRS=0), written into ``workdir``
    and named through the ``dat`` constant. ``start_state``: a line of the starting state U
    (AUTO's units) that the equations' STPNT reads (:data:`~.constants.START_FILE`) instead of
    U = 0. ``on_slow(name, seconds)`` is called when the run
    is still running after each of :func:`slow_notices` (a run stuck until its timeout is
    not silent meanwhile).
    """
    workdir.mkdir(parents=True, exist_ok=False)
    constants = dict(constants, sv=name)
    if restart is not None:
        restart_name = "restart"
        shutil.copyfile(restart, workdir / f"s.{restart_name}")
        constants["s"] = restart_name
    if data is not None:
        (workdir / "start.dat").write_text(data)
        constants["dat"] = "start"
    if start_state is not None:
        (workdir / START_FILE).write_text(start_state)
    text = constants_text(constants)
    (workdir / f"c.{name}").write_text(text)
    (workdir / "fort.2").write_text(text)

    start = time.perf_counter()
    returncode: int | None
    command = [*_pdeathsig_prefix(), str(executable)]
    with (workdir / "stdout.txt").open("wb") as out, (workdir / "stderr.txt").open("wb") as err:
        with _LIVE_LOCK:
            if _STOPPING.is_set():
                raise Interrupted()
            process = subprocess.Popen(command, cwd=workdir, env=_auto_env(),
                                       stdin=subprocess.DEVNULL, stdout=out, stderr=err,
                                       start_new_session=True)
            _LIVE.add(process)
        try:
            returncode = _wait(process, timeout, name, on_slow)
            timed_out = False
        except subprocess.TimeoutExpired:
            kill_group(process.pid)
            process.wait()
            returncode, timed_out = None, True
        except BaseException:  # KeyboardInterrupt: never leave AUTO running
            kill_group(process.pid)
            process.wait()
            raise
        finally:
            with _LIVE_LOCK:
                _LIVE.discard(process)
    if _STOPPING.is_set():  # killed by stop_all: no outcome to report
        raise Interrupted()
    wall = time.perf_counter() - start
    (workdir / "fort.2").unlink(missing_ok=True)

    stdout = (workdir / "stdout.txt").read_text(errors="replace")
    labels = tuple((m.group(1), int(m.group(2)))
                   for m in map(_LABEL_LINE.match, stdout.splitlines()) if m)
    n_points = _count_points(workdir / f"b.{name}")
    status, message = _classify(returncode, timed_out, stdout, n_points, labels, timeout)
    return RunOutcome(name, status, message, workdir, text, returncode, wall, n_points, labels)


def slow_notices(timeout: float) -> list[float]:
    """Seconds at which a run still running is reported: 10, 20, 40, ... before ``timeout``."""
    notices, seconds = [], SLOW_NOTICE
    while seconds < timeout:
        notices.append(seconds)
        seconds *= 2
    return notices


#: Seconds of a run before the first "still running" notice.
SLOW_NOTICE = 10.0


def _wait(process: subprocess.Popen, timeout: float, name: str,
          on_slow: Callable[[str, float], None] | None) -> int:
    """``process.wait(timeout)`` (TimeoutExpired past it), calling ``on_slow`` on the way."""
    start = time.monotonic()
    for notice in slow_notices(timeout) if on_slow is not None else ():
        try:
            return process.wait(timeout=max(0.0, notice - (time.monotonic() - start)))
        except subprocess.TimeoutExpired:
            on_slow(name, notice)
    return process.wait(timeout=max(0.0, timeout - (time.monotonic() - start)))


def _classify(returncode: int | None, timed_out: bool, stdout: str, n_points: int,
              labels: tuple[tuple[str, int], ...], timeout: float) -> tuple[RunStatus, str]:
    if timed_out:
        return RunStatus.TIMEOUT, (f"AUTO did not finish within {timeout:g} s ({n_points} "
                                   "points kept)")
    assert returncode is not None
    if returncode < 0 or returncode > 128:
        return RunStatus.CRASHED, f"AUTO crashed with {_describe_signal(returncode)}"
    for pattern, meaning in FATAL_PATTERNS:  # before the status: bifpy's AUTO exits 1 here
        found = re.search(pattern, stdout)
        if found:
            return RunStatus.ERROR, f"{meaning}: AUTO said '{found.group(0).strip()}'"
    if returncode != 0:
        return RunStatus.ERROR, f"AUTO exited with status {returncode}"
    if n_points == 0:
        return RunStatus.ERROR, "AUTO wrote no solution points"
    if any(kind == "MX" for kind, _ in labels):
        return RunStatus.MX, ("no convergence with the minimum step size (MX): the branch ends "
                              "early; try a smaller auto.step_min or more auto.mesh_intervals")
    return RunStatus.OK, "ok"

