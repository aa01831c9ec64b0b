"""The console script's end (:func:`whirl_cli.entry.leave`): the exit functions run, the
streams are flushed and the exit status is the command's, as with the interpreter's own exit;
a thread still running is waited for."""

from __future__ import annotations

import subprocess
import sys
import textwrap


def _run(body: str) -> subprocess.CompletedProcess:
    """``body`` run by a fresh interpreter, its stdout a pipe (block-buffered, as in a batch
    job or ``whirl ... | tee``)."""
    return subprocess.run([sys.executable, "-c", textwrap.dedent(body)], capture_output=True,
                          text=True, timeout=60)


def test_exit_functions_run_and_buffered_output_is_flushed_with_the_status():
    done = _run("""
        import atexit, sys
        from whirl_cli.entry import leave
        atexit.register(lambda: print("exit function ran"))
        print("a line" * 1000, end="")
        sys.stderr.write("to stderr")
        leave(3)
    """)
    assert done.returncode == 3
    assert done.stdout == "a line" * 1000 + "exit function ran\n"
    assert done.stderr == "to stderr"


def test_a_status_of_none_is_0_and_a_message_is_printed_with_status_1():
    assert _run("from whirl_cli.entry import leave; leave(None)").returncode == 0
    done = _run("from whirl_cli.entry import leave; leave('no such study')")
    assert (done.returncode, done.stderr) == (1, "no such study\n")


def test_a_thread_still_running_is_waited_for():
    done = _run("""
        import threading, time
        from whirl_cli.entry import leave
        def late():
            time.sleep(0.5)
            print("thread finished", flush=True)
        threading.Thread(target=late).start()
        leave(4)
    """)
    assert (done.returncode, done.stdout) == (4, "thread finished\n")


def test_the_console_script_ends_with_the_commands_status_and_output(tmp_path):
    missing = tmp_path / "missing.yaml"
    done = subprocess.run([sys.executable, "-m", "whirl_cli", "validate", str(missing)],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 1 and "missing.yaml: cannot read" in done.stderr
    assert "Traceback" not in done.stderr
    done = subprocess.run([sys.executable, "-m", "whirl_cli", "--version"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stdout.startswith("whirl, version ")


def test_the_console_script_module_imports_nothing_before_it_catches_an_interrupt():
    """The generated script imports :mod:`whirl_cli.entry` before any handler is in place: a
    Ctrl-C while that import loads another module would end in a traceback. It loads only
    itself and its package (``os`` and ``sys`` are loaded with the interpreter)."""
    code = ("import sys; before = set(sys.modules); import whirl_cli.entry; "
            "print(' '.join(sorted(set(sys.modules) - before)))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60, check=True)
    assert done.stdout.split() == ["whirl_cli", "whirl_cli.entry"]
