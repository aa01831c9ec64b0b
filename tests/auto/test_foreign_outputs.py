"""``whirl run`` replaces only whirl's own files, and finds an output it cannot write before
any AUTO run (the real CLI and AUTO; paths that are not whirl's made in a tmp_path)."""

from __future__ import annotations

import os
import stat

import pytest
from click.testing import CliRunner

from whirl_cli import publish
from whirl_cli.cli import cli
from whirl_cli.output import store

from ..conftest import STUDIES
from ..foreign_paths import KINDS, fingerprint, make, tmpfs

AIRSPEED = STUDIES / "linear_datum_airspeed.yaml"  # plots: bifurcation, linear


def run(*args, env=None):
    return CliRunner().invoke(cli, ["run", *map(str, args)], env=env)


def refused_before_work(done, words: str) -> None:
    """Exit 1 with ``words`` in a message that does not invite --overwrite, no AUTO run."""
    assert done.exit_code == 1, done.output
    message = done.output.strip().splitlines()[-1]
    assert words in message and "--overwrite" not in message, done.output
    assert " points " not in done.output  # no AUTO run reported


@pytest.mark.parametrize("overwrite", [(), ("--overwrite",)])
@pytest.mark.parametrize("kind", KINDS)
def test_run_refuses_what_is_not_whirls(tmp_path, kind, overwrite):
    """Before: ``-o nulldev --overwrite`` replaced a character device with an HDF5 file, and
    the refusal without --overwrite invited exactly that."""
    target = tmp_path / "out" / "r.h5"
    target.parent.mkdir()
    words = make(kind, target)
    before = fingerprint(target)
    done = run(AIRSPEED, "-o", target, *overwrite)
    if kind == "directory":  # refused by -o itself
        words = "is a directory"
    refused_before_work(done, words)
    assert fingerprint(target) == before
    assert sorted(os.listdir(target.parent)) == sorted(
        ["r.h5"] + (["elsewhere"] if kind == "symlink" else []))


#: What a plot path that is not whirl's is called where the result file's words differ.
PLOT_WORDS = {"text": "a file that is not PNG", "hdf5": "a file that is not PNG"}


@pytest.mark.parametrize("overwrite", [(), ("--overwrite",)])
@pytest.mark.parametrize("kind", KINDS)
def test_run_refuses_a_plot_path_that_is_not_whirls_before_any_work(tmp_path, kind,
                                                                    overwrite):
    """Before: a plot path was checked only when the plots were published, after every AUTO
    run."""
    plot = tmp_path / "r_airspeed_bifurcation.png"
    words = PLOT_WORDS.get(kind, make(kind, plot))
    before = fingerprint(plot)
    done = run(AIRSPEED, "-o", tmp_path / "r.h5", *overwrite)
    refused_before_work(done, words)
    assert f"{plot}: " in done.output and "not a PNG image" in done.output
    assert fingerprint(plot) == before
    assert sorted(os.listdir(tmp_path)) == sorted(
        [plot.name] + (["elsewhere"] if kind == "symlink" else []))


def test_run_refuses_to_write_over_its_study(tmp_path):
    study = tmp_path / "same.yaml"
    study.write_text(AIRSPEED.read_text())
    before = fingerprint(study)
    for overwrite in ((), ("--overwrite",)):
        refused_before_work(run(study, "-o", study, *overwrite), "the study file itself")
    assert fingerprint(study) == before
    assert os.listdir(tmp_path) == ["same.yaml"]


def test_a_whirl_result_is_still_replaced_but_not_a_plot_that_is_not_a_file(tmp_path):
    output = tmp_path / "r.h5"
    assert run(AIRSPEED, "-o", output).exit_code == 0
    first = os.stat(output).st_ino
    assert run(AIRSPEED, "-o", output, "--overwrite").exit_code == 0
    assert os.stat(output).st_ino != first and store.read(output).continuations
    plot = tmp_path / "r_linear_V.png"
    plot.unlink()
    os.mkfifo(plot)
    kept = output.read_bytes()
    done = run(AIRSPEED, "-o", output, "--overwrite")
    assert done.exit_code == 1
    assert f"{plot}: a FIFO (named pipe), not a PNG image; whirl never replaces it" \
        in done.output
    assert stat.S_ISFIFO(os.lstat(plot).st_mode) and output.read_bytes() == kept


def test_an_unknown_engine_leaves_no_output_directory(tmp_path):
    """Before: the output directory was made before the engine was known to be wrong."""
    done = run(AIRSPEED, "-o", tmp_path / "new" / "r.h5", env={"WHIRL_AUTO_ENGINE": "zzz"})
    assert done.exit_code == 1 and "WHIRL_AUTO_ENGINE='zzz'" in done.output
    assert os.listdir(tmp_path) == []


def test_a_read_only_output_is_found_before_any_work(tmp_path):
    """Before: a read-only file system was found after every AUTO run."""
    with tmpfs(tmp_path / "ro", "ro,size=64m") as mount:
        refused_before_work(run(AIRSPEED, "-o", mount / "r.h5"), "Read-only file system")


def test_a_full_output_is_found_before_any_work(tmp_path):
    with tmpfs(tmp_path / "full", "size=1m") as mount:
        refused_before_work(run(AIRSPEED, "-o", mount / "r.h5"), "MiB free")
        assert os.listdir(mount) == []


def test_plots_keep_the_output_stem(tmp_path):
    """Before: ``-o "o/résultat 1.h5"`` wrote ``o/r_sultat_1_...png``."""
    output = tmp_path / "o" / "résultat 1.h5"
    assert run(AIRSPEED, "-o", output).exit_code == 0
    assert sorted(os.listdir(output.parent)) == [
        "résultat 1.h5", "résultat 1_airspeed_bifurcation.png", "résultat 1_linear_V.png"]
    assert publish.recorded_plots(output) == ("résultat 1_airspeed_bifurcation.png",
                                                  "résultat 1_linear_V.png")
