"""Interrupts are never lost: a signal landing where Python discards exceptions (a weakref
callback, ``__del__``) is raised again when the guarded block ends (issue 13, item 1: seen as
"Exception ignored ... KeyboardInterrupt" and a run that went on to the end)."""

from __future__ import annotations

import gc
import os
import pickle
import signal
import sys
import threading
import time
import weakref

import pytest

from whirl_cli.runtime import (
    Interrupted,
    Standby,
    catching,
    check,
    forked_map,
    held_signals,
    preload,
    preloaded,
    thread_map,
)


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


@pytest.mark.parametrize("mapped", ["thread_map", "forked_map"])
def test_a_swallowed_signal_is_raised_after_the_next_item_of_a_map(mapped):
    """A study must stop at once, not at the end of the block: a map raises the swallowed
    interrupt after its next item (here the first), before the block goes on."""
    reached = []
    with pytest.raises(Interrupted):
        with catching():
            interrupt_inside_a_weakref_callback()
            reached.append("the block went on")
            if mapped == "thread_map":
                thread_map(lambda x: x, [1, 2, 3], 1)
            else:
                forked_map(lambda k: k, 3, 2)
            reached.append("after the map")
    assert reached == ["the block went on"]


def test_an_interrupted_forked_map_kills_its_workers_and_leaves_no_thread(tmp_path):
    """Interrupted while its workers run, forked_map kills them at once (none finishes its
    item, none is left) and leaves no thread of its own behind."""
    import multiprocessing

    def item(k: int) -> None:
        time.sleep(30)
        (tmp_path / f"finished{k}").touch()

    children, threads = set(multiprocessing.active_children()), set(threading.enumerate())
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    with pytest.raises(Interrupted):
        with catching():
            timer.start()
            forked_map(item, 2, 2)
    timer.join()
    assert set(multiprocessing.active_children()) <= children
    assert set(threading.enumerate()) <= threads
    assert list(tmp_path.iterdir()) == []


def test_forked_map_raises_the_error_of_the_first_failing_item_with_its_traceback():
    def item(k: int) -> int:
        if k in (1, 3):
            raise ValueError(f"item {k}")
        return k

    with pytest.raises(ValueError, match="item 1") as caught:
        forked_map(item, 5, 2)
    assert "raise ValueError" in str(caught.value.__cause__)  # the worker's traceback


def test_a_forked_map_worker_that_dies_or_returns_what_does_not_pickle_is_an_error():
    with pytest.raises(RuntimeError, match="exit code 3"):
        forked_map(lambda k: os._exit(3) if k == 2 else k, 4, 2)
    with pytest.raises(RuntimeError, match="not returned whole"):
        forked_map(lambda k: (lambda: k), 2, 2)  # a lambda does not pickle


def test_a_swallowed_signal_is_raised_by_the_next_signal_and_by_check():
    for again in ("signal", "check"):
        with pytest.raises(Interrupted):
            with catching():
                interrupt_inside_a_weakref_callback()
                if again == "signal":
                    os.kill(os.getpid(), signal.SIGINT)
                else:
                    check()
                raise AssertionError(f"the {again} did not raise the swallowed interrupt")
    check()  # nothing left to raise once delivered


def test_a_held_signal_is_raised_on_leaving_by_the_handler_in_place():
    """On leaving :func:`held_signals` the previous handler is called at once (a signal
    raised again would wait for the next check, maybe inside a ``__del__`` that drops it)."""
    with pytest.raises(KeyboardInterrupt):
        with held_signals():
            os.kill(os.getpid(), signal.SIGINT)
    with pytest.raises(Interrupted):
        with catching(), held_signals():
            os.kill(os.getpid(), signal.SIGTERM)


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


def test_no_thread_outlives_thread_map_when_an_interrupt_lands_in_thread_start(monkeypatch):
    """Seen as a sweep's work directory left behind (CI, about 1 in 30 under load): Ctrl-C
    inside ``Thread.start`` left a started thread the pool did not know of; it ran an AUTO
    run into the directory after the study had removed it."""
    import threading
    import time

    from whirl_cli.runtime import thread_map

    real_start = threading.Thread.start

    def start_then_interrupt(thread):
        real_start(thread)
        os.kill(os.getpid(), signal.SIGINT)  # as if Ctrl-C came while the thread started

    monkeypatch.setattr(threading.Thread, "start", start_then_interrupt)
    finished = []

    def slow(item: int) -> int:
        time.sleep(0.2)
        finished.append(item)
        return item

    before = set(threading.enumerate())
    with pytest.raises(Interrupted):
        with catching():
            thread_map(slow, range(6), workers=2)
    assert set(threading.enumerate()) <= before  # every thread has ended
    assert 1 <= len(finished) < 6  # those started ran to their end, the others never began
    time.sleep(0.5)
    assert len(finished) == len(set(finished)) and len(finished) < 6  # nothing ran later


def test_thread_map_returns_in_item_order():
    from whirl_cli.runtime import thread_map

    assert thread_map(lambda x: x * x, range(10), workers=3) == [x * x for x in range(10)]


def test_a_signal_during_interpreter_shutdown_ends_whirl_without_a_traceback(tmp_path):
    """After the command, the interpreter joins the worker pools' threads at exit
    (``threading._shutdown``): a SIGINT landing there must end whirl quietly (killed by the
    signal, its outputs complete), not print a KeyboardInterrupt traceback. Here the join is
    a long wait registered like the pools' own exit hook, which only the signal ends."""
    import subprocess
    import sys
    import time

    script = tmp_path / "slow_exit.py"
    script.write_text(
        "import sys, threading, time\n"
        "threading._register_atexit(lambda: (print('exiting', flush=True), time.sleep(600)))\n"
        "from whirl_cli.cli import main\n"
        "sys.argv = ['whirl', '--version']\n"
        "main()\n")
    process = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    try:
        assert "version" in process.stdout.readline()
        assert process.stdout.readline().strip() == "exiting"
        time.sleep(0.2)
        process.send_signal(signal.SIGINT)
        _, stderr = process.communicate(timeout=120)  # a guard against a hang only
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert "Traceback" not in stderr, stderr
    assert process.returncode == -signal.SIGINT


def probe_module(tmp_path, monkeypatch, name: str, text: str) -> str:
    """A module ``name`` of ``text`` under ``tmp_path`` (on sys.path), not imported yet."""
    (tmp_path / f"{name}.py").write_text(text)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, name, raising=False)
    return name


def slow_module(tmp_path, monkeypatch, name: str, body: str = "") -> str:
    """A module ``name`` under ``tmp_path`` (on sys.path) that takes 0.3 s to import."""
    return probe_module(tmp_path, monkeypatch, name, f"import time\ntime.sleep(0.3)\n{body}\n")


def waiting_module(tmp_path, monkeypatch, name: str, flag, attribute: str) -> str:
    """A module ``name`` whose import ends only once the file ``flag`` exists (or after
    20 s); its ``attribute`` says whether the flag was there by then."""
    present = f"os.path.exists({str(flag)!r})"
    return probe_module(tmp_path, monkeypatch, name,
                        "import os, time\ndeadline = time.monotonic() + 20\n"
                        f"while not {present} and time.monotonic() < deadline:\n"
                        f"    time.sleep(0.01)\n{attribute} = {present}\n")


def test_preload_imports_in_the_background_and_a_fork_waits_for_it(tmp_path, monkeypatch):
    """The module's import ends only once this test has gone on past ``preload`` (or after
    20 s, then without DONE): ``preload`` did not wait for it, and the forked workers see it
    imported whole (a module being imported is in sys.modules already, without DONE)."""
    flag = tmp_path / "went_on"
    name = waiting_module(tmp_path, monkeypatch, "whirl_preload_probe", flag, "DONE")
    preload(name)
    flag.touch()
    seen = forked_map(lambda _k: getattr(sys.modules.get(name), "DONE", False), 2, 2)
    assert seen == [True, True]
    assert not [t for t in threading.enumerate() if t.name == "whirl-preload"]


def test_a_failed_preload_is_ignored_and_met_where_the_module_is_used(tmp_path, monkeypatch):
    name = slow_module(tmp_path, monkeypatch, "whirl_preload_broken", "raise ValueError('no')")
    preload(name)
    preloaded()
    assert name not in sys.modules
    with pytest.raises(ValueError, match="no"):
        __import__(name)


def test_preload_of_imported_modules_starts_no_thread():
    preload("os", "signal")
    assert not [t for t in threading.enumerate() if t.name == "whirl-preload"]


def test_a_standby_worker_imports_first_and_computes_from_what_is_submitted_later(
        tmp_path, monkeypatch):
    # a module whose import in the worker ends only once this test has submitted (or 20 s)
    flag = tmp_path / "submitted"
    name = waiting_module(tmp_path, monkeypatch, "whirl_standby_probe", flag, "SUBMITTED_FIRST")
    inherited = {"offset": 10}  # made before the fork: the worker sees it without pickling

    def work(values):  # a closure: it does not pickle, it is inherited at the fork
        return [v + inherited["offset"] for v in values], sys.modules[name].SUBMITTED_FIRST

    with Standby(work, (name,)) as standby:
        standby.submit(list(range(100_000)))  # more than a pipe holds: read while importing
        flag.touch()
        values, submitted_first = standby.result()
    assert values == [v + 10 for v in range(100_000)]
    assert submitted_first  # imported in the worker, before the work, but not waited for
    assert name not in sys.modules  # not here


def test_a_standby_worker_raises_its_error_here_and_ends_with_the_block():
    def failing(_argument):
        raise ValueError("bad orbit")

    with Standby(failing) as standby:
        standby.submit(None)
        with pytest.raises(ValueError, match="bad orbit"):
            standby.result()
    with Standby(lambda _argument: time.sleep(60)) as standby:
        standby.submit(None)
        process = standby.process  # what the block must end
        assert process.is_alive()
    assert not process.is_alive()  # killed on leaving, not waited for
    assert process.exitcode == -signal.SIGKILL


def test_a_standby_worker_that_dies_is_an_error_not_a_hang():
    with Standby(lambda _argument: os._exit(3)) as standby:
        standby.submit(None)
        with pytest.raises(RuntimeError, match="exit code 3"):
            standby.result()


def _ended_pid() -> int:
    """The PID of a process that has ended and been reaped."""
    import subprocess

    process = subprocess.Popen(["true"], start_new_session=True)
    process.wait()
    return process.pid


def test_stopping_a_process_that_has_ended_meanwhile_is_no_error(monkeypatch):
    """A process group's SIGTERM ends a sweep worker (or an AUTO run) between the check that
    it is alive and the signal whirl sends it: that is no error."""
    from types import SimpleNamespace

    from whirl_cli.auto.runner import kill_group
    from whirl_cli.sweep.executors import LocalPool

    kill_group(_ended_pid())
    pool = LocalPool(1)
    try:
        ended = SimpleNamespace(pid=_ended_pid(), is_alive=lambda: True)  # as it was checked
        monkeypatch.setattr(pool, "workers", lambda: [ended])
        pool.interrupt()
        assert pool.cancelled.is_set()
    finally:
        pool.shutdown()


def test_a_signal_an_outer_block_swallowed_is_raised_when_an_inner_block_begins():
    """Nested blocks (``whirl run`` around AUTO's): an inner block must not drop the outer
    one's swallowed interrupt; it is raised at once, before the inner block runs."""
    reached = []
    with pytest.raises(Interrupted) as caught:
        with catching():
            interrupt_inside_a_weakref_callback()
            reached.append("the outer block went on")
            with catching():
                reached.append("the inner block ran")
            reached.append("after the inner block")
    assert reached == ["the outer block went on"] and caught.value.signum == signal.SIGINT


def test_an_inner_block_neither_raises_nor_drops_an_outer_blocks_signal():
    """An interrupt the outer block delivered, which its code caught to go on (a clean-up),
    is the outer block's: an inner block does not raise it, nor forget it (the outer block
    raises it when it ends); the inner block's own first signal calls its ``on_first``."""
    calls, reached = [], []
    with pytest.raises(Interrupted) as caught:
        with catching():
            with pytest.raises(Interrupted):
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(1)
            with catching(on_first=lambda: calls.append("stop")):
                reached.append("the inner block ran")
            reached.append("after the inner block")
    assert reached == ["the inner block ran", "after the inner block"]
    assert caught.value.signum == signal.SIGTERM and calls == []
    with pytest.raises(Interrupted) as caught:
        with catching():
            with pytest.raises(Interrupted):
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(1)
            with catching(on_first=lambda: calls.append("stop")):
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(1)
    assert caught.value.signum == signal.SIGINT and calls == ["stop"]
    with catching():  # nothing pending afterwards
        check()


def test_an_interrupted_command_says_interrupted_on_one_line(monkeypatch, capsys, tmp_path):
    """click closes a terminal's ``^C`` echo with a blank line before its Abort; whirl says
    "interrupted" alone (the exit status says which signal)."""
    from whirl_cli import cli, study

    def interrupted(*_args, **_kwargs):
        raise Interrupted(signal.SIGTERM)

    monkeypatch.setattr(study, "load_study", interrupted)
    monkeypatch.setattr(sys, "argv", ["whirl", "validate", str(tmp_path / "x.yaml")])
    with pytest.raises(SystemExit) as end:
        cli._main()
    assert end.value.code == 143
    assert capsys.readouterr().err == "interrupted\n"


def test_an_interrupt_a_library_turned_into_its_own_error_ends_whirl_as_an_interrupt(
        monkeypatch, capsys):
    """Seen as "internal error: SchemaError: Error building "literal" validator: Interrupted:
    SIGTERM" for a SIGTERM early in ``whirl figures``: pydantic-core's compiled code catches
    the interrupt raised inside a call back into Python and raises its own error, with no
    cause. The signal reached whirl's handler, so: exit 143 and "interrupted"."""
    from whirl_cli import cli
    from whirl_cli.runtime import signals

    monkeypatch.setattr(signals, "_delivered", [])

    def command(**_options):
        previous = signal.signal(signal.SIGTERM, signals.raise_interrupted)
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(5)  # the handler raises before this ends
        except KeyboardInterrupt:
            pass  # what the compiled code does with it
        finally:
            signal.signal(signal.SIGTERM, previous)
        raise RuntimeError('Error building "literal" validator: Interrupted: SIGTERM')

    monkeypatch.setattr(cli.cli, "main", command)
    with pytest.raises(SystemExit) as ended:
        cli.main()
    assert ended.value.code == 128 + signal.SIGTERM
    assert capsys.readouterr().err == "interrupted\n"


class _Interrupting:
    """A descriptor whose ``__set_name__`` is interrupted (as by a signal while a class such as
    a pydantic model is made): Python 3.11 wraps the interrupt in a RuntimeError."""

    def __set_name__(self, owner: type, name: str) -> None:
        raise Interrupted(signal.SIGTERM)


def test_an_interrupt_python_wrapped_in_another_exception_ends_whirl_as_an_interrupt(
        monkeypatch, capsys):
    """Seen as "internal error: RuntimeError: Error calling __set_name__" for a SIGTERM early
    in ``whirl figures``: exit 143 and "interrupted" instead."""
    from whirl_cli import cli

    def command(**_options):
        class Model:  # noqa: F841 - made only to be interrupted
            field = _Interrupting()

    monkeypatch.setattr(cli.cli, "main", command)
    with pytest.raises(SystemExit) as ended:
        cli.main()
    assert ended.value.code == 128 + signal.SIGTERM
    assert capsys.readouterr().err == "interrupted\n"


def entry_with_stand_in(attribute: str):
    """Run the console script (:func:`whirl_cli.entry.main`) in a fresh interpreter with a
    stand-in for the command line's module: ``attribute``, Python source defining
    ``attribute(name)``, its module ``__getattr__`` (what ``from .cli import main`` calls)."""
    import subprocess

    script = (attribute
              + "import sys, types\n"
                "stand_in = types.ModuleType('whirl_cli.cli')\n"
                "stand_in.__getattr__ = attribute\n"
                "sys.modules['whirl_cli.cli'] = stand_in\n"
                "from whirl_cli.entry import main\n"
                "main()\n")
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=60, check=False)


def test_an_interrupt_wrapped_while_the_command_line_is_imported_ends_whirl_too():
    """The console script's import of the command line: a stand-in module whose ``main`` is
    a class interrupted while it is made."""
    done = entry_with_stand_in(
        "import signal\n"
        "from whirl_cli.runtime import Interrupted\n"
        "class Interrupting:\n"
        "    def __set_name__(self, owner, name): raise Interrupted(signal.SIGTERM)\n"
        "def attribute(name):\n"
        "    class Model:\n"
        "        field = Interrupting()\n")
    assert (done.returncode, done.stderr) == (143, "interrupted\n")


def test_a_sigterm_python_drops_while_the_command_line_is_imported_still_ends_whirl():
    """The console script's import of the command line, a stand-in module: SIGTERM lands
    inside a weakref callback the garbage collector runs meanwhile, where Python prints
    "Exception ignored" and drops the handler's exception, before any :func:`catching` block
    is in force. The command must not run: exit 143, "interrupted" and nothing else."""
    done = entry_with_stand_in(
        "import gc, os, signal, weakref\n"
        "class Thing: pass\n"
        "def attribute(name):\n"
        "    thing = Thing()\n"
        "    ref = weakref.ref(thing, lambda _r: os.kill(os.getpid(), signal.SIGTERM))\n"
        "    del thing\n"
        "    gc.collect()\n"
        "    assert ref\n"
        "    return lambda: print('the command ran')\n")
    assert (done.returncode, done.stdout, done.stderr) == (143, "", "interrupted\n")
