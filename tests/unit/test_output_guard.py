"""whirl replaces only its own files (output.guard), in every writer that overwrites; the
output directory is checked before any work; AUTO's work directory never leaks."""

from __future__ import annotations

import os
import signal
import stat
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

from whirl_cli import api, publish
from whirl_cli.errors import OutputError
from whirl_cli.figures.build import stored_key
from whirl_cli.output import atomic, guard, store
from whirl_cli.plots.files import plot_names, save_study_plots

from ..conftest import ROOT
from ..foreign_paths import KINDS, fingerprint, make, small_result, tmpfs

LEGACY = ROOT / "tests" / "data" / "legacy_hardening_case2.h5"


@pytest.mark.parametrize("overwrite", [False, True])
@pytest.mark.parametrize("kind", KINDS)
def test_a_result_file_is_written_only_over_a_whirl_result(tmp_path, kind, overwrite):
    """Before: a device, FIFO, symlink or other program's file was removed by an overwriting
    write, and the refusal without --overwrite invited exactly that."""
    path = tmp_path / "out" / "r.h5"
    path.parent.mkdir()
    words = make(kind, path)
    before = fingerprint(path)
    with pytest.raises(OutputError) as refused:
        store.write(small_result(), path, overwrite=overwrite)
    assert words in str(refused.value) and "--overwrite" not in str(refused.value)
    assert fingerprint(path) == before
    with pytest.raises(OutputError):
        guard.ready(path, overwrite)


@pytest.mark.parametrize("kind", ["device", "fifo", "directory", "symlink", "text"])
def test_a_plot_is_written_only_over_a_png(tmp_path, kind):
    """The same guard in every writer that replaces files: publish_study, whirl plot, and
    atomic.publish itself (figures and the index)."""
    result = store.read(LEGACY)
    name = plot_names(result, ("bifurcation",), "r")[0]
    target = tmp_path / name
    make(kind, target)
    before = fingerprint(target)
    for write in (lambda: save_study_plots(result, ("bifurcation",), tmp_path, "r"),
                  lambda: atomic.publish(b"\x89PNG\r\n\x1a\n", target, True, own=guard.IMAGE),
                  lambda: atomic.publish(b"<!DOCTYPE html>", target, True, own=guard.PAGE),
                  lambda: publish.publish_study(small_result(), tmp_path / "r.h5", (),
                                                    True, drawn=publish.Drawn(
                                                        ((name, b"\x89PNG\r\n\x1a\n"),)))):
        with pytest.raises(OutputError, match="whirl never replaces it"):
            write()
        assert fingerprint(target) == before
    assert not (tmp_path / "r.h5").exists()


def test_whirls_own_files_are_still_replaced(tmp_path):
    path = tmp_path / "r.h5"
    store.write(small_result("old"), path)
    with pytest.raises(OutputError, match="output exists; pass --overwrite"):
        store.write(small_result("new"), path)
    store.write(small_result("new"), path, overwrite=True)
    assert store.read(path).study_name == "new"
    png = tmp_path / "a.png"
    png.write_bytes(b"\x89PNG\r\n\x1a\nold")
    atomic.publish(b"\x89PNG\r\n\x1a\nnew", png, True, own=guard.IMAGE)
    assert png.read_bytes().endswith(b"new")


def test_the_study_file_itself_is_refused(tmp_path):
    study = tmp_path / "same.yaml"
    study.write_text("name: same\n")
    for overwrite in (False, True):
        with pytest.raises(OutputError, match="same.yaml: the study file itself") as refused:
            guard.ready(study, overwrite, study)
        assert "--overwrite" not in str(refused.value)
    assert study.read_text() == "name: same\n"


def test_recorded_plots_outside_the_folder_are_never_removed(tmp_path):
    """A result file recording ``../victim.png`` (or an absolute path) as its plot: the
    overwriting publish removes only plain names in its own folder, and only PNG files."""
    out = tmp_path / "out"
    out.mkdir()
    victim = tmp_path / "victim.png"
    victim.write_bytes(b"\x89PNG\r\n\x1a\nsomeone's")
    (out / "notes.png").write_text("not a PNG")
    store.write(small_result("old", ("../victim.png", str(victim), "notes.png")), out / "r.h5")
    publish.publish_study(small_result("new"), out / "r.h5", (), overwrite=True)
    assert victim.read_bytes() == b"\x89PNG\r\n\x1a\nsomeone's"
    assert (out / "notes.png").read_text() == "not a PNG"
    assert store.read(out / "r.h5").study_name == "new"


def test_a_figure_key_is_not_read_from_a_fifo(tmp_path):
    """Before: ``whirl figures`` waited for ever on a FIFO where a figure's PNG goes."""
    fifo = tmp_path / "fig1.png"
    os.mkfifo(fifo)
    found = []
    reader = threading.Thread(target=lambda: found.append(stored_key(fifo)), daemon=True)
    reader.start()
    reader.join(30)
    if reader.is_alive():  # unblock the reader before failing
        os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
    assert found == [None]


def test_plot_names_keep_the_stem(tmp_path):
    """Before: ``-o "o/résultat 1.h5"`` wrote ``r_sultat_1_...``."""
    result = store.read(LEGACY)
    names = plot_names(result, ("bifurcation", "period"), "résultat 1")
    assert names and all(name.startswith("résultat 1_") for name in names)


# --------------------------------------------------------------------- the output directory
def test_an_unwritable_or_full_directory_is_found_up_front(tmp_path, monkeypatch):
    path = tmp_path / "new" / "deeper" / "r.h5"
    guard.writable(path)  # the nearest existing folder takes files
    assert not (tmp_path / "new").exists()  # and nothing was made
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(OutputError, match="is not a directory"):
        guard.writable(blocker / "r.h5")

    class Full:
        f_bavail, f_frsize = 3, 4096

    monkeypatch.setattr(guard.os, "statvfs", lambda path: Full)
    with pytest.raises(OutputError) as refused:
        guard.writable(path)
    # what is free and what is needed, in numbers that say it (not "0.0 MiB")
    assert str(refused.value) == (f"{path}: only 12 KiB free in {tmp_path}; whirl needs at "
                                  "least 16 MiB there for a result file and its plots")


def test_a_read_only_file_system_is_found_up_front(tmp_path):
    with tmpfs(tmp_path / "ro", "ro,size=64m") as mount:
        for path in (mount / "r.h5", mount / "sub" / "r.h5"):
            with pytest.raises(OutputError, match="not writable .Read-only file system"):
                guard.writable(path)


def test_the_output_directory_is_made_only_when_published(tmp_path, monkeypatch):
    out = tmp_path / "a" / "b" / "r.h5"

    def full(*args, **kwargs):
        raise OutputError("disk full")

    with monkeypatch.context() as patch:
        patch.setattr(store, "write", full)
        with pytest.raises(OutputError, match="disk full"):  # nothing left behind
            publish.publish_study(small_result(), out, ())
    assert os.listdir(tmp_path) == []
    publish.publish_study(small_result(), out, ())
    assert store.read(out).study_name == "mine"


# --------------------------------------------------------------------- AUTO's work directory
def test_an_interrupt_while_the_work_directory_is_made_removes_it(tmp_path, monkeypatch):
    """Before: the held interrupt was raised before the clean-up block began: the directory
    stayed (once in 64 Ctrl-C)."""
    import tempfile

    made, real = [], tempfile.mkdtemp

    def mkdtemp(*args, **kwargs):
        made.append(real(*args, dir=tmp_path, **{k: v for k, v in kwargs.items()
                                                 if k != "dir"}))
        os.kill(os.getpid(), signal.SIGINT)  # arrives while held
        return made[-1]

    monkeypatch.setattr(tempfile, "mkdtemp", mkdtemp)
    study = api.load(ROOT / "studies" / "thesis_ch3" / "linear_case2.yaml")
    with pytest.raises(KeyboardInterrupt), api._workroot(study, None):
        pytest.fail("the interrupt is raised before the work starts")
    assert made and os.listdir(tmp_path) == []


def test_an_unknown_engine_makes_nothing(tmp_path, monkeypatch):
    from whirl_cli.errors import ToolchainError

    monkeypatch.setenv("WHIRL_AUTO_ENGINE", "zzz")
    study = api.load(ROOT / "studies" / "thesis_ch3" / "linear_case2.yaml")
    with pytest.raises(ToolchainError), api._workroot(study, tmp_path / "runs"):
        pass
    assert not (tmp_path / "runs").exists()


# --------------------------------------------------------------------- concurrent publishers
PUBLISHER = textwrap.dedent("""
    import sys, time
    from pathlib import Path
    from whirl_cli import publish
    from whirl_cli.results import StudyResult

    output, name, pause = Path(sys.argv[1]), sys.argv[2], sys.argv[3] == "pause"
    real = publish.recorded_plots

    def recorded_then_wait(path):  # the old file's plots are known: wait for the test
        found = real(path)
        (output.parent.parent / "ready").touch()
        while not (output.parent.parent / "go").exists():
            time.sleep(0.01)
        return found

    if pause:
        publish.recorded_plots = recorded_then_wait
    result = StudyResult(study_name=name, model="m", continuations=(), linear_sweeps=(),
                         runs=(), attributes={"study_yaml": f"name: {name}\\n"})
    publish.publish_study(result, output, (), overwrite=True, drawn=publish.Drawn(
        ((f"r_{name}.png", b"\\x89PNG\\r\\n\\x1a\\n" + name.encode()),)))
""")


def waiting_for_a_lock(pid: int) -> bool:
    """``pid`` waits for a file lock (a ``->`` line of /proc/locks)."""
    return any(line.split()[1] == "->" and line.split()[5] == str(pid)
               for line in Path("/proc/locks").read_text().splitlines()
               if len(line.split()) > 5)


def test_two_overwriting_publishers_leave_one_consistent_set(tmp_path):
    """Before: one publisher read the old file's plots, another then published its own set,
    and the first removed only the old plots: the other study's plots stayed beside its
    result. Now the one published last removes the plots of the result it replaced."""
    out = tmp_path / "out"
    out.mkdir()
    publish.publish_study(small_result("old"), out / "r.h5", (), drawn=publish.Drawn(
        (("r_old.png", b"\x89PNG\r\n\x1a\nold"),)))
    first = subprocess.Popen([sys.executable, "-c", PUBLISHER, str(out / "r.h5"), "a",
                              "pause"])
    try:
        deadline = time.monotonic() + 60  # against a hang only
        while not (tmp_path / "ready").exists() and first.poll() is None:
            assert time.monotonic() < deadline
            time.sleep(0.01)
        second = subprocess.Popen([sys.executable, "-c", PUBLISHER, str(out / "r.h5"), "b",
                                   "run"])
        while second.poll() is None and not waiting_for_a_lock(second.pid):
            assert time.monotonic() < deadline
            time.sleep(0.01)
    finally:
        (tmp_path / "go").touch()
    assert first.wait(60) == 0 and second.wait(60) == 0
    plots = sorted(p.name for p in out.glob("*.png"))
    assert plots == list(publish.recorded_plots(out / "r.h5")), plots


@pytest.mark.parametrize("kind", ["text", "fifo", "directory"])
@pytest.mark.parametrize("name", ["linear-case2.h5", "linear-case2_k1_bifurcation.png"])
def test_a_sweep_refuses_a_foreign_output_path_before_any_work(tmp_path, kind, name):
    """``whirl sweep`` checks every file it would write before it starts, result files and
    plots (``<study>_*.png``): another program's file (here a text file, a FIFO, a directory)
    at one of them stops it with a reason, nothing else is written and the path is left as
    it was."""
    studies = tmp_path / "studies"
    studies.mkdir()
    (studies / "a.yaml").write_text((ROOT / "studies" / "thesis_ch3" / "linear_case2.yaml")
                                    .read_text())
    results = tmp_path / "results"
    results.mkdir()
    target = results / name
    if kind == "text":
        target.write_text("mine")
    elif kind == "fifo":
        os.mkfifo(target)
    else:
        target.mkdir()
    done = subprocess.run([str(Path(sys.executable).with_name("whirl")), "sweep", str(studies),
                           "-o", str(results)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 1, done.stderr
    assert f"{target}: " in done.stderr and "whirl never replaces it" in done.stderr
    assert "Traceback" not in done.stderr and "start" not in done.stderr
    assert sorted(p.name for p in results.iterdir()) == [name]
    if kind == "text":
        assert target.read_text() == "mine"
    else:
        assert stat.S_ISFIFO(target.lstat().st_mode) if kind == "fifo" else target.is_dir()


# ------------------------------------------------------------ plots of two results colliding
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("order", ["shorter stem first", "longer stem first"])
def test_a_plot_another_result_recorded_is_never_replaced(tmp_path, order):
    """Study ``a`` with continuation ``b_c`` and study ``a_b`` with continuation ``c`` both
    draw ``a_b_c_bifurcation.png``: whichever is published second is refused (with or
    without --overwrite), the first one's plot and files are left as they were."""
    name = "a_b_c_bifurcation.png"
    first, second = ("a", "a_b") if order == "shorter stem first" else ("a_b", "a")
    publish.publish_study(small_result(first), tmp_path / f"{first}.h5", (),
                              drawn=publish.Drawn(((name, PNG + b"first"),)))
    before = sorted(os.listdir(tmp_path)), (tmp_path / name).read_bytes()
    for overwrite in (False, True):
        with pytest.raises(OutputError) as refused:
            publish.publish_study(small_result(second), tmp_path / f"{second}.h5", (),
                                      overwrite, drawn=publish.Drawn(
                                          ((name, PNG + b"second"),)))
        assert str(refused.value) == (f"{tmp_path / name}: a plot of {tmp_path / first}.h5, "
                                      f"not of {tmp_path / second}.h5; whirl never "
                                      "replaces it")
        assert (sorted(os.listdir(tmp_path)), (tmp_path / name).read_bytes()) == before


def test_whirl_plot_does_not_replace_a_plot_another_result_recorded(tmp_path):
    """``whirl plot x.h5`` (continuation k1) draws ``x_k1_bifurcation.png``, which the
    result ``x_k1.h5`` beside it recorded as its own."""
    result = tmp_path / "x.h5"
    result.write_bytes(LEGACY.read_bytes())
    name = "x_k1_bifurcation.png"
    publish.publish_study(small_result("other"), tmp_path / "x_k1.h5", (),
                              drawn=publish.Drawn(((name, PNG + b"other"),)))
    with pytest.raises(OutputError, match=f"a plot of {tmp_path / 'x_k1.h5'}"):
        save_study_plots(store.read(result), ("bifurcation",), tmp_path, "x",
                         result_file=result)
    assert (tmp_path / name).read_bytes() == PNG + b"other"
    # its own plots are still replaced
    save_study_plots(store.read(result), ("bifurcation",), tmp_path / "own", "x",
                     result_file=result)
    save_study_plots(store.read(result), ("bifurcation",), tmp_path / "own", "x",
                     result_file=result)
