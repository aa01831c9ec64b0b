"""Threads that never outlive their call (:func:`thread_map`) and modules imported in the
background (:func:`preload`)."""

from __future__ import annotations

import importlib
import sys
import threading
from collections.abc import Callable, Iterable

from .blocks import check, held_signals

#: Threads of :func:`preload` not yet joined (a fork joins them first).
_preloading: list[threading.Thread] = []
#: Every module :func:`preload` was asked for (each is imported by one thread only).
_requested: set[str] = set()


def preload(*modules: str) -> None:
    """Import ``modules`` in a background thread: modules a later stage needs (matplotlib
    for the plots), imported while AUTO runs instead of after it. Every fork
    (:func:`~.processes.forking`) waits for the thread first, so a forked worker inherits the
    modules, and never an import lock held by a thread that does not exist in it. A failed
    import is ignored here: the stage that needs the module meets the error itself. Preload
    only modules no other thread imports meanwhile (two threads importing parts of one
    package at once can meet in its circular imports, and Python then raises its
    import-deadlock error in one of them). Asking again for a module asked for before does
    nothing."""
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


def thread_map(function: Callable, items: Iterable, workers: int) -> list:
    """``[function(item) for item in items]`` over ``workers`` threads, in item order.

    No thread outlives the call, an interrupt included (the caller may then remove the files
    they work on): the threads start with signals held (an interrupt inside
    ``Thread.start`` would leave a started thread the pool does not know of), items not
    started yet are cancelled on an exception, and the running ones are waited for, again
    if an interrupt lands in that wait (under :func:`~.blocks.catching` later signals do not
    raise, and the AUTO runs have been killed, so the second wait is short)."""
    from concurrent.futures import ThreadPoolExecutor  # here: importing the facade stays cheap

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
