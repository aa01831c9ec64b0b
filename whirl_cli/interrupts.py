"""Interrupts and worker processes: what every part of whirl that forks or stops shares.

* :class:`Interrupted` is the KeyboardInterrupt whirl raises for SIGINT and SIGTERM (see
  :func:`whirl_cli.auto.runner.interruptible`); it survives pickling, so it can travel back from a
  worker process.
* :func:`quiet_worker` is the initializer of every worker process whirl forks (cross-check
  simulations, sweep studies), which are forked inside :func:`forking`; :func:`end_processes`
  ends such workers after an interrupt.
* :func:`thread_map` maps over threads that never outlive the call, an interrupt included;
  :func:`forked_map` over forked worker processes (CPU-bound Python: simulations, plots);
  :class:`Standby` is one worker forked early, importing what a later call needs.
* :func:`preload` imports modules a later stage needs in a background thread (while AUTO
  runs); every fork waits for it first.
"""

from __future__ import annotations

import importlib
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager

from .signals import Interrupted


def quiet_worker(sigterm=signal.SIG_DFL) -> None:
    """Initializer of worker processes forked from whirl (cross-check and sweep pools).

    A fork inherits the parent's signal handlers; whirl's (:func:`interruptible`) would raise
    inside the pool's queue code of a worker, where an interrupt can leave a lock held and
    the other workers waiting for ever. So: SIGINT is ignored (a terminal's Ctrl-C reaches the
    whole process group; the parent alone decides and then ends its workers), SIGTERM is
    ``sigterm``: the default (the parent, or a batch system, can end a worker at once), or
    ignored like SIGINT by workers whose tasks leave files to remove (a sweep's, which
    handle both inside a task), and the worker dies with its parent (Linux parent-death
    signal), so none outlives a SIGKILLed whirl."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, sigterm)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, HELD)  # blocked while forking: see below
    die_with_parent()


#: The signals whirl handles: held back while worker processes are forked.
HELD = frozenset({signal.SIGINT, signal.SIGTERM})


#: Threads of :func:`preload` not yet joined (a fork joins them first).
_preloading: list[threading.Thread] = []
#: Every module :func:`preload` was asked for (each is imported by one thread only).
_requested: set[str] = set()


def preload(*modules: str) -> None:
    """Import ``modules`` in a background thread: modules a later stage needs (matplotlib
    for the plots, about 0.7 s), imported while AUTO runs instead of after it. Every fork
    (:func:`forking`) waits for the thread first, so a forked worker inherits the modules,
    and never an import lock held by a thread that does not exist in it. A failed import is
    ignored here: the stage that needs the module meets the error itself. Preload only
    modules no other thread imports meanwhile (two threads importing parts of one package
    at once can meet in its circular imports, and Python then raises its import-deadlock
    error in one of them). Asking again for a module asked for before does nothing."""
    missing = [name for name in modules if name not in sys.modules and name not in _requested]
    if not missing:
        return
    _requested.update(missing)

    def load() -> None:
        for name in missing:
            try:
                importlib.import_module(name)
            except Exception:  # noqa: BLE001, S110 - reported where the module is used
                pass

    thread = threading.Thread(target=load, name="whirl-preload", daemon=True)
    with held_signals():  # an interrupt in start() would leave a thread not in the list
        _preloading.append(thread)
        thread.start()


def preloaded() -> None:
    """Wait until the modules of every :func:`preload` are imported (or failed to)."""
    while _preloading:
        _preloading[0].join()
        _preloading.pop(0)


@contextmanager
def forking() -> Iterator[None]:
    """Fork worker processes inside this: SIGINT and SIGTERM are blocked in the calling
    thread, so a child starts with them blocked and none can arrive (and run the parent's
    inherited handler in the child, e.g. inside the interpreter's fork hooks) before
    :func:`quiet_worker` has set the child's own handlers and unblocked them. In the parent a
    signal that arrived meanwhile is delivered once the block ends. Modules being preloaded
    (:func:`preload`) are imported first."""
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


def end_processes(processes) -> None:
    """SIGKILL worker processes (``multiprocessing.Process``) and reap them: after an
    interrupt they hold nothing worth waiting for."""
    for process in processes:
        if process.is_alive():
            process.kill()
    for process in processes:
        process.join(5)


class _Block:
    """The state of one :func:`catching` block: the signals that arrived while it was in
    force (the first one being raised), and those whose :class:`Interrupted` a ``__del__`` or
    weakref callback dropped (raised again by the next signal, at the next :func:`check`, or
    when the block ends)."""

    def __init__(self) -> None:
        self.pending: list[int] = []
        self.swallowed: list[int] = []

    def take(self) -> int:
        """The first signal still to be raised (after which nothing is)."""
        signum = (self.swallowed or self.pending)[0]
        self.pending.clear()
        self.swallowed.clear()
        return signum


#: The :func:`catching` blocks in force, innermost last (each with its own signals).
_blocks: list[_Block] = []


@contextmanager
def catching(on_first: Callable[[], None] | None = None) -> Iterator[None]:
    """While inside (main thread only; elsewhere a no-op): SIGINT and SIGTERM raise
    :class:`Interrupted` in the main thread, after ``on_first()`` (e.g. kill the running AUTO
    processes) for the first of them; later ones do not interrupt the clean-up.

    Python discards an exception raised inside a weakref callback or a ``__del__`` (a signal
    can land in one, e.g. while matplotlib draws or a finished process is collected), printing
    "Exception ignored". So such a signal is remembered and raised again at the first chance:
    the next signal, the next :func:`check` (:func:`thread_map` and :func:`forked_map` check
    after every item, so a study stops within one item), when a block nested inside begins,
    or when the block would end normally: an interrupt is never lost. A nested block keeps
    its own signals: it raises only those that arrived while it was the innermost."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    check()  # an outer block's swallowed interrupt first
    block = _Block()

    def handler(signum: int, frame: object) -> None:
        first = not block.pending
        block.pending.append(signum)
        if first and on_first is not None:
            on_first()
        if first or block.swallowed:
            block.swallowed.clear()
            raise Interrupted(signum)

    def unraisable(hook: sys.UnraisableHookArgs) -> None:  # the "Exception ignored" print
        if isinstance(hook.exc_value, Interrupted):  # ours: raised again (see above)
            _blocks[-1].swallowed.append(hook.exc_value.signum)
        else:
            default(hook)

    previous = {number: signal.signal(number, handler) for number in HELD}
    default, sys.unraisablehook = sys.unraisablehook, unraisable
    _blocks.append(block)
    try:
        yield
    except Interrupted:
        block.pending.clear()  # delivered
        block.swallowed.clear()
        raise
    finally:
        _blocks.remove(block)
        sys.unraisablehook = default
        for number, old in previous.items():
            signal.signal(number, old)
    if block.pending:  # swallowed on its way (see above): raise it now
        raise Interrupted(block.take())


def check() -> None:
    """Raise now, in the main thread, an interrupt that a ``__del__`` or weakref callback
    swallowed inside the innermost :func:`catching` block (a no-op otherwise)."""
    if _blocks and _blocks[-1].swallowed and \
            threading.current_thread() is threading.main_thread():
        raise Interrupted(_blocks[-1].take())


@contextmanager
def held_signals() -> Iterator[None]:
    """SIGINT and SIGTERM are held back while inside (main thread only; elsewhere a no-op):
    one that arrives is recorded, and raised again on leaving, so that the handler that was
    in place (Python's KeyboardInterrupt, :func:`catching`'s, or the default action) deals
    with it then. (Blocking the signals would not do: the kernel hands a process-directed
    signal to any thread that does not block it.)"""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    arrived: list[int] = []
    held = (signal.SIGINT, signal.SIGTERM)
    previous = {number: signal.signal(number, lambda signum, _frame: arrived.append(signum))
                for number in held}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
        for number in dict.fromkeys(arrived):  # the handler called here, not when the signal
            if callable(previous[number]):     # is next checked for (maybe in a __del__,
                previous[number](number, None)  # which would drop its exception)
            else:
                signal.raise_signal(number)


def thread_map(function: Callable, items: Iterable, workers: int) -> list:
    """``[function(item) for item in items]`` over ``workers`` threads, in item order.

    No thread outlives the call, an interrupt included (the caller may then remove the files
    they work on): the threads start with signals held (an interrupt inside
    ``Thread.start`` would leave a started thread the pool does not know of), items not
    started yet are cancelled on an exception, and the running ones are waited for, again
    if an interrupt lands in that wait (under :func:`catching` later signals do not raise,
    and the AUTO runs have been killed, so the second wait is short)."""
    pool = ThreadPoolExecutor(max_workers=max(1, workers))
    futures = []
    try:
        with held_signals():
            futures = [pool.submit(function, item) for item in items]
        results = []
        for future in futures:
            results.append(future.result())
            check()
        return results
    finally:
        for future in futures:
            future.cancel()
        try:
            pool.shutdown(wait=True)
        except KeyboardInterrupt:
            pool.shutdown(wait=True)
            raise


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
        self._process = context.Process(target=_standby, args=(child, function, tuple(modules)),
                                        name="whirl-standby", daemon=True)
        with forking():
            self._process.start()
        child.close()

    def submit(self, argument: object) -> None:
        """Give the worker its argument (once)."""
        self._connection.send(argument)

    def result(self) -> object:
        """``function(argument)`` as the worker computed it, or its exception raised here."""
        try:
            done, value = self._connection.recv()
        except EOFError:
            self._process.join(5)
            raise RuntimeError(f"a worker process ended before its result (exit code "
                               f"{self._process.exitcode})") from None
        if not done:
            raise value
        return value

    def close(self) -> None:
        """End the worker (at once if it still runs) and its connection."""
        end_processes([self._process])
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
    if not received:
        return
    try:
        outcome = (True, function(received[0]))
    except BaseException as error:  # noqa: BLE001 - every failure goes back to the parent
        outcome = (False, error)
    try:
        connection.send(outcome)
    except Exception as error:  # noqa: BLE001 - e.g. an exception that does not pickle
        connection.send((False, RuntimeError(f"{type(outcome[1]).__name__}: {outcome[1]} "
                                             f"(not returned whole: {error})")))


#: The function of the :func:`forked_map` in progress, inherited by its forked workers.
_FORKED: Callable[[int], object] | None = None


def _forked_call(k: int):
    assert _FORKED is not None
    return _FORKED(k)


def forked_map(function: Callable[[int], object], count: int, jobs: int) -> list:
    """``[function(0), ..., function(count - 1)]``, in up to ``jobs`` worker processes forked
    from this one (they inherit ``function`` and all it refers to; only the results are
    pickled back, in order); in this process if ``jobs`` < 2, ``count`` < 2 or fork is not
    available. Fork only while no other thread of this process runs (e.g. AUTO's). The
    workers ignore SIGINT and die with the parent (:func:`quiet_worker`); an interrupt or an
    error here kills them at once."""
    import multiprocessing  # with the process pool, here: a study without workers needs
    from concurrent.futures import ProcessPoolExecutor  # neither (about 0.005 s)

    if jobs < 2 or count < 2 or "fork" not in multiprocessing.get_all_start_methods():
        results = []
        for k in range(count):
            results.append(function(k))
            check()
        return results
    global _FORKED
    _FORKED = function
    try:
        pool = ProcessPoolExecutor(min(jobs, count), mp_context=multiprocessing.get_context("fork"),
                                   initializer=quiet_worker)
        try:
            with forking():  # map submits every task (and forks the workers) at once
                results = pool.map(_forked_call, range(count))
            done = []
            for result in results:
                done.append(result)
                check()
            return done
        except BaseException:  # e.g. Ctrl-C: the workers hold nothing worth waiting for
            workers = list((getattr(pool, "_processes", None) or {}).values())
            manager = getattr(pool, "_executor_manager_thread", None)
            pool.shutdown(wait=False, cancel_futures=True)
            end_processes(workers)
            if manager is not None:  # left running, it races Python's exit hook for the
                manager.join(5)      # pool's wakeup pipe ("Bad file descriptor" traceback)
            raise
        finally:
            pool.shutdown(wait=True)
    finally:
        _FORKED = None
