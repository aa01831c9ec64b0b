"""Many studies at once: plan which to (re)run, run them in parallel, store in the parent.

``whirl sweep PATHS...`` is built from three pieces:

* :func:`plan` (pure, no AUTO): find the study files, validate them, name each output
  ``<out_dir>/<study name>.h5`` and decide per study: ``run`` (no output yet, the study or
  whirl changed, or ``force``), ``skip`` (the output holds the same ``study_sha256``,
  ``whirl_version`` and ``whirl_code_sha256``), ``plot`` (up to date, but plots it should
  have are missing: they are drawn from the stored result) or ``invalid`` (the YAML does
  not validate, or two files share a name).
* :func:`compute`, the task a worker process runs: :func:`whirl_cli.pipeline.run_study` with
  ``jobs=1`` in its own temporary directory; it returns the :class:`StudyResult` (frozen
  dataclasses, picklable) and writes nothing else.
* :func:`execute`: submits the planned studies to any ``concurrent.futures.Executor`` (a local
  process pool, or Dask's ``Client.get_executor()``) and, as each finishes, writes its HDF5
  file and plots as one unit (:func:`whirl_cli.output.study_files.publish_study`) **in the parent
  process only**.

Interrupting (Ctrl-C) cancels the studies not started yet, interrupts the running ones (their
AUTO processes are killed and their working directories removed) and keeps every output
already written; a study's outputs are never half a set (see :mod:`whirl_cli.output.study_files`).
"""

from __future__ import annotations

import multiprocessing
import os
import pickle
import shutil
import signal
import tempfile
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import Executor, Future, ProcessPoolExecutor, as_completed, wait
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import h5py

from . import __version__
from .auto.runner import interruptible
from .errors import StudyError, WhirlError
from .interrupts import quiet_worker
from .output.provenance import code_sha256
from .output.study_files import missing_plots, publish_plots, publish_study
from .results import StudyResult
from .study import Study, load_study
from .verdict import is_problem, verdict

RUN, SKIP, PLOT, INVALID = "run", "skip", "plot", "invalid"
DASK_HINT = "install with pip install 'whirl[dask]'"


# ------------------------------------------------------------------------------ planning
@dataclass(frozen=True)
class SweepItem:
    """One study file of a sweep and what to do with it.

    ``action``: "run" | "skip" | "plot" | "invalid"; ``reason`` says why (e.g. "new", "study
    changed", "up to date", "up to date, plots missing", or the validation errors).
    ``stored_problems``: problems recorded in an up-to-date output that is skipped (failed
    branches or cross-checks), so that a resumed sweep still reports them.
    """

    source: Path
    action: str
    reason: str
    study: Study | None = None
    output: Path | None = None
    stored_problems: tuple[str, ...] = ()

    @property
    def name(self) -> str:
        return self.study.name if self.study is not None else self.source.name


def find_studies(paths: Iterable[str | os.PathLike[str]]) -> list[Path]:
    """Study files named by ``paths``: files as given, directories searched recursively for
    ``*.yaml`` (sorted); each file once, in the order found."""
    found: list[Path] = []
    seen: set[Path] = set()
    for entry in map(Path, paths):
        if entry.is_dir():
            candidates = sorted(p for p in entry.rglob("*.yaml") if p.is_file())
            if not candidates:
                raise WhirlError(f"{entry}: no study files (*.yaml) in this directory")
        elif entry.exists():
            candidates = [entry]
        else:
            raise WhirlError(f"{entry}: no such file or directory")
        for path in candidates:
            key = path.resolve()
            if key not in seen:
                seen.add(key)
                found.append(path)
    return found


def plan(paths: Iterable[str | os.PathLike[str]], out_dir: str | os.PathLike[str],
         force: bool = False, plots: bool = True) -> list[SweepItem]:
    """What a sweep of ``paths`` into ``out_dir`` will do, study by study (no AUTO, no writes).

    A study is skipped when ``<out_dir>/<study name>.h5`` exists with the same
    ``study_sha256``, ``whirl_version`` and ``whirl_code_sha256`` root attributes, unless
    ``force``; if ``plots`` and some of its plots are missing, they are drawn ("plot").
    """
    out_dir = Path(out_dir)
    items: list[SweepItem] = []
    owners: dict[str, Path] = {}
    for path in find_studies(paths):
        try:
            study = load_study(path, label=str(path))
        except StudyError as error:
            items.append(SweepItem(path, INVALID, error.message))
            continue
        if study.name in owners:
            items.append(SweepItem(path, INVALID, f"{path}: study name {study.name!r} is also "
                                   f"used by {owners[study.name]} (outputs would collide)",
                                   study))
            continue
        owners[study.name] = path
        output = out_dir / f"{study.name}.h5"
        action, reason, problems = _decide(study, output, force)
        if action == SKIP and plots:
            try:
                if missing_plots(output, study.plots):
                    action, reason = PLOT, "up to date, plots missing"
            except (OSError, KeyError, ValueError, WhirlError) as error:
                action, reason = RUN, f"unreadable output ({type(error).__name__})"
        items.append(SweepItem(path, action, reason, study, output, problems))
    return items


def _decide(study: Study, output: Path, force: bool) -> tuple[str, str, tuple[str, ...]]:
    """(action, reason, stored problems) for one valid study and its output path."""
    if force:
        return RUN, "forced", ()
    if not output.exists():
        return RUN, "new", ()
    try:
        stored = stored_state(output)
    except (OSError, KeyError, ValueError) as error:
        return RUN, f"unreadable output ({type(error).__name__})", ()
    if stored.study_sha256 != study.sha256:
        return RUN, "study changed", ()
    if stored.whirl_version != __version__:
        return RUN, f"whirl {stored.whirl_version} -> {__version__}", ()
    if stored.code_sha256 != code_sha256():
        return RUN, "whirl's code changed", ()
    return SKIP, "up to date", stored.problems


@dataclass(frozen=True)
class StoredState:
    """What a sweep needs to know of an existing result file."""

    study_sha256: str
    whirl_version: str
    code_sha256: str  # "" in files written before whirl recorded it
    problems: tuple[str, ...]  # by the failure policy of :mod:`whirl_cli.verdict`


def stored_state(output: Path) -> StoredState:
    """The provenance and stored problems of an existing result file, read with h5py (root
    attributes, branch attributes and cross-check outcomes only, not the data)."""
    def text(value) -> str:
        return value.decode() if isinstance(value, bytes) else str(value)

    problems: list[str] = []
    with h5py.File(output, "r") as handle:
        attrs = handle.attrs
        for name, group in handle.get("continuations", {}).items():
            for branch, sub in group.get("branches", {}).items():
                if is_problem(text(sub.attrs.get("kind", "")),
                              text(sub.attrs.get("status", "ok"))):
                    problems.append(f"{branch} ({text(sub.attrs.get('run', ''))}): "
                                    f"{text(sub.attrs.get('message', ''))}")
            if "cross_checks" in group:
                failed = int((~group["cross_checks/passed"][()].astype(bool)).sum())
                if failed:
                    problems.append(f"{failed} cross-check(s) failed in {name}")
        return StoredState(text(attrs["study_sha256"]), text(attrs["whirl_version"]),
                           text(attrs.get("whirl_code_sha256", "")), tuple(problems))


# ------------------------------------------------------------------------------ the task
#: Set by the parent of a local pool when a sweep is interrupted: queued tasks then stop at once.
_CANCELLED = None


def _init_worker(cancelled) -> None:
    """Initializer of local worker processes: :func:`whirl_cli.interrupts.quiet_worker` (SIGINT
    ignored except inside :func:`whirl_cli.pipeline.run_study`, whose own handler kills the
    running AUTO processes and raises; SIGTERM default; death with the sweep process), and
    ``cancelled`` (an Event) makes tasks still queued return at once."""
    global _CANCELLED
    _CANCELLED = cancelled
    quiet_worker()


def compute(study: Study) -> StudyResult:
    """Run ``study`` (AUTO runs one at a time) in a fresh temporary directory, removed
    afterwards; the worker-side task of a sweep."""
    from .pipeline import run_study

    if _CANCELLED is not None and _CANCELLED.is_set():
        raise KeyboardInterrupt("sweep cancelled")
    workroot = Path(tempfile.mkdtemp(prefix=f"whirl-sweep-{study.name}-"))
    try:
        return run_study(study, workroot, jobs=1)
    except BaseException as error:
        _join_helper_threads(study.auto.timeout if study.auto else None)
        raise portable(error) from None
    finally:
        shutil.rmtree(workroot, ignore_errors=True)


def portable(error: BaseException) -> BaseException:
    """``error`` if it survives pickling (it travels back to the parent), else a plain
    KeyboardInterrupt or RuntimeError with its message. An exception that cannot be
    unpickled makes a process pool declare itself broken and kill every worker."""
    try:
        pickle.loads(pickle.dumps(error))
        return error
    except Exception:
        text = f"{type(error).__name__}: {error}"
        return KeyboardInterrupt(text) if isinstance(error, KeyboardInterrupt) \
            else RuntimeError(text)


def _join_helper_threads(timeout: float | None) -> None:
    """Wait for the threads a study left running (an interrupted AUTO run still writing into
    the work directory) before the directory is removed; at most ``timeout`` s each (default
    120, the AUTO run limit)."""
    for thread in threading.enumerate():
        if thread is not threading.current_thread() and not thread.daemon:
            thread.join(timeout or 120.0)


# ------------------------------------------------------------------------------ execution
@dataclass(frozen=True)
class Outcome:
    """What became of one study. ``status``: "ok" | "failed" (stored, with problems) |
    "skipped" | "invalid" | "error" (no result: the task raised).

    ``auto_seconds``: summed wall time of its AUTO runs (s); ``written``: files written.
    """

    item: SweepItem
    status: str
    problems: tuple[str, ...] = ()
    auto_seconds: float = 0.0
    runs: int = 0
    written: tuple[Path, ...] = ()

    @property
    def failed(self) -> bool:
        return self.status in ("failed", "invalid", "error") or bool(self.problems)


def execute(items: Sequence[SweepItem], executor: Executor, plots: bool = True,
            report: Callable[[Outcome], None] | None = None,
            on_submitted: Callable[[int], None] | None = None) -> list[Outcome]:
    """Run the ``run`` items on ``executor``; write each result and its plots as it arrives.

    Skipped and invalid items become outcomes at once. ``report`` is called with every
    outcome, in completion order; ``on_submitted`` with the number of studies submitted.
    A KeyboardInterrupt cancels the futures not started yet and propagates.
    """
    outcomes: list[Outcome] = []

    def done(outcome: Outcome) -> None:
        outcomes.append(outcome)
        if report is not None:
            report(outcome)

    for item in items:
        if item.action == SKIP:
            done(Outcome(item, "skipped", item.stored_problems))
        elif item.action == INVALID:
            done(Outcome(item, "invalid", (item.reason,)))
    queue = sorted((item for item in items if item.action == RUN), key=expected_cost,
                   reverse=True)  # longest first: less idle time at the end of a sweep
    futures: dict[Future, SweepItem] = {executor.submit(compute, item.study): item
                                        for item in queue}
    if on_submitted is not None:
        on_submitted(len(futures))
    try:
        for item in items:  # while the workers compute
            if item.action == PLOT:
                done(_complete_plots(item))
        for future in as_completed(futures):
            done(_store(futures[future], future, plots))
    except BaseException:
        _stop_running(executor, futures)
        raise
    return outcomes


def _stop_running(executor: Executor, futures: Iterable[Future], grace: float = 60.0) -> None:
    """After Ctrl-C: an executor that can ``interrupt`` (the local pool) makes every queued
    study return at once and the running ones kill their AUTO runs and remove their work
    directories; this waits up to ``grace`` s for that. Others (Dask) get their futures
    cancelled (running tasks there finish on their own)."""
    interrupt = getattr(executor, "interrupt", None)
    if interrupt is None:
        for future in futures:
            future.cancel()
        return
    interrupt()
    wait(list(futures), timeout=grace)


def expected_cost(item: SweepItem) -> int:
    """A rough relative cost of a study, to start the long ones first: periodic families and
    time-simulation cross-checks dominate."""
    study = item.study
    if study is None:
        return 0
    periodic = sum(bool(getattr(c, "periodic", False)) for c in study.continuations)
    return 1 + len(study.continuations) + 2 * periodic + 2 * periodic * bool(study.cross_check)


def _store(item: SweepItem, future: Future, plots: bool) -> Outcome:
    """Write a finished study's HDF5 file and plots; a task's exception becomes an outcome."""
    try:
        result: StudyResult = future.result()
    except WhirlError as error:
        return Outcome(item, "error", (error.message,))
    except Exception as error:  # a bug or a lost worker: report it, go on with the others
        return Outcome(item, "error", (f"{type(error).__name__}: {error}",))
    assert item.output is not None and item.study is not None
    auto_seconds = sum(r.wall_seconds for r in result.runs)
    try:
        published = publish_study(result, item.output, item.study.plots if plots else (),
                                  overwrite=True)
    except Exception as error:  # e.g. a result the store cannot represent: go on
        return Outcome(item, "error", (f"writing {item.output}: {type(error).__name__}: "
                                       f"{error}", *verdict(result).problems), auto_seconds,
                       len(result.runs))
    problems = verdict(result, published.plot_error).problems
    return Outcome(item, "failed" if problems else "ok", problems, auto_seconds,
                   len(result.runs), published.paths)


def _complete_plots(item: SweepItem) -> Outcome:
    """Draw the missing plots of an up-to-date study from its stored result."""
    assert item.output is not None and item.study is not None
    try:
        written = publish_plots(item.output, item.study.plots)
    except Exception as error:  # the result file stands; say what went wrong with plots
        return Outcome(item, "error", (f"plots: {type(error).__name__}: {error}",
                                       *item.stored_problems))
    return Outcome(item, "plotted", item.stored_problems, written=written)


# ------------------------------------------------------------------------------ executors
def prepare_workers(items: Sequence[SweepItem]) -> None:
    """Import what a worker needs and build the planned studies' models in this process, so
    that workers started by fork inherit them instead of each spending about a second on
    imports and sympy work (harmless with other start methods)."""
    import numpy as np

    from . import pipeline  # noqa: F401  (imported for the workers to inherit)
    from .analysis import simulate  # noqa: F401  (imported for the workers to inherit)

    for item in items:
        if item.action == RUN and item.study is not None:
            model = item.study.variant()
            params = model.parameter_vector(item.study.parameter_values())
            model.jacobian_numpy(np.zeros(model.n_states), params)
            model.rhs_numpy(np.zeros(model.n_states), params)


class LocalPool(ProcessPoolExecutor):
    """A process pool of ``jobs`` workers whose studies can be interrupted.

    Workers ignore SIGINT except inside ``run_study`` (see :func:`_init_worker`);
    ``interrupt`` sets the shared cancel flag (queued tasks return at once) and sends them
    SIGINT (a terminal's Ctrl-C reaches them directly, ``kill -INT`` on the parent does not).
    The pool's own cancel/terminate paths are not used after an interrupt: in Python 3.11
    they can leave a worker waiting forever."""

    def __init__(self, jobs: int) -> None:
        context = multiprocessing.get_context()
        self.cancelled = context.Event()
        super().__init__(max_workers=jobs, mp_context=context, initializer=_init_worker,
                         initargs=(self.cancelled,))
        self.jobs = jobs

    def workers(self) -> list:
        return list((getattr(self, "_processes", None) or {}).values())

    def start(self) -> None:
        """Start every worker now (before a progress display thread exists: fork is safe)."""
        for started in [self.submit(os.getpid) for _ in range(self.jobs)]:
            started.result()

    def close(self, timeout: float) -> None:
        """Shut down after an interrupt without risking a hang: workers not gone after
        ``timeout`` s (a worker killed inside the pool's queue code leaves the others
        waiting on its lock) are terminated; by then they run no study."""
        workers = self.workers()
        self.shutdown(wait=False)
        deadline = time.monotonic() + timeout
        for process in workers:
            process.join(max(0.0, deadline - time.monotonic()))
        for process in workers:
            if process.is_alive():
                process.terminate()
                process.join(5)

    def interrupt(self) -> None:
        self.cancelled.set()
        for process in self.workers():
            if process.is_alive():
                os.kill(process.pid, signal.SIGINT)


@contextmanager
def local_pool(jobs: int) -> Iterator[Executor]:
    """A started :class:`LocalPool`, shut down on leaving (after Ctrl-C, :func:`execute` has
    already interrupted and drained it)."""
    pool = LocalPool(jobs)
    try:
        pool.start()
        yield pool
    except BaseException:  # every task has returned (see _stop_running)
        pool.close(timeout=10.0)
        raise
    else:
        pool.shutdown(wait=True)


@contextmanager
def dask_pool(address: str) -> Iterator[Executor]:
    """``dask.distributed.Client(address).get_executor()``; needs the optional extra
    ``whirl[dask]``. Workers need whirl, AUTO-07p and gfortran installed."""
    try:
        from dask.distributed import Client
    except ImportError as error:
        raise WhirlError(f"--dask needs dask.distributed ({error}); {DASK_HINT}") from None
    try:
        client = Client(address, timeout="20s")
    except (OSError, TimeoutError, ValueError) as error:
        raise WhirlError(f"cannot connect to the Dask scheduler at {address}: {error}") from None
    executor = client.get_executor(pure=False)
    try:
        yield executor
    except BaseException:
        executor.shutdown(wait=False)
        raise
    finally:
        client.close()


# ------------------------------------------------------------------------------ reporting
@dataclass
class Tally:
    """Counts of a sweep in progress, for the progress display and the summary."""

    total: int
    started: float = field(default_factory=time.perf_counter)
    outcomes: list[Outcome] = field(default_factory=list)

    @property
    def done(self) -> int:
        return len(self.outcomes)

    @property
    def failures(self) -> list[Outcome]:
        return [o for o in self.outcomes if o.failed]

    def count(self, status: str) -> int:
        return sum(o.status == status for o in self.outcomes)

    def line(self, outcome: Outcome) -> str:
        """One log line per study: counter, status, name, AUTO time, output or first problem."""
        width = len(str(self.total))
        mark = {"ok": "ok", "skipped": "skip", "plotted": "plot"}.get(outcome.status,
                                                                       outcome.status.upper())
        head = f"[{self.done:>{width}}/{self.total}] {mark:<8} {outcome.item.name:<28}"
        if outcome.status == "skipped":
            detail = outcome.item.reason
        elif outcome.status == "plotted":
            detail = f"{outcome.item.reason}: {len(outcome.written)} drawn"
        elif outcome.status in ("ok", "failed"):
            detail = (f"{outcome.runs:>3} AUTO runs {outcome.auto_seconds:6.2f} s -> "
                      f"{outcome.item.output}")
        else:  # an invalid study's problems name its file
            detail = "" if outcome.status == "invalid" else str(outcome.item.source)
        if outcome.problems:
            more = len(outcome.problems) - 1
            detail += f"  {outcome.problems[0]}" + (f" (+{more} more)" if more else "")
        return f"{head} {detail}"

    def summary(self, interrupted: bool = False) -> str:
        """Counts and elapsed time, then one line per failed study."""
        seconds = time.perf_counter() - self.started
        parts = [f"{self.count('ok')} ok", f"{self.count('skipped')} up to date"]
        parts += [f"{n} plots completed" for n in [self.count("plotted")] if n]
        parts += [f"{n} {s}" for s in ("failed", "error", "invalid") if (n := self.count(s))]
        if interrupted:
            parts.append(f"{self.total - self.done} not finished (interrupted)")
        text = f"sweep: {', '.join(parts)} of {self.total} studies in {seconds:.1f} s"
        for outcome in self.failures:
            named = "" if outcome.status == "invalid" else f"{outcome.item.source}: "
            text += f"\n  {named}" + "; ".join(outcome.problems)
        return text


class Reporter:
    """Progress of a sweep on stderr: a rich progress bar (done/total, failures, ETA) on a
    terminal, otherwise one plain line per study."""

    def __init__(self, total: int, console=None) -> None:
        from rich.console import Console

        self.console = console or Console(stderr=True, highlight=False)
        self.tally = Tally(total)
        self.progress = None
        self.task = None

    def __enter__(self) -> Reporter:
        if self.console.is_terminal:
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )

            self.progress = Progress(
                TextColumn("sweep"), BarColumn(), MofNCompleteColumn(),
                TextColumn("{task.fields[failed]} failed"), TimeElapsedColumn(),
                TextColumn("ETA"), TimeRemainingColumn(), console=self.console)
            self.progress.start()
            self.task = self.progress.add_task("sweep", total=self.tally.total, failed=0)
        return self

    def __exit__(self, *exc) -> None:
        if self.progress is not None:
            self.progress.stop()

    def __call__(self, outcome: Outcome) -> None:
        self.tally.outcomes.append(outcome)
        line = self.tally.line(outcome)
        if self.progress is not None:
            self.progress.console.print(line, markup=False, soft_wrap=True)
            self.progress.update(self.task, completed=self.tally.done,
                                 failed=len(self.tally.failures))
        else:
            self.console.print(line, markup=False, soft_wrap=True)


def run_sweep(paths: Sequence[str | os.PathLike[str]], out_dir: Path, jobs: int = 1,
              dask_address: str | None = None, force: bool = False, plots: bool = True,
              console=None) -> Tally:
    """Plan, execute and report a sweep (what ``whirl sweep`` does): the tally of outcomes.

    The summary is printed in every case; a KeyboardInterrupt propagates after it.
    """
    items = plan(paths, out_dir, force, plots)
    if any(item.action == RUN for item in items):
        Path(out_dir).mkdir(parents=True, exist_ok=True)
    reporter = Reporter(len(items), console)
    interrupted = False
    try:
        with interruptible():  # SIGTERM (a batch system's cancel) stops a sweep like Ctrl-C
            if dask_address:
                pool = dask_pool(dask_address)
            else:
                prepare_workers(items)
                pool = local_pool(jobs)
            with pool as executor, reporter:
                execute(items, executor, plots=plots, report=reporter)
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        reporter.console.print(reporter.tally.summary(interrupted), markup=False, soft_wrap=True)
    return reporter.tally
