"""``whirl sweep``: plan, execute and report a sweep (:func:`run_sweep`).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from pathlib import Path

from ..auto.runner import interruptible
from ..output.guard import RESULT, check, plots_ready, writable
from .execute import Outcome, execute
from .executors import dask_pool, local_pool, prepare_workers
from .plan import RUN, SweepItem, plan
from .report import Reporter, Tally


def run_sweep(paths: Sequence[str | os.PathLike[str]], out_dir: Path, jobs: int = 1,
              dask_address: str | None = None, force: bool = False, plots: bool = True,
              console=None, on_outcome: Callable[[Outcome, int], None] | None = None,
              on_summary: Callable[[str], None] | None = None) -> Tally:
    """Plan, execute and report a sweep (what ``whirl sweep`` does): the tally of outcomes.

    ``on_outcome`` is called in this process after each outcome is reported, with the number
    of studies still running or waiting for a worker (fewer than ``jobs``: a worker is idle).
    The summary is given to ``on_summary`` (None: printed with the progress, on ``console``)
    in every case; a KeyboardInterrupt propagates after it.
    """
    items = plan(paths, out_dir, force, plots)
    pending = sum(item.action == RUN for item in items)
    _refuse_outputs([item for item in items if item.action == RUN], plots)
    if pending:
        Path(out_dir).mkdir(parents=True, exist_ok=True)
    reporter = Reporter(len(items), console)

    def report(outcome: Outcome) -> None:
        nonlocal pending
        reporter(outcome)
        pending -= outcome.item.action == RUN
        if on_outcome is not None:
            on_outcome(outcome, pending)

    interrupted = False
    try:
        with interruptible():  # SIGTERM (a batch system's cancel) stops a sweep like Ctrl-C
            if dask_address:
                pool = dask_pool(dask_address)
            else:
                prepare_workers(items)
                pool = local_pool(jobs)
            with pool as executor, reporter:
                execute(items, executor, plots=plots, report=report)
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        summary = reporter.tally.summary(interrupted)
        if on_summary is None:
            reporter.console.print(summary, markup=False, soft_wrap=True)
        else:
            on_summary(summary)
    return reporter.tally


def _refuse_outputs(runs: Sequence[SweepItem], plots: bool) -> None:
    """Before any work: OutputError if a result file a sweep would write, or (``plots``) a
    file named as one of its plots, is not whirl's to replace (a link, directory, device,
    another program's file) or its folder cannot take files (read-only, full)."""
    for item in runs:
        check(item.output, RESULT, overwrite=True)
        if plots and item.study.plots:
            plots_ready(item.output)
    if runs:
        writable(runs[0].output)

