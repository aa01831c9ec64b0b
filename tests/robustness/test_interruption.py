"""Atomic, lossless output and clean interruption.

* ``whirl run`` killed (SIGKILL) at seeded random moments never leaves a partial HDF5 file at
  the output path, nor a temporary file next to it, nor an AUTO process running;
* the writer itself, failing at every step (store-level fault injection), leaves the old
  file or nothing, and no temporary file, with O_TMPFILE and with the named fallback;
* an existing output is never replaced without ``--overwrite``, also when it appears while
  the study runs (byte-identical afterwards);
* SIGINT (exit 130) and SIGTERM (exit 143) stop at once without a traceback, kill the running
  AUTO processes and remove the work directory.
"""

from __future__ import annotations

import os
import random
import signal
import subprocess
import time
from pathlib import Path

import h5py
import pytest
from click.testing import CliRunner

from whirl_cli import pipeline
from whirl_cli.cli import cli
from whirl_cli.errors import OutputError
from whirl_cli.output import atomic, guard, store
from whirl_cli.results import Provenance, StudyResult

from .helpers import STUDIES, WHIRL, auto_processes, environment

SEED = 20240601
KILLS = 10


def session_cache() -> Path:
    return Path(os.environ["WHIRL_CACHE_DIR"])


def wait_for_no_auto(cache: Path, seconds: float = 120.0) -> list[int]:
    """The AUTO processes still alive once none are, or after ``seconds`` (a guard against
    a hang, not a measure: the loop ends as soon as they are gone)."""
    deadline = time.monotonic() + seconds
    while (left := auto_processes(cache)) and time.monotonic() < deadline:
        time.sleep(0.05)
    return left


def check_output_dir(directory: Path, name: str = "r.h5") -> bool:
    """The output is absent or a complete whirl file, with no temporary file (of it or of a
    plot: both are published atomically, ``atomic.publish``) and nothing else but its plots.
    Returns whether the output exists."""
    names = sorted(p.name for p in directory.iterdir()) if directory.exists() else []
    hidden = [n for n in names if n.startswith(".") or "tmp" in n]
    assert not hidden, names
    assert set(names) <= {name} | {n for n in names if n.startswith(Path(name).stem + "_")
                                   and n.endswith(".png")}, names
    if name not in names:
        return False
    with h5py.File(directory / name, "r") as handle:
        assert handle.attrs["whirl_schema"] == store.SCHEMA
    result = store.read(directory / name)  # every dataset readable
    assert result.continuations and result.runs
    return True


# ------------------------------------------------------------------------------ SIGKILL
@pytest.mark.auto
def test_sigkill_at_random_moments_never_leaves_a_partial_file(tmp_path):
    cache = session_cache()
    study = STUDIES / "linear_datum_airspeed.yaml"
    env = environment(cache, TMPDIR=str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    started = time.monotonic()
    reference = subprocess.run([str(WHIRL), "run", str(study), "-o", str(tmp_path / "ref.h5")],
                               env=env, capture_output=True, text=True, timeout=120)
    duration = time.monotonic() - started
    assert reference.returncode == 0, reference.stderr
    rng = random.Random(SEED)
    delays = sorted(rng.uniform(0, duration) for _ in range(KILLS))
    written = 0
    for k, delay in enumerate(delays):
        out = tmp_path / f"kill{k}"
        process = subprocess.Popen([str(WHIRL), "run", str(study), "-o", str(out / "r.h5")],
                                   env=env, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        time.sleep(delay)
        process.kill()
        process.wait(timeout=30)
        assert wait_for_no_auto(cache) == [], f"AUTO left running after SIGKILL at {delay:.2f} s"
        written += check_output_dir(out)
    # --overwrite over a complete older output: afterwards the old file, the new one, or
    # (killed between removing the old and linking the new) none; never a temporary
    old, overwrite_kills = (tmp_path / "ref.h5").read_bytes(), 6
    found = {"old": 0, "new": 0, "none": 0}
    for k in range(overwrite_kills):
        out = tmp_path / f"overwrite{k}"
        out.mkdir()
        (out / "r.h5").write_bytes(old)
        process = subprocess.Popen([str(WHIRL), "run", str(study), "-o", str(out / "r.h5"),
                                    "--overwrite"], env=env, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        time.sleep(rng.uniform(0, duration))
        process.kill()
        process.wait(timeout=30)
        assert wait_for_no_auto(cache) == [], "AUTO left running after SIGKILL"
        exists = check_output_dir(out)
        found["none" if not exists else "old" if (out / "r.h5").read_bytes() == old
              else "new"] += 1
    print(f"\n  {KILLS} SIGKILLs in [0, {duration:.2f}] s: {written} complete outputs, "
          f"{KILLS - written} none; {overwrite_kills} overwriting runs: {found['old']} old, "
          f"{found['new']} new, {found['none']} none; no partial HDF5 file, no temporary file of "
          "it or of a plot")


# ------------------------------------------------------------------------------ the writer
def small_result(name: str = "s") -> StudyResult:
    return StudyResult(study_name=name, model="m", continuations=(), linear_sweeps=(), runs=(),
                       attributes={"note": "x" * 100_000},
                       provenance=Provenance(study_yaml=f"name: {name}\n"))


def whirl_file(path: Path, name: str = "old") -> bytes:
    """A whirl result file at ``path`` (whirl replaces no other file); its bytes."""
    store.write(small_result(name), path)
    return path.read_bytes()


class Boom(BaseException):
    pass


def explode(*args, **kwargs):
    raise Boom


@pytest.mark.parametrize("tmpfile", [True, False], ids=["O_TMPFILE", "named"])
@pytest.mark.parametrize("step", ["write", "link", "replace", "unlink", "relink"])
@pytest.mark.parametrize("overwrite", [False, True])
def test_a_write_that_fails_at_any_step_leaves_the_old_file_or_nothing(
        tmp_path, monkeypatch, tmpfile, step, overwrite):
    """Steps: writing the data, linking it (every link), renaming it into place, removing
    the old file (O_TMPFILE with overwrite), linking again after that removal (ditto)."""
    if not tmpfile:
        monkeypatch.delattr(os, "O_TMPFILE")
    path = tmp_path / "r.h5"
    if overwrite:
        old = whirl_file(path)
    if step == "write":
        def half(fd, data):
            os.write(fd, data[:len(data) // 2])
            raise Boom
        monkeypatch.setattr(atomic, "_write_all", half)
    elif step == "link":
        monkeypatch.setattr(atomic.os, "link", explode)
    elif step == "replace":
        monkeypatch.setattr(atomic.os, "replace", explode)
    elif step == "unlink":  # the old file (temporaries may still be removed)
        real_unlink = os.unlink

        def unlink(name, *args, **kwargs):
            if name == path.name:
                raise Boom
            return real_unlink(name, *args, **kwargs)
        monkeypatch.setattr(atomic.os, "unlink", unlink)
    else:  # a link after the old file was removed: the second link of one write
        real_link, calls = os.link, []

        def link(*args, **kwargs):
            calls.append(args)
            if len(calls) > 1:
                raise Boom
            return real_link(*args, **kwargs)
        monkeypatch.setattr(atomic.os, "link", link)
    # what is at ``path`` afterwards: "old" (the write failed), "none" (it failed), "new"
    replacing = tmpfile and overwrite  # the O_TMPFILE path removes the old file, then links
    outcome = {
        "write": "old" if overwrite else "none",
        "link": "new" if overwrite and not tmpfile  # the named fallback renames instead
        else "old" if overwrite else "none",
        "replace": "old" if overwrite and not tmpfile else "new",
        "unlink": "old" if replacing else "new",
        "relink": "none" if replacing else "new",  # the trade-off of atomic._link_unnamed
    }[step]
    if outcome == "new":
        store.write(small_result(), path, overwrite=overwrite)
    else:
        with pytest.raises(Boom):
            store.write(small_result(), path, overwrite=overwrite)
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ([] if outcome == "none" else ["r.h5"]), names
    if outcome == "old":
        assert path.read_bytes() == old
    elif outcome == "new":
        assert store.read(path).study_name == "s"


@pytest.mark.parametrize("tmpfile", [True, False], ids=["O_TMPFILE", "named"])
def test_the_writer_never_replaces_a_file_without_overwrite(tmp_path, monkeypatch, tmpfile):
    if not tmpfile:
        monkeypatch.delattr(os, "O_TMPFILE")
    path = tmp_path / "r.h5"
    store.write(small_result(), path)
    assert store.read(path).attributes["note"] == "x" * 100_000
    before = path.read_bytes()
    with pytest.raises(OutputError, match="output exists; pass --overwrite"):
        store.write(small_result(), path)
    # the file appears between the check and the link (another process): still refused
    with pytest.raises(OutputError, match="output exists; pass --overwrite"):
        atomic._publish(b"other", path, False, guard.RESULT)
    assert path.read_bytes() == before
    store.write(small_result(), path, overwrite=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.h5"]
    mode = path.stat().st_mode & 0o777
    umask = os.umask(0)
    os.umask(umask)
    assert mode == 0o666 & ~umask


def test_publish_writes_bytes_the_same_way(tmp_path):
    """``atomic.publish`` (for plots rendered to memory): no-clobber unless overwrite."""
    path = atomic.publish(b"first", tmp_path / "p.png")
    with pytest.raises(OutputError, match="output exists"):
        atomic.publish(b"second", path)
    assert path.read_bytes() == b"first"
    atomic.publish(b"third", path, overwrite=True)
    assert path.read_bytes() == b"third" and [p.name for p in tmp_path.iterdir()] == ["p.png"]


def test_an_unwritable_directory_is_an_output_error(tmp_path):
    if os.geteuid() == 0:
        locked = tmp_path / "file"  # root ignores permissions: a file as the directory
        locked.write_text("")
        with pytest.raises(OutputError, match="does not exist"):
            store.write(small_result(), locked / "r.h5")
        return
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    with pytest.raises(OutputError, match="cannot write the output"):
        store.write(small_result(), locked / "r.h5")


@pytest.mark.auto
def test_whirl_run_never_overwrites_without_overwrite(tmp_path, monkeypatch):
    study = STUDIES / "linear_datum_airspeed.yaml"
    output = tmp_path / "r.h5"
    before = whirl_file(output)
    runner = CliRunner()
    refused = runner.invoke(cli, ["run", str(study), "-o", str(output)])
    assert refused.exit_code == 1 and "output exists; pass --overwrite" in refused.output
    assert output.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.h5"]

    # the file appears while the study runs (e.g. a second `whirl run`): refused at the end
    output.unlink()
    real = pipeline.run_and_draw

    def racing(*args, **kwargs):
        done = real(*args, **kwargs)
        output.write_bytes(before)
        return done

    monkeypatch.setattr(pipeline, "run_and_draw", racing)
    raced = runner.invoke(cli, ["run", str(study), "-o", str(output), "--no-plots"])
    assert raced.exit_code == 1 and "output exists; pass --overwrite" in raced.output
    assert output.read_bytes() == before
    monkeypatch.setattr(pipeline, "run_and_draw", real)

    replaced = runner.invoke(cli, ["run", str(study), "-o", str(output), "--overwrite",
                                   "--no-plots"])
    assert replaced.exit_code == 0, replaced.output
    assert check_output_dir(tmp_path)


# ------------------------------------------------------------------------------ signals
SLOW = """name: slow
model: classical
continuations:
  - {name: one, type: one-parameter, parameter: K1, start: 0.1, range: [-0.3, 0.5]}
  - {name: two, type: one-parameter, parameter: V, start: 6.7, range: [0.0, 10.0]}
auto: {max_steps: 100000000, step_initial: 1.0e-9, step_min: 1.0e-12, step_max: 1.0e-9,
       timeout: 60}
plots: []
"""


@pytest.mark.auto
@pytest.mark.parametrize(("signum", "status"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)],
                         ids=["SIGINT", "SIGTERM"])
def test_a_signal_stops_cleanly_and_kills_auto(tmp_path, signum, status):
    cache = session_cache()
    study = tmp_path / "slow.yaml"
    study.write_text(SLOW)
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    env = environment(cache, TMPDIR=str(scratch))
    process = subprocess.Popen([str(WHIRL), "run", str(study), "-o", str(tmp_path / "r.h5"),
                                "--jobs", "2"], env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    try:
        while len(auto_processes(cache)) < 2 and process.poll() is None:
            time.sleep(0.05)
        assert len(auto_processes(cache)) == 2, "whirl ended before its AUTO runs started"
        process.send_signal(signum)
        # a guard against a hang: each AUTO run would go on to its 60 s timeout and whirl
        # would then end with exit 1, so the status below says the signal stopped it
        stdout, stderr = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert process.returncode == status, (stdout, stderr)
    assert stderr.endswith("\ninterrupted\n") and "Traceback" not in stdout + stderr
    assert "\n\n" not in stderr, stderr  # no blank line before "interrupted"
    assert wait_for_no_auto(cache) == []
    assert not (tmp_path / "r.h5").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["slow.yaml", "tmp"]
    assert list(scratch.iterdir()) == [], "the work directory was not removed"


def test_interrupted_is_a_keyboard_interrupt_with_the_signal():
    from whirl_cli.runtime import Interrupted

    assert issubclass(Interrupted, KeyboardInterrupt)
    assert Interrupted(signal.SIGTERM).signum == signal.SIGTERM
    assert 128 + Interrupted().signum == 130
