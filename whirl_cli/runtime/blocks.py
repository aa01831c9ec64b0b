"""Blocks of code in which SIGINT and SIGTERM raise :class:`~.signals.Interrupted`
(:func:`catching`) or are held back until the block ends (:func:`held_signals`)."""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from .signals import Interrupted, delivered, dropped_interrupt

#: The signals whirl handles: held back while worker processes are forked.
HELD = frozenset({signal.SIGINT, signal.SIGTERM})


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
    the next signal, the next :func:`check` (``thread_map`` and ``forked_map`` check after
    every item, so a study stops within one item), when a block nested inside begins, or when
    the block would end normally: an interrupt is never lost. A nested block keeps its own
    signals: it raises only those that arrived while it was the innermost."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    check()  # an outer block's swallowed interrupt first
    block = _Block()

    def handler(signum: int, frame: object) -> None:
        interrupt = delivered(signum)
        first = not block.pending
        block.pending.append(signum)
        if first and on_first is not None:
            on_first()
        if first or block.swallowed:
            block.swallowed.clear()
            raise interrupt

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
    swallowed inside the innermost :func:`catching` block, or outside any block after
    :func:`~.signals.terminate_as_interrupt` (a no-op otherwise)."""
    if threading.current_thread() is not threading.main_thread():
        return
    if _blocks:
        if _blocks[-1].swallowed:
            raise Interrupted(_blocks[-1].take())
        return
    signum = dropped_interrupt()
    if signum is not None:
        raise Interrupted(signum)


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
