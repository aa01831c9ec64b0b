"""Where a sweep's studies run: a local process pool whose studies can be interrupted, or the
executor of a Dask cluster.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import threading
import time
from collections.abc import Iterator, Sequence
from concurrent.futures import Executor, ProcessPoolExecutor
from contextlib import contextmanager

from ..errors import WhirlError
from ..runtime import forking
from .execute import init_worker
from .plan import RUN, SweepItem

DASK_HINT = "install with pip install 'whirl[dask]'"


def prepare_workers(items: Sequence[SweepItem]) -> None:
    """Import what a worker needs and build the planned studies' models in this process, so
    that workers started by fork inherit them instead of each spending about a second on
    imports and sympy work (harmless with other start methods)."""
    import numpy as np

    from .. import pipeline  # noqa: F401  (imported for the workers to inherit)
    from ..analysis import simulate  # noqa: F401  (imported for the workers to inherit)

    for item in items:
        if item.action == RUN and item.study is not None:
            model = item.study.variant()
            params = model.parameter_vector(item.study.parameter_values())
            model.jacobian_numpy(np.zeros(model.n_states), params)
            model.rhs_numpy(np.zeros(model.n_states), params)


class LocalPool(ProcessPoolExecutor):
    """A process pool of ``jobs`` workers whose studies can be interrupted.

    Workers ignore SIGINT and SIGTERM except inside a study (see
    :func:`whirl_cli.sweep.execute.init_worker`);
    ``interrupt`` sets the shared cancel flag (queued tasks return at once) and sends them
    SIGINT (a terminal's Ctrl-C reaches them directly, ``kill -INT`` on the parent does not).
    The pool's own cancel/terminate paths are not used after an interrupt: in Python 3.11
    they can leave a worker waiting forever. The workers are the child processes that
    :meth:`start` made (:func:`multiprocessing.active_children`)."""

    def __init__(self, jobs: int) -> None:
        context = multiprocessing.get_context()
        self.cancelled = context.Event()
        super().__init__(max_workers=jobs, mp_context=context, initializer=init_worker,
                         initargs=(self.cancelled,))
        self.jobs = jobs
        self._workers: list = []

    def workers(self) -> list:
        return list(self._workers)

    def start(self) -> None:
        """Start every worker now (before a progress display thread exists: fork is safe)."""
        before = set(multiprocessing.active_children())
        with forking():
            started = [self.submit(os.getpid) for _ in range(self.jobs)]
        self._workers = [p for p in multiprocessing.active_children() if p not in before]
        for future in started:
            future.result()

    def close(self, timeout: float) -> None:
        """Shut down without risking a hang: workers not gone after ``timeout`` s are killed;
        by then they run no study. Every worker gets the whole ``timeout`` to end its study and
        remove its work directory, also in a broken pool (a worker died, its manager has sent
        the others SIGTERM, which ends a study at once but is ignored by an idle worker, see
        :func:`whirl_cli.sweep.execute.init_worker`, so an idle one then waits to be killed).
        The shutdown waits in a thread of its own until the pool's manager thread has ended (one
        left running races Python's exit for the pool's wakeup pipe)."""
        workers = self.workers()
        shutdown = threading.Thread(target=self.shutdown, name="whirl-pool-shutdown",
                                    daemon=True)
        shutdown.start()
        deadline = time.monotonic() + timeout
        for process in workers:
            process.join(max(0.0, deadline - time.monotonic()))
        for process in workers:
            if process.is_alive():
                process.kill()
                process.join(5)
        shutdown.join(5)

    def interrupt(self) -> None:
        self.cancelled.set()
        for process in self.workers():
            if process.is_alive():
                try:
                    os.kill(process.pid, signal.SIGINT)
                except ProcessLookupError:  # ended meanwhile (a process group's SIGTERM),
                    pass                    # and reaped by the pool's manager thread


@contextmanager
def local_pool(jobs: int) -> Iterator[Executor]:
    """A started :class:`LocalPool`, shut down on leaving (after Ctrl-C, :func:`execute` has
    already interrupted and drained it)."""
    pool = LocalPool(jobs)
    try:
        pool.start()
        yield pool
    finally:  # after an interrupt every task has returned (see _stop_running)
        pool.close(timeout=10.0)


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

