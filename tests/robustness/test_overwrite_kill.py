"""SIGKILL at every step of an overwriting write (O_TMPFILE): a child process writes a result
over an existing file and kills itself just before its k-th file-system call, for every k.
Afterwards the output is the old file, the new complete file, or absent (only when killed
between removing the old file and linking the new one, the documented trade-off of
``atomic._link_unnamed``); never a partial or a temporary file."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from whirl_cli.errors import OutputError
from whirl_cli.output import atomic, store
from whirl_cli.results import Provenance, StudyResult

CHILD = textwrap.dedent("""
    import os, signal, sys
    from pathlib import Path
    from whirl_cli.output import store
    from whirl_cli.results import StudyResult

    target, calls = int(sys.argv[2]), []

    def counted(name, real):
        def call(*args, **kwargs):
            calls.append(name)
            if len(calls) == target:
                os.kill(os.getpid(), signal.SIGKILL)
            return real(*args, **kwargs)
        return call

    for name in ("open", "write", "fsync", "link", "unlink", "replace", "rename"):
        setattr(os, name, counted(name, getattr(os, name)))
    result = StudyResult(study_name="new", model="m", continuations=(), linear_sweeps=(),
                         runs=(), attributes={"study_yaml": "name: new\\n",
                                              "note": "x" * 100_000})
    store.write(result, Path(sys.argv[1]), overwrite=True)
    print(" ".join(calls))
""")


def test_sigkill_before_any_step_of_an_overwrite_leaves_old_new_or_nothing(tmp_path):
    old = tmp_path / "old.h5"  # whirl replaces only a whirl result file
    store.write(small_result("old"), old)
    outcomes, k = [], 0
    while True:
        k += 1
        directory = tmp_path / f"kill{k}"
        directory.mkdir()
        path = directory / "r.h5"
        path.write_bytes(old.read_bytes())
        done = subprocess.run([sys.executable, "-c", CHILD, str(path), str(k)],
                              capture_output=True, text=True, timeout=60)
        names = sorted(p.name for p in directory.iterdir())
        assert names in ([], ["r.h5"]), f"killed before call {k}: {names}"
        if not names:
            outcomes.append("none")
        elif path.read_bytes() == old.read_bytes():
            outcomes.append("old")
        else:
            assert store.read(path).study_name == "new"  # complete
            outcomes.append("new")
        if done.returncode == 0:  # k is past the last call: the write completed
            assert outcomes[-1] == "new"
            calls = done.stdout.split()
            break
        assert done.returncode == -9, done.stderr
    assert k == len(calls) + 1
    # old until the old file is removed, absent until the new one is linked, then new
    removal = calls.index("unlink")
    assert calls[removal + 1] == "link" and "replace" not in calls, calls
    assert outcomes == ["old"] * (removal + 1) + ["none"] + ["new"] * (k - removal - 2), \
        list(zip(calls, outcomes, strict=False))


def small_result(name: str = "mine") -> StudyResult:
    return StudyResult(study_name=name, model="m", continuations=(), linear_sweeps=(),
                       runs=(), provenance=Provenance(study_yaml=f"name: {name}\n"))


def test_an_overwrite_replaces_a_file_another_writer_links_in_between(tmp_path, monkeypatch):
    path = tmp_path / "r.h5"
    store.write(small_result("other"), path)  # whirl replaces only a whirl result file
    other = path.read_bytes()
    real_unlink, removed = os.unlink, []

    def unlink(name, *args, **kwargs):  # another writer links its file right after ours went
        real_unlink(name, *args, **kwargs)
        removed.append(name)
        if len(removed) < 3:
            path.write_bytes(other)
    monkeypatch.setattr(atomic.os, "unlink", unlink)
    store.write(small_result(), path, overwrite=True)
    assert removed == ["r.h5"] * 3
    assert store.read(path).study_name == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.h5"]

    # a writer that keeps losing the race gives up with a message, leaving the other's file
    def always(name, *args, **kwargs):
        real_unlink(name, *args, **kwargs)
        path.write_bytes(other)
    monkeypatch.setattr(atomic.os, "unlink", always)
    with pytest.raises(OutputError, match="r.h5: not replaced: other processes keep writing"):
        store.write(small_result(), path, overwrite=True)
    assert path.read_bytes() == other
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.h5"]
