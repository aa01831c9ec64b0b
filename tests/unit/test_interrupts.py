"""Interrupts are never lost: a signal landing where Python discards exceptions (a weakref
callback, ``__del__``) is raised again when the guarded block ends (issue 13, item 1: seen as
"Exception ignored ... KeyboardInterrupt" and a run that went on to the end)."""

from __future__ import annotations

import gc
import os
import pickle
import signal
import weakref

import pytest

from whirl_cli.interrupts import Interrupted, catching


class Thing:
    pass


def interrupt_inside_a_weakref_callback() -> None:
    """Send SIGINT to this process from within a weakref callback, as the garbage collector
    runs it: the handler's exception is discarded there."""
    thing = Thing()
    _ = weakref.ref(thing, lambda _ref: os.kill(os.getpid(), signal.SIGINT))
    keep = [_]  # the reference object must outlive the referent for the callback to run
    del thing
    gc.collect()
    assert keep


def test_a_signal_swallowed_in_a_weakref_callback_is_raised_at_the_end(capfd):
    reached = []
    with pytest.raises(Interrupted) as caught:
        with catching():
            interrupt_inside_a_weakref_callback()
            reached.append("the block went on")  # Python discarded the first raise
    assert reached and caught.value.signum == signal.SIGINT
    assert "Exception ignored" not in capfd.readouterr().err  # no traceback printed


def test_a_delivered_signal_is_raised_once_and_calls_on_first():
    calls = []
    with pytest.raises(Interrupted):
        with catching(on_first=lambda: calls.append("stop")):
            os.kill(os.getpid(), signal.SIGTERM)
    assert calls == ["stop"]
    with catching():  # nothing pending afterwards
        pass


def test_interrupted_survives_pickling():
    copy = pickle.loads(pickle.dumps(Interrupted(signal.SIGTERM)))
    assert isinstance(copy, Interrupted) and copy.signum == signal.SIGTERM
