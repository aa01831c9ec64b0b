"""Reading a result file that is not one: ``whirl plot``, ``check`` and ``compare`` given a
text file, an empty or truncated file, an HDF5 file of another program, or a whirl file with
a dataset missing exit 1 with one line ``<file>: <reason>``, never a traceback or "internal
error"."""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

from whirl_cli.cli import cli
from whirl_cli.output.store import read, write

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
    return path, "a damaged whirl result file (/continuations/k1/branches/main_down/stable: "


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


# ------------------------------------------------------------------ a whirl file not whole
BRANCH = "continuations/k1/branches/main_down"
POINTS = "continuations/k1/special_points"
SWEEP = "linear/sweeps/V"
LINEAR = ROOT / "tests" / "regression" / "references" / "linear_datum_airspeed.h5"
PERIODIC = "continuations/k1/branches/periodic_1"


@dataclass(frozen=True)
class New:
    """A committed result written again by this whirl."""

    committed: Path


NEW, NEW_LINEAR = New(REFERENCE), New(LINEAR)


def _replace(handle: h5py.File, key: str, change) -> None:
    """Dataset ``key`` replaced by ``change`` of its values, its attributes kept."""
    values, attributes = handle[key][()], dict(handle[key].attrs)
    del handle[key]
    handle[key] = change(values)
    handle[key].attrs.update(attributes)


def _strings(values: np.ndarray) -> np.ndarray:
    return np.array([str(v) for v in values.ravel()]).reshape(values.shape).astype("S")


def _delete(key: str):
    return lambda handle: handle.__delitem__(key)


def _changed(key: str, change):
    return lambda handle: _replace(handle, key, change)


def _no_attribute(key: str, name: str):
    return lambda handle: handle[key].attrs.__delitem__(name)


#: damage: (the file it is done to, the damage, the HDF5 path and the words whirl must say)
DAMAGES = {
    "branches group deleted": (REFERENCE, _delete("continuations/k1/branches"),
                               "/continuations/k1/branches", "missing"),
    "branch deleted": (REFERENCE, _delete("continuations/k1/branches/secondary_1b"),
                       f"/{POINTS}/branch", "'secondary_1b'"),
    "dataset deleted": (REFERENCE, _delete(f"{BRANCH}/state_max"), f"/{BRANCH}/state_max",
                        "missing"),
    "runs deleted": (REFERENCE, _delete("runs"), "/runs", "missing"),
    "stability as strings": (REFERENCE, _changed(f"{BRANCH}/stable", _strings),
                             f"/{BRANCH}/stable", "strings"),
    "point stability as strings": (REFERENCE, _changed(f"{POINTS}/stable", _strings),
                                   f"/{POINTS}/stable", "strings"),
    "point types as floats": (REFERENCE, _changed(f"{BRANCH}/point_type",
                                                  lambda v: v.astype(float)),
                              f"/{BRANCH}/point_type", "floats"),
    "whirl directions as numbers": (LINEAR, _changed(f"{SWEEP}/whirl",
                                                     lambda v: np.zeros(v.shape)),
                                    f"/{SWEEP}/whirl", "floats"),
    "columns not its names": (REFERENCE, _changed(f"{BRANCH}/state_min", lambda v: v[:, :3]),
                              f"/{BRANCH}/state_min", "(204, 3)"),
    "a point short": (REFERENCE, _changed(f"{BRANCH}/l2_norm", lambda v: v[1:]),
                      f"/{BRANCH}/l2_norm", "(203,)"),
    "a table column short": (REFERENCE, _changed(f"{POINTS}/label", lambda v: v[1:]),
                             f"/{POINTS}/label", "(9,)"),
    "sweep modes short": (LINEAR, _changed(f"{SWEEP}/frequency", lambda v: v[:, :2]),
                          f"/{SWEEP}/frequency", "(201, 2)"),
    "attribute missing": (REFERENCE, _no_attribute(BRANCH, "kind"), f"/{BRANCH}",
                          "attribute 'kind' missing"),
    "names missing": (REFERENCE, _no_attribute(f"{BRANCH}/parameters", "names"),
                      f"/{BRANCH}/parameters", "attribute 'names' missing"),
    # a whole group deleted reads as nothing of its kind unless the file says it held one:
    # an older file by its AUTO runs, a file of this whirl by what each group records
    "continuations deleted": (REFERENCE, _delete("continuations"), "/continuations",
                              "missing"),
    "continuations deleted, new file": (NEW, _delete("continuations"), "/continuations",
                                        "missing"),
    "a continuation deleted": (NEW_LINEAR, _delete("continuations/airspeed"),
                               "/continuations", "0 of its 1 members"),
    "orbits deleted": (NEW, _delete(f"{PERIODIC}/orbits"), f"/{PERIODIC}/orbits", "missing"),
    "an orbit deleted": (NEW, _delete(f"{PERIODIC}/orbits/9"), f"/{PERIODIC}/orbits",
                         "7 of its 8 members"),
    "cross-checks deleted": (NEW, _delete("continuations/k1/cross_checks"),
                             "/continuations/k1/cross_checks", "missing"),
    "linear sweeps deleted": (NEW_LINEAR, _delete("linear/sweeps"), "/linear/sweeps",
                              "missing"),
    "linear group deleted": (NEW_LINEAR, _delete("linear"), "/linear", "missing"),
}


def damaged(name: str, directory: Path) -> tuple[Path, str, str]:
    """A copy of a committed result in ``directory`` (as this whirl writes it, for a
    :class:`New` source) with the damage ``name`` done to it, the HDF5 path whirl must name
    and words its reason must hold."""
    source, damage, where, words = DAMAGES[name]
    path = directory / f"{name.replace(' ', '_').replace(',', '')}.h5"
    if isinstance(source, New):
        write(read(source.committed), path)
    else:
        shutil.copyfile(source, path)
    with h5py.File(path, "r+") as handle:
        damage(handle)
    return path, where, words


@pytest.mark.parametrize("command", ["plot", "summary", "check"])
@pytest.mark.parametrize("name", list(DAMAGES))
def test_a_result_file_not_whole_is_one_line_naming_what_is_wrong(tmp_path, name, command):
    bad, where, words = damaged(name, tmp_path)
    result = CliRunner().invoke(cli, [command, str(bad)])
    assert isinstance(result.exception, SystemExit), repr(result.exception)  # no exception
    assert result.exit_code == 1, result.output
    lines = result.output.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"{bad}: "), result.output
    assert f"({where}: " in lines[0] and words in lines[0], result.output
    assert [p.name for p in tmp_path.iterdir()] == [bad.name]  # no plots of half a file


def test_the_console_script_refuses_a_file_without_branches(tmp_path):
    """The reported symptom, through the real ``whirl`` executable."""
    bad, where, _ = damaged("branches group deleted", tmp_path)
    for command in ("plot", "summary", "check"):
        done = whirl(command, bad)
        assert done.returncode == 1, done
        assert done.stdout == "" and done.stderr.splitlines() == [
            f"{bad}: a damaged whirl result file ({where}: missing)"], done


@pytest.mark.parametrize("source", [REFERENCE, LINEAR,
                                    ROOT / "tests" / "data" / "legacy_hardening_case2.h5"])
def test_the_committed_results_still_read(source):
    result = read(source)
    assert result.continuations and all(len(b) for c in result.continuations
                                        for b in c.branches)
