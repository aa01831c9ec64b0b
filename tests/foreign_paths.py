"""Paths that are not whirl's (devices, FIFOs, directories, symbolic links, foreign files),
made for the tests that check whirl never writes over them."""

from __future__ import annotations

import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import h5py
import pytest

from whirl_cli.output import store
from whirl_cli.results import Provenance, StudyResult


def small_result(name: str = "mine", plots: tuple[str, ...] = ()) -> StudyResult:
    return StudyResult(study_name=name, model="m", continuations=(), linear_sweeps=(),
                       runs=(), attributes={"plots": list(plots)},
                       provenance=Provenance(study_yaml=f"name: {name}\n"))


def fingerprint(path: Path) -> tuple:
    """What must not change of a path whirl refuses: its type, device number, target, bytes."""
    found = os.lstat(path)
    content = None
    if stat.S_ISLNK(found.st_mode):
        content = os.readlink(path)
    elif stat.S_ISREG(found.st_mode):
        content = path.read_bytes()
    elif stat.S_ISDIR(found.st_mode):
        content = sorted(os.listdir(path))
    return stat.S_IFMT(found.st_mode), found.st_rdev, found.st_ino, content


def make(kind: str, path: Path) -> str:
    """A path of ``kind`` that is not whirl's; the words its refusal must hold."""
    if kind == "device":
        os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, 3))  # as /dev/null
        return "a character device"
    if kind == "fifo":
        os.mkfifo(path)
        return "a FIFO"
    if kind == "directory":
        path.mkdir()
        (path / "inside").write_text("kept")
        return "a directory"
    if kind == "symlink":
        outside = path.parent / "elsewhere" / "outside.h5"
        outside.parent.mkdir()
        store.write(small_result("outside"), outside)  # even a whirl result
        path.symlink_to(outside)
        return "a symbolic link"
    if kind == "dangling":
        path.symlink_to(path.parent / "nowhere")
        return "a symbolic link"
    if kind == "text":
        path.write_text("someone's notes\n")
        return "not HDF5"
    if kind == "hdf5":
        with h5py.File(path, "w") as handle:
            handle["data"] = [1.0, 2.0]
        return "an HDF5 file without whirl's whirl_schema attribute"
    raise AssertionError(kind)


KINDS = ["device", "fifo", "directory", "symlink", "dangling", "text", "hdf5"]


@contextmanager
def tmpfs(mount: Path, options: str) -> Iterator[Path]:
    """A tmpfs mounted at the new folder ``mount`` with ``options`` (e.g. "ro,size=64m" for a
    read-only file system, "size=1m" for a full one), unmounted afterwards; the test is
    skipped where it cannot be mounted (not root)."""
    mount.mkdir()
    if os.geteuid() != 0 or os.system(f"mount -t tmpfs -o {options} tmpfs {mount}") != 0:
        pytest.skip("needs root and mount")
    try:
        yield mount
    finally:
        os.system(f"umount {mount}")
