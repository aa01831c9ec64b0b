"""Executing a sweep: the task a worker runs and the parent loop that stores each result.

* :func:`compute`, the task a worker process runs: :func:`whirl_cli.pipeline.run_study` with
  ``jobs=1`` in its own temporary directory; it returns the :class:`StudyResult` (frozen
  dataclasses, picklable) and writes nothing else. :func:`init_worker` initialises local
  workers and shares the cancel flag :func:`compute` reads (both here, so that they see one
  module global).
* :func:`execute`: submits the planned studies to any ``concurrent.futures.Executor`` (a local
  process pool, or Dask's ``Client.get_executor()``) and, as each finishes, writes its HDF5
  file and plots as one unit (:func:`whirl_cli.publish.publish_study`) **in the
  parent process only**.
"""

from __future__ import annotations

import logging
import pickle
import shutil
import signal
import sys
import tempfile
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Executor, Future, as_completed, wait
from dataclasses import dataclass
from functools import partial
from pathlib import Path

from ..errors import WhirlError
from ..kinds import SweepStatus
from ..publish import publish_plots, publish_study
from ..results import StudyResult
from ..runtime import catching, held_signals, quiet_worker
from ..study import Study
from ..study import continuations as continuation_types
from ..verdict import verdict
from .plan import INVALID, PLOT, RUN, SKIP, SweepItem

#: Set by the parent of a local pool when a sweep is interrupted: queued tasks then stop at once.
_CANCELLED = None


def init_worker(cancelled) -> None:
    """Initializer of local worker processes: :func:`whirl_cli.runtime.quiet_worker` with
    SIGTERM ignored as SIGINT is (a process group's SIGTERM, a batch system's cancel, must not
    end a worker inside the pool's queue code, where it would leave a lock held and the
    parent waiting: the parent, which receives it too, ends its workers), except inside
    :func:`compute`, which removes its work directory and returns the interrupt; death with
    the sweep process; and ``cancelled`` (an Event) makes tasks still queued return at once."""
    global _CANCELLED
    _CANCELLED = cancelled
    quiet_worker(sigterm=signal.SIG_IGN)


def compute(study: Study) -> StudyResult:
    """Run ``study`` (AUTO runs one at a time) in a fresh temporary directory, removed
    afterwards; the worker-side task of a sweep. In a local worker SIGINT and SIGTERM raise
    :class:`whirl_cli.runtime.Interrupted` inside it (the work directory is made and
    removed with them held: none is left behind)."""
    from ..pipeline import run_study

    with catching():
        if _CANCELLED is not None and _CANCELLED.is_set():
            raise KeyboardInterrupt("sweep cancelled")
        if _CANCELLED is not None and not sys.stderr.isatty():  # a local worker, no progress bar
            _progress(f"{'start':<8} {study.name}")
        workroot = None
        try:
            with held_signals():
                workroot = Path(tempfile.mkdtemp(prefix=f"whirl-sweep-{study.name}-"))
            return run_study(study, workroot, jobs=1, on_slow=partial(_still_running, study.name))
        except BaseException as error:  # run_study's threads have ended (runtime.thread_map)
            raise portable(error) from None
        finally:
            with held_signals():  # an interrupt meanwhile is raised once it is removed
                if workroot is not None:
                    shutil.rmtree(workroot, ignore_errors=True)


def _still_running(study: str, run: str, seconds: float) -> None:
    """A line on the sweep's stderr: an AUTO run of ``study`` still running after ``seconds``."""
    _progress(f"  {study}: AUTO run {run} still running after {seconds:g} s")


def _progress(line: str) -> None:
    """``line`` on the sweep's stderr, from a worker (one write: lines never interleave);
    nothing with ``whirl -q`` (the level of whirl's log, inherited by a forked worker)."""
    if logging.getLogger("whirl").isEnabledFor(logging.INFO):
        sys.stderr.write(line + "\n")
        sys.stderr.flush()


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


@dataclass(frozen=True)
class Outcome:
    """What became of one study (``status``).

    ``auto_seconds``: summed wall time of its AUTO runs (s); ``written``: files written.
    """

    item: SweepItem
    status: SweepStatus
    problems: tuple[str, ...] = ()
    auto_seconds: float = 0.0
    runs: int = 0
    written: tuple[Path, ...] = ()

    @property
    def failed(self) -> bool:
        return self.status.failed or bool(self.problems)


def execute(items: Sequence[SweepItem], executor: Executor, plots: bool = True,
            report: Callable[[Outcome], None] | None = None,
            on_submitted: Callable[[int], None] | None = None) -> list[Outcome]:
    """Run the ``run`` items on ``executor``; write each result and its plots as it arrives.

    Skipped and invalid items become outcomes once the studies to run are submitted (the
    workers start first). ``report`` is called with every outcome, in completion order;
    ``on_submitted`` with the number of studies submitted.
    A KeyboardInterrupt cancels the futures not started yet and propagates.
    """
    outcomes: list[Outcome] = []

    def done(outcome: Outcome) -> None:
        outcomes.append(outcome)
        if report is not None:
            report(outcome)

    queue = sorted((item for item in items if item.action == RUN), key=expected_cost,
                   reverse=True)  # longest first: less idle time at the end of a sweep
    futures: dict[Future, SweepItem] = {executor.submit(compute, item.study): item
                                        for item in queue}
    if on_submitted is not None:
        on_submitted(len(futures))
    try:
        for item in items:  # while the workers compute
            if item.action == SKIP:
                done(Outcome(item, SweepStatus.SKIPPED, item.stored_problems))
            elif item.action == INVALID:
                done(Outcome(item, SweepStatus.INVALID, (item.reason,)))
        for item in items:
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
    """A rough relative cost of a study, to start the long ones first: each continuation's as
    its type estimates it (in one-parameter runs without periodic families); a time
    simulation costs about what a periodic family does."""
    study = item.study
    if study is None:
        return 0
    cost = 1 + 3 * len(study.simulations)
    return cost + sum(continuation_types.of(spec).cost(spec, study)
                      for spec in study.continuations)


def _store(item: SweepItem, future: Future, plots: bool) -> Outcome:
    """Write a finished study's HDF5 file and plots; a task's exception becomes an outcome."""
    try:
        result: StudyResult = future.result()
    except WhirlError as error:
        return Outcome(item, SweepStatus.ERROR, (error.message,))
    except Exception as error:  # a bug or a lost worker: report it, go on with the others
        return Outcome(item, SweepStatus.ERROR, (f"{type(error).__name__}: {error}",))
    assert item.output is not None and item.study is not None
    auto_seconds = sum(r.wall_seconds for r in result.runs)
    try:
        published = publish_study(result, item.output, item.study.plots if plots else (),
                                  overwrite=True, state=item.study.plot_state)
    except Exception as error:  # e.g. a result the store cannot represent: go on
        return Outcome(item, SweepStatus.ERROR, (f"writing {item.output}: {type(error).__name__}: "
                                       f"{error}", *verdict(result).problems), auto_seconds,
                       len(result.runs))
    problems = verdict(result, published.plot_error).problems
    return Outcome(item, SweepStatus.FAILED if problems else SweepStatus.OK, problems, auto_seconds,
                   len(result.runs), published.paths)


def _complete_plots(item: SweepItem) -> Outcome:
    """Draw the missing plots of an up-to-date study from its stored result."""
    assert item.output is not None and item.study is not None
    try:
        written = publish_plots(item.output, item.study.plots, item.study.plot_state)
    except Exception as error:  # the result file stands; say what went wrong with plots
        return Outcome(item, SweepStatus.ERROR, (f"plots: {type(error).__name__}: {error}",
                                       *item.stored_problems))
    return Outcome(item, SweepStatus.PLOTTED, item.stored_problems, written=written)

