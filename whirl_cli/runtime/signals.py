"""The exception SIGINT and SIGTERM raise in whirl, and their handler from the first moment.

Only :mod:`signal` and :mod:`sys` are imported here (and light modules by the package):
:func:`whirl_cli.entry.main` installs :func:`raise_interrupted` for SIGINT and SIGTERM before
it imports anything else, so that a batch system's cancel ends whirl as Ctrl-C does instead of
by the signal's default action, however early it lands; every signal a handler of whirl's
receives is noted, so that an error a library made of the interrupt is still taken as one. An
interrupt Python drops (raised inside a ``__del__`` or weakref callback, where it only prints
"Exception ignored") before any :func:`whirl_cli.runtime.catching` block is in force is kept,
and raised by the next :func:`whirl_cli.runtime.check` (the console script checks once the
command line is imported, and every ``catching`` block checks when it begins).
"""

from __future__ import annotations

import signal
import sys

#: Signal numbers of interrupts Python dropped outside any ``catching`` block, oldest first.
_dropped: list[int] = []
#: Signal numbers of the SIGINTs and SIGTERMs whirl's handlers received, oldest first.
_delivered: list[int] = []


class Interrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM during :func:`whirl_cli.auto.runner.interruptible`: every running AUTO
    process is killed. 128 + ``signum`` is whirl's exit status."""

    def __init__(self, signum: int = signal.SIGINT) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = int(signum)

    def __reduce__(self):
        """Pickle by the signal number (the default would re-create it from its message, the
        signal's name, which is no signal number): an interrupt raised in a worker process
        must reach the parent intact, or the process pool breaks."""
        return type(self), (self.signum,)


def wrapped_interrupt(error: BaseException) -> KeyboardInterrupt | None:
    """The interrupt that caused ``error`` (its ``__cause__`` or ``__context__``, at any
    depth), if any: Python turns an interrupt raised inside some of its hooks into another
    exception (3.11: a RuntimeError for one inside ``__set_name__``). An error with no
    interrupt behind it, once whirl has raised one, is taken as that interrupt's doing too:
    libraries' compiled code turns an exception raised inside a call back into Python into
    its own error without a cause (pydantic-core: a SchemaError "Error building ...
    validator: Interrupted: SIGTERM" while a model's validator is built)."""
    seen: set[int] = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, KeyboardInterrupt):
            return error
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return Interrupted(_delivered[-1]) if _delivered else None


def delivered(signum: int) -> Interrupted:
    """Note that a handler of whirl's received ``signum``; its :class:`Interrupted`."""
    _delivered.append(int(signum))
    return Interrupted(signum)


def raise_interrupted(signum: int, _frame: object) -> None:
    """A signal handler: raise :class:`Interrupted` for ``signum``."""
    raise delivered(signum)


def terminate_as_interrupt() -> None:
    """From now on SIGINT and SIGTERM raise :class:`Interrupted` (a KeyboardInterrupt, as
    Python's SIGINT handler raises), and an interrupt Python drops is kept for
    :func:`dropped_interrupt` instead of printed."""
    signal.signal(signal.SIGINT, raise_interrupted)
    signal.signal(signal.SIGTERM, raise_interrupted)
    default = sys.unraisablehook

    def unraisable(hook: sys.UnraisableHookArgs) -> None:
        if isinstance(hook.exc_value, KeyboardInterrupt):
            _dropped.append(getattr(hook.exc_value, "signum", signal.SIGINT))
        else:
            default(hook)

    sys.unraisablehook = unraisable


def dropped_interrupt() -> int | None:
    """The signal number of the first interrupt Python dropped outside any ``catching`` block
    since the last call (None: none); forgets them all."""
    first = _dropped[0] if _dropped else None
    _dropped.clear()
    return first
