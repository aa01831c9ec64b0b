"""Reading a result file that is not one: ``whirl plot``, ``check`` and ``compare`` given a
text file, an empty or truncated file, an HDF5 file of another program, or a whirl file with
a dataset missing exit 1 with one line ``<file>: <reason>``, never a traceback or "internal
error"."""

from __future__ import annotations

import shutil
from pathlib import Path

import h5py
import pytest
from click.testing import CliRunner

from whirl_cli.cli import cli

from .helpers import ROOT, whirl

REFERENCE = ROOT / "tests" / "regression" / "references" / "hardening_case2.h5"


def make_bad(kind: str, directory: Path) -> tuple[Path, str]:
    """A bad result file of ``kind`` in ``directory`` and the reason whirl must give."""
    if kind == "yaml":
        path = directory / "study.yaml"
        path.write_text("name: x\nmodel: classical\n")
        return path, "not an HDF5 file"
    if kind == "empty":
        path = directory / "empty.h5"
        path.write_bytes(b"")
        return path, "not an HDF5 file"
    if kind == "truncated":
        path = directory / "truncated.h5"
        data = REFERENCE.read_bytes()
        path.write_bytes(data[:len(data) // 3])
        return path, f"truncated HDF5 file ({len(data) // 3} of its {len(data)} bytes)"
    if kind == "foreign":
        path = directory / "foreign.h5"
        with h5py.File(path, "w") as handle:
            handle["x"] = [1.0, 2.0]
        return path, "an HDF5 file but not a whirl result file (no whirl_schema attribute)"
    assert kind == "damaged"
    path = directory / "damaged.h5"
    shutil.copyfile(REFERENCE, path)
    with h5py.File(path, "r+") as handle:
        del handle["continuations/k1/branches/main_down/stable"]
    return path, "not a complete whirl result file ("


KINDS = ["yaml", "empty", "truncated", "foreign", "damaged"]
COMMANDS = ["plot", "check", "compare-a", "compare-b"]


def arguments(command: str, bad: Path, good: Path) -> list[str]:
    if command == "compare-a":
        return ["compare", str(bad), str(good)]
    if command == "compare-b":
        return ["compare", str(good), str(bad)]
    return [command, str(bad)]


@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("kind", KINDS)
def test_a_file_that_is_not_a_result_is_one_clean_line(tmp_path, kind, command):
    bad, reason = make_bad(kind, tmp_path)
    good = tmp_path / "good.h5"
    shutil.copyfile(REFERENCE, good)
    result = CliRunner().invoke(cli, arguments(command, bad, good))
    assert isinstance(result.exception, SystemExit), repr(result.exception)  # no exception
    assert result.exit_code == 1
    lines = result.output.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"{bad}: {reason}"), result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([bad.name, good.name])


def test_the_console_script_names_the_file_and_the_reason(tmp_path):
    """The reported symptom, through the real ``whirl`` executable (its ``main``)."""
    study = tmp_path / "x.yaml"
    study.write_text("name: x\n")
    for args in (["plot", study], ["check", study], ["compare", REFERENCE, study]):
        done = whirl(*args)
        assert done.returncode == 1, done
        assert done.stdout == "" and done.stderr == f"{study}: not an HDF5 file\n", done


def test_plot_into_a_directory_that_cannot_be_made_is_one_line(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    result = CliRunner().invoke(cli, ["plot", str(REFERENCE), "-o", str(blocker / "plots")])
    assert isinstance(result.exception, SystemExit) and result.exit_code == 1
    assert result.output == f"{blocker / 'plots'}: cannot create the output directory " \
        "(Not a directory)\n"
