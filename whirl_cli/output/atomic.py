"""Publishing a file atomically: it appears at its path complete or not at all, and no
temporary file is left behind, even by SIGKILL.

The data is written to an unnamed file in the target directory (Linux ``O_TMPFILE``) and linked
into place. Without ``overwrite`` the link fails if the path exists (also if it appeared
meanwhile); with it, the old file is removed and the new one linked in its place (see
:func:`_link_unnamed` for the trade-off). Where ``O_TMPFILE`` is unavailable a hidden named
temporary is written and renamed into place (a SIGKILL before the rename leaves it). Result
files (:func:`whirl_cli.output.store.write`) and plots are published this way.

Only a regular file of the kind being written is ever replaced or named in the way
(:mod:`whirl_cli.output.guard`, checked just before the old name is removed): never a link,
a directory, a device or a FIFO. :func:`locked` serialises whirl processes publishing into
one directory.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from ..errors import OutputError
from . import guard


def publish(data: bytes, path: Path, overwrite: bool = False, what: str = "the file",
            own: guard.Own = guard.FILE) -> Path:
    """Write ``data`` (e.g. a PNG rendered to memory) to ``path`` the way
    :func:`whirl_cli.output.store.write` writes result files: complete or not at all, no
    temporary file left even by SIGKILL. ``what`` names the file in the error message; an
    existing file is replaced only with ``overwrite`` and only if it is ``own``'s kind
    (:func:`whirl_cli.output.guard.refusal`)."""
    path = Path(path)
    try:
        _publish(data, path, overwrite, own)
    except OSError as error:
        raise OutputError(f"{path}: cannot write {what} ({error.strerror or error})") from None
    return path


@contextmanager
def locked(directory: Path) -> Iterator[None]:
    """Hold an exclusive lock (``flock``) on ``directory`` among whirl processes that publish
    into it; unlocked on a file system without such locks."""
    fd = os.open(directory, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        import fcntl

        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
        except OSError:  # no locks here (some network file systems)
            pass
        yield
    finally:
        os.close(fd)


def _publish(image: bytes, path: Path, overwrite: bool, own: guard.Own) -> None:
    """Make ``image`` the file at ``path`` in one step (see
    :func:`whirl_cli.output.store.write`)."""
    directory = os.open(path.parent, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        fd = None
        if os.path.isdir("/proc/self/fd"):  # the unnamed file is linked through /proc
            try:
                fd = os.open(path.parent, os.O_TMPFILE | os.O_WRONLY | os.O_CLOEXEC, 0o666)
            except (AttributeError, OSError):  # not Linux, or a file system without O_TMPFILE
                fd = None
        if fd is None:
            _publish_named(image, path, overwrite, directory, own)
        else:
            try:
                _write_all(fd, image)
                _link_unnamed(fd, path, overwrite, directory, own)
            finally:
                os.close(fd)
        try:
            os.fsync(directory)  # the new name survives a power cut
        except OSError:  # some file systems cannot sync a directory; the file is in place
            pass
    finally:
        os.close(directory)


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]
    os.fsync(fd)


def _in_the_way(path: Path, overwrite: bool, directory: int, own: guard.Own) -> None:
    """Raise :class:`OutputError` unless the existing file at ``path`` may be replaced (it is
    ``own``'s kind, and ``overwrite``)."""
    reason = guard.refusal(path.name, own, dir_fd=directory)
    if reason:
        raise OutputError(guard.message(path, reason, own))
    if not overwrite:
        raise OutputError(f"{path}: output exists; pass --overwrite to replace it")


#: How often an overwriting write removes a file another writer put in its place meanwhile.
_REPLACE_ATTEMPTS = 100


def _link_unnamed(fd: int, path: Path, overwrite: bool, directory: int, own: guard.Own
                  ) -> None:
    """Give the O_TMPFILE file ``fd`` the name ``path`` (linked through /proc/self/fd).

    Without ``overwrite`` the link fails if ``path`` exists. With it, an existing file is
    removed and the unnamed one linked in its place, again if another writer's file appeared
    in between; each time only if it is ``own``'s kind (:func:`_in_the_way`). A link
    cannot replace a name, and a rename needs the new file to have a name first: a named
    temporary, which SIGKILL before the rename would leave behind. The
    trade-off: for the microseconds between the unlink and the link no file is at ``path``
    (a reader may find none, and a SIGKILL exactly then leaves neither the old file nor the
    new one), but there is never a partial or a temporary file.
    """
    source = f"/proc/self/fd/{fd}"
    for _ in range(_REPLACE_ATTEMPTS):
        try:
            os.link(source, path.name, dst_dir_fd=directory, follow_symlinks=True)
            return
        except FileExistsError:
            _in_the_way(path, overwrite, directory, own)
        try:
            os.unlink(path.name, dir_fd=directory)
        except FileNotFoundError:  # another writer removed it first
            pass
    raise OutputError(f"{path}: not replaced: other processes keep writing it")


def _publish_named(image: bytes, path: Path, overwrite: bool, directory: int,
                   own: guard.Own) -> None:
    """Fallback without O_TMPFILE: a hidden temporary next to ``path``, renamed into place."""
    temporary = f".{path.name}.tmp-{os.getpid()}"
    fd = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666,
                 dir_fd=directory)
    try:
        try:
            _write_all(fd, image)
        finally:
            os.close(fd)
        if overwrite:
            reason = guard.refusal(path.name, own, dir_fd=directory)
            if reason:
                raise OutputError(guard.message(path, reason, own))
            os.replace(temporary, path.name, src_dir_fd=directory, dst_dir_fd=directory)
        else:
            try:
                os.link(temporary, path.name, src_dir_fd=directory, dst_dir_fd=directory)
            except FileExistsError:
                _in_the_way(path, overwrite, directory, own)
    finally:
        try:
            os.unlink(temporary, dir_fd=directory)
        except FileNotFoundError:
            pass

