"""Worker processes forked from whirl: how they start (:func:`forking`,
:func:`quiet_worker`), how they end (:func:`end_processes`), a map over them
(:func:`forked_map`) and one held in reserve (:class:`Standby`).

Only public interfaces of :mod:`multiprocessing` are used: each worker is a forked
``Process`` with a ``Pipe`` of its own, so the parent knows every worker it has and can kill
them at once after an interrupt.
"""

from __future__ import annotations

import importlib
import os
import signal
import threading
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager

from .blocks import HELD, check
from .threads import preloaded


def quiet_worker(sigterm=signal.SIG_DFL) -> None:
    """Set up a worker process forked from whirl (cross-check and sweep pools).

    A fork inherits the parent's signal handlers; whirl's (:func:`~.blocks.catching`) would
    raise inside the pool's queue code of a worker, where an interrupt can leave a lock held
    and the other workers waiting for ever. So: SIGINT is ignored (a terminal's Ctrl-C
    reaches the whole process group; the parent alone decides and then ends its workers),
    SIGTERM is ``sigterm``: the default (the parent, or a batch system, can end a worker at
    once), or ignored like SIGINT by workers whose tasks leave files to remove (a sweep's,
    which handle both inside a task), and the worker dies with its parent (Linux
    parent-death signal), so none outlives a SIGKILLed whirl."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, sigterm)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, HELD)  # blocked while forking: see forking
    die_with_parent()


@contextmanager
def forking() -> Iterator[None]:
    """Fork worker processes inside this: SIGINT and SIGTERM are blocked in the calling
    thread, so a child starts with them blocked and none can arrive (and run the parent's
    inherited handler in the child, e.g. inside the interpreter's fork hooks) before
    :func:`quiet_worker` has set the child's own handlers and unblocked them. In the parent a
    signal that arrived meanwhile is delivered once the block ends. Modules being preloaded
    (:func:`~.threads.preload`) are imported first."""
    preloaded()
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, HELD)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def die_with_parent() -> None:
    """Ask Linux to SIGKILL this process when its parent dies (``prctl(PR_SET_PDEATHSIG)``);
    a no-op where ``prctl`` is unavailable."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        pr_set_pdeathsig = 1
        libc.prctl(pr_set_pdeathsig, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):
        return
    if os.getppid() == 1:  # the parent died before the request took effect
        os._exit(1)


def end_processes(processes: Iterable) -> None:
    """SIGKILL worker processes (``multiprocessing.Process``) and reap them: after an
    interrupt they hold nothing worth waiting for."""
    processes = list(processes)
    for process in processes:
        if process.is_alive():
            process.kill()
    for process in processes:
        process.join(5)


class RemoteTraceback(Exception):
    """The traceback of an exception raised in a worker process (its ``__cause__`` here)."""

    def __str__(self) -> str:
        return f'\n"""\n{self.args[0]}"""'


def _send_outcome(connection, outcome: tuple) -> None:
    """Send ``outcome`` (``(..., done, value, traceback)``); a value or exception that does
    not pickle becomes a RuntimeError naming it."""
    try:
        connection.send(outcome)
    except Exception as error:  # noqa: BLE001 - e.g. an exception that does not pickle
        value = outcome[-2]
        connection.send((*outcome[:-3], False, RuntimeError(
            f"{type(value).__name__}: {value} (not returned whole: {error})"), outcome[-1]))


def _outcome(function: Callable, argument: object) -> tuple[bool, object, str | None]:
    """``(True, function(argument), None)``, or ``(False, its exception, its traceback)``."""
    try:
        return True, function(argument), None
    except BaseException as error:  # noqa: BLE001 - every failure goes back to the parent
        import traceback

        return False, error, traceback.format_exc()


def _value(done: bool, value: object, remote: str | None) -> object:
    """``value``, or raise it here (an exception of a worker, its traceback as the cause)."""
    if done:
        return value
    if remote is not None:
        value.__cause__ = RemoteTraceback(remote)
    raise value


def _dead_worker(process) -> RuntimeError:
    process.join(5)
    return RuntimeError(f"a worker process ended before its result (exit code "
                        f"{process.exitcode})")


class Standby:
    """One worker process forked now and held in reserve for a call whose argument is not
    known yet (e.g. the cross-checks of continuations AUTO has still to run): it imports
    ``modules`` at once, on another core while this process goes on, then computes
    ``function(argument)`` for the argument of :meth:`submit` and sends it back to
    :meth:`result`. ``function`` is inherited at the fork (it need not pickle); the argument,
    the result and an exception it raises are pickled. A context manager: leaving it kills
    the worker if it still runs (an interrupt, an error, a result never asked for).

    Fork it while no other thread of this process runs (as :func:`forked_map`). The worker
    ignores SIGINT and dies with its parent (:func:`quiet_worker`); it receives the argument
    in a thread of its own while it imports, so :meth:`submit` never waits for the imports."""

    def __init__(self, function: Callable[[object], object], modules: Iterable[str] = ()
                 ) -> None:
        import multiprocessing

        context = multiprocessing.get_context("fork")
        self._connection, child = context.Pipe()
        self.process = context.Process(target=_standby, args=(child, function, tuple(modules)),
                                       name="whirl-standby", daemon=True)
        with forking():
            self.process.start()
        child.close()

    def submit(self, argument: object) -> None:
        """Give the worker its argument (once)."""
        self._connection.send(argument)

    def result(self) -> object:
        """``function(argument)`` as the worker computed it, or its exception raised here."""
        try:
            outcome = self._connection.recv()
        except EOFError:
            raise _dead_worker(self.process) from None
        return _value(*outcome)

    def close(self) -> None:
        """End the worker (at once if it still runs) and its connection."""
        end_processes([self.process])
        self._connection.close()

    def __enter__(self) -> Standby:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def _standby(connection, function: Callable[[object], object], modules: tuple[str, ...]
             ) -> None:
    """The body of a :class:`Standby` worker."""
    quiet_worker()
    received: list[object] = []

    def receive() -> None:
        try:
            received.append(connection.recv())
        except EOFError:  # the parent closed without submitting
            pass

    reader = threading.Thread(target=receive, daemon=True)
    reader.start()
    for name in modules:
        try:
            importlib.import_module(name)
        except Exception:  # noqa: BLE001, S110 - the function meets the error itself
            pass
    reader.join()
    if received:
        _send_outcome(connection, _outcome(function, received[0]))


def _serve(connection, function: Callable[[int], object]) -> None:
    """The body of a :func:`forked_map` worker: ``function(k)`` for every ``k`` received,
    sent back as ``(k, *outcome)``, until ``None`` or the parent's end of the pipe
    closes."""
    quiet_worker()
    while True:
        try:
            k = connection.recv()
        except EOFError:
            return
        if k is None:
            return
        _send_outcome(connection, (k, *_outcome(function, k)))


def forked_map(function: Callable[[int], object], count: int, jobs: int) -> list:
    """``[function(0), ..., function(count - 1)]``, in up to ``jobs`` worker processes forked
    from this one (they inherit ``function`` and all it refers to; only the indices and the
    results are pickled), in order; in this process if ``jobs`` < 2, ``count`` < 2 or fork
    is not available. Fork only while no other thread of this process runs (e.g. AUTO's).
    The workers ignore SIGINT and die with the parent (:func:`quiet_worker`); an interrupt
    or an error here kills them at once. An exception of ``function`` is raised here, that
    of the first item that raised one."""
    import multiprocessing  # here: a study without workers needs it not

    if jobs < 2 or count < 2 or "fork" not in multiprocessing.get_all_start_methods():
        results = []
        for k in range(count):
            results.append(function(k))
            check()
        return results
    context = multiprocessing.get_context("fork")
    workers: list[tuple[object, object]] = []  # (process, connection)
    try:
        with forking():
            for _ in range(min(jobs, count)):
                connection, child = context.Pipe()
                process = context.Process(target=_serve, args=(child, function),
                                          name="whirl-worker", daemon=True)
                workers.append((process, connection))
                process.start()
                child.close()
        results = _gather(workers, count)
        for _, connection in workers:
            connection.send(None)
        for process, _ in workers:
            process.join(5)
        return results
    finally:  # after an interrupt or an error: the workers hold nothing worth waiting for
        end_processes(process for process, _ in workers)
        for _, connection in workers:
            connection.close()


def _gather(workers: list[tuple[object, object]], count: int) -> list:
    """Hand the indices ``0 .. count - 1`` to ``workers``, one at a time to each idle one,
    and collect the results in order (:func:`~.blocks.check` after each). After an item
    failed no more are handed out; its exception is raised once every item before it is
    done."""
    from multiprocessing.connection import wait

    indices = iter(range(count))
    results: list = [None] * count
    errors: dict[int, tuple] = {}  # index -> outcome
    busy: dict[object, tuple[object, int]] = {}  # connection -> (process, index)

    def hand_out(process, connection) -> None:
        k = None if errors else next(indices, None)
        if k is not None:
            connection.send(k)
            busy[connection] = (process, k)

    for process, connection in workers:
        hand_out(process, connection)
    while busy:
        for connection in wait(list(busy)):
            process, _ = busy.pop(connection)
            try:
                k, *outcome = connection.recv()
            except EOFError:
                raise _dead_worker(process) from None
            if outcome[0]:
                results[k] = outcome[1]
            else:
                errors[k] = outcome
            hand_out(process, connection)
            check()
        if errors and all(k > min(errors) for _, k in busy.values()):
            break
    if errors:
        _value(*errors[min(errors)])
    return results
