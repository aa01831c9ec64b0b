"""What whirl may replace: only its own files, checked before anything is written.

An existing path is replaced (``--overwrite``) only if it is a regular file of the kind whirl
writes there (:class:`Own`: a whirl result file, a PNG image, an HTML page), never a symbolic
link, a directory, a device, a FIFO or a socket, nor the study file itself.
:func:`check` refuses anything else with one line saying what the path is;
:func:`refusal` is that reason (also with a directory descriptor, as
:mod:`whirl_cli.output.atomic` checks again just before it removes a name). :func:`writable`
finds an output directory that cannot take the files before any work starts.
"""

from __future__ import annotations

import errno
import os
import re
import stat
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..errors import OutputError

#: Free space below which an output directory is refused up front (bytes): what one study
#: may write, with room (the largest result files of the shipped studies, two-parameter
#: boundaries, take about 6 MB, their plots well under 1 MB). A floor, not an estimate: how
#: many points AUTO stores is known only once it has run (``max_steps`` bounds it loosely).
MINIMUM_FREE = 16 * 2**20

#: Errors of a file system without ``O_TMPFILE`` (then the permission is asked instead).
_UNSUPPORTED = frozenset({errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL})

#: What the file types other than a regular file are called in messages.
_TYPES = ((stat.S_ISLNK, "a symbolic link"), (stat.S_ISDIR, "a directory"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket"))


@dataclass(frozen=True)
class Own:
    """A kind of file whirl writes: ``noun`` names it in messages; ``recognise(fd)`` of an
    open regular file is "" if it is one, else what the file is instead."""

    noun: str
    recognise: Callable[[int], str]


def whirl_marked(fd: int) -> bool | None:
    """Whether the open HDF5 file ``fd`` has whirl's root attribute ``whirl_schema`` (a whirl
    result file); None if it is not an HDF5 file or cannot be read as one."""
    if os.pread(fd, 8, 0) != b"\x89HDF\r\n\x1a\n":
        return None
    import h5py

    try:
        with os.fdopen(os.dup(fd), "rb") as stream, h5py.File(stream, "r") as handle:
            return "whirl_schema" in handle.attrs
    except (OSError, ValueError):
        return None


def _result(fd: int) -> str:
    """"" for a whirl result file (HDF5 with the root attribute ``whirl_schema``)."""
    marked = whirl_marked(fd)
    if marked is None:
        return "a file that is not HDF5 (or a damaged one)"
    return "" if marked else "an HDF5 file without whirl's whirl_schema attribute"


def starting(what: str, *signatures: bytes, any_case: bool = True) -> Callable[[int], str]:
    """A check for :class:`Own`: the file starts with one of ``signatures`` (in any case
    unless ``any_case`` is False), else ``what``."""
    def fold(text: bytes) -> bytes:
        return text.lower() if any_case else text

    def recognise(fd: int) -> str:
        head = fold(os.pread(fd, max(len(s) for s in signatures), 0))
        return "" if any(head.startswith(fold(s)) for s in signatures) else what
    return recognise


RESULT = Own("a whirl result file", _result)
IMAGE = Own("a PNG image", starting("a file that is not PNG", b"\x89PNG\r\n\x1a\n"))
PAGE = Own("an HTML page", starting("a file that is not HTML", b"<!DOCTYPE html>"))
#: Any regular file (no check of its content).
FILE = Own("a regular file", lambda fd: "")


def refusal(path: str | os.PathLike[str], own: Own = FILE, study: str | os.PathLike[str] = "",
            dir_fd: int | None = None) -> str:
    """Why whirl must not replace ``path`` (relative to ``dir_fd`` if given): what it is
    instead of ``own``; "" if it may (absent, or a regular file ``own`` recognises)."""
    try:
        found = os.stat(path, dir_fd=dir_fd, follow_symlinks=False)
    except (FileNotFoundError, NotADirectoryError):  # nothing there
        return ""
    except OSError as error:
        return f"cannot be inspected ({error.strerror or error})"
    if study and _same(found, study):
        return "the study file itself"
    for test, name in _TYPES:
        if test(found.st_mode):
            return name
    if not stat.S_ISREG(found.st_mode):
        return "not a regular file"
    try:  # O_NONBLOCK, O_NOFOLLOW: never wait on a FIFO or follow a link swapped in meanwhile
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_NOFOLLOW | os.O_CLOEXEC,
                     dir_fd=dir_fd)
    except FileNotFoundError:
        return ""
    except OSError as error:
        return f"a file that cannot be read ({error.strerror or error})"
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return "not a regular file"
        return own.recognise(fd)
    finally:
        os.close(fd)


def _same(found: os.stat_result, other: str | os.PathLike[str]) -> bool:
    try:
        known = os.stat(other)
    except OSError:
        return False
    return (found.st_dev, found.st_ino) == (known.st_dev, known.st_ino)


def message(path: str | os.PathLike[str], reason: str, own: Own) -> str:
    """The refusal of ``path`` for ``reason`` (never an invitation to ``--overwrite``)."""
    return f"{path}: {reason}, not {own.noun}; whirl never replaces it"


def check(path: Path, own: Own, overwrite: bool, study: str | os.PathLike[str] = "") -> None:
    """Raise :class:`OutputError` unless whirl may write ``path``: it is absent, or (with
    ``overwrite``) a regular file ``own`` recognises that is not ``study``."""
    reason = refusal(path, own, study)
    if reason:
        raise OutputError(message(path, reason, own))
    if not overwrite and os.path.lexists(path):
        raise OutputError(f"{path}: output exists; pass --overwrite to replace it")


def writable(output: Path, minimum_free: int = MINIMUM_FREE) -> None:
    """Raise :class:`OutputError` if ``output``'s directory (or, if it does not exist yet,
    the directory it would be made in) cannot take new files: not a directory, no write
    permission, a read-only file system, or less than ``minimum_free`` bytes free."""
    directory = Path(os.path.abspath(output)).parent
    nearest = directory
    while not os.path.lexists(nearest) and nearest != nearest.parent:
        nearest = nearest.parent
    if not nearest.is_dir():
        raise OutputError(f"{output}: cannot create the output directory ({nearest} is not a "
                          "directory)")
    where = "the output directory" if nearest == directory else f"{nearest}"
    problem = _unwritable(nearest)
    if problem:
        raise OutputError(f"{output}: {where} is not writable ({problem})")
    try:
        space = os.statvfs(nearest)
    except OSError:
        return
    free = space.f_bavail * space.f_frsize
    if free < minimum_free:
        raise OutputError(f"{output}: only {_size(free)} free in {where}; whirl needs at "
                          f"least {_size(minimum_free)} there for a result file and its plots")


def _size(count: int) -> str:
    """A number of bytes in words: ``512 bytes``, ``12.0 KiB``, ``3.5 MiB``, ``16 MiB``."""
    if count < 1024:
        return f"{count} bytes"
    for unit, scale in (("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if count >= scale:
            value = count / scale
            return f"{value:.0f} {unit}" if value == int(value) else f"{value:.1f} {unit}"
    raise AssertionError(count)


def _unwritable(directory: Path) -> str:
    """Why no file can be made in ``directory`` ("" if one can): an unnamed file
    (``O_TMPFILE``) is made and dropped, leaving nothing; else the permission is asked."""
    try:
        fd = os.open(directory, os.O_TMPFILE | os.O_WRONLY | os.O_CLOEXEC, 0o600)
    except AttributeError:  # not Linux
        pass
    except OSError as error:
        if error.errno not in _UNSUPPORTED:
            return error.strerror or str(error)
    else:
        os.close(fd)
        return ""
    if not os.access(directory, os.W_OK | os.X_OK):
        return "permission denied"
    return ""


def ready(output: Path, overwrite: bool, study: str | os.PathLike[str] = "",
          plots: bool = False) -> None:
    """Refuse, before any work, an ``output`` result file whirl may not write:
    :func:`check` (with :data:`RESULT`, never ``study``), with ``plots`` also
    :func:`plots_ready`, and :func:`writable`."""
    check(output, RESULT, overwrite, study)
    if plots:
        plots_ready(output, study)
    writable(output)


#: What a plot's file name holds after its output's stem and ``_`` (others become ``_``).
PLOT_CHARACTERS = "A-Za-z0-9._+-"


def plot_stem(stem: str) -> str:
    """The output's stem as its plots' names begin: kept as given (letters of any script,
    spaces), but for what no file name can hold (``/``, NUL), which becomes ``_``."""
    return re.sub(r"[/\0]", "_", stem)


def plot_paths(output: Path) -> list[Path]:
    """The entries of ``output``'s directory named as its plots are (``<stem>_*.png``),
    whatever they are; none if the directory does not exist."""
    named = re.compile(re.escape(plot_stem(output.stem)) + f"_[{PLOT_CHARACTERS}]*\\.png")
    try:
        entries = os.listdir(output.parent)
    except (FileNotFoundError, NotADirectoryError):
        return []
    return [output.parent / name for name in sorted(entries) if named.fullmatch(name)]


def plots_ready(output: Path, study: str | os.PathLike[str] = "") -> None:
    """Raise :class:`OutputError` before any work if a file named as one of ``output``'s
    plots is one whirl would not replace (:func:`refusal` with :data:`IMAGE`): which plots a
    result draws is known only once it is computed, so every such name is checked."""
    for path in plot_paths(output):
        reason = refusal(path, IMAGE, study)
        if reason:
            raise OutputError(message(path, reason, IMAGE))
