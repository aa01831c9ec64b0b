"""The AUTO-07p toolchain: gfortran, Debian's AUTO runtime, and compiled equation files.

Equation files are compiled and linked against Debian's AUTO runtime objects
(``/usr/lib/auto-07p/lib/*.o``) once per source text: executables are cached under
``$WHIRL_CACHE_DIR`` (default ``~/.cache/whirl``) keyed by a hash of the source, the compiler,
the flags and the runtime objects. The cache entry appears atomically (a directory rename), so
concurrent processes never see a half-written executable.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from ..cache import cache_dir
from ..errors import ToolchainError

AUTO_DIR = Path(os.environ.get("WHIRL_AUTO_DIR", "/usr/lib/auto-07p"))
#: The flags of Debian's ``cmds/cmds.make`` (minus the build-path mapping).
FFLAGS = ("-g", "-O2", "-fstack-protector-strong", "-fPIC", "-std=legacy", "-fopenmp")
INSTALL_HINT = "install them with: sudo apt-get install auto-07p gfortran   (or: make setup)"


def runtime_objects() -> list[Path]:
    objects = sorted((AUTO_DIR / "lib").glob("*.o"))
    if not objects:
        raise ToolchainError(f"AUTO-07p runtime objects not found in {AUTO_DIR / 'lib'}; "
                             + INSTALL_HINT)
    return objects


def gfortran() -> str:
    path = shutil.which("gfortran")
    if not path:
        raise ToolchainError("gfortran (needed to compile AUTO equation files) is not installed; "
                             + INSTALL_HINT)
    return path


@cache
def _compiler_identity(compiler: str) -> str:
    out = subprocess.run([compiler, "--version"], capture_output=True, text=True, check=False)
    return out.stdout.splitlines()[0] if out.stdout else compiler


@cache
def auto_version() -> str:
    """The installed AUTO-07p package version (Debian), or 'unknown'."""
    try:
        out = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "auto-07p"],
                             capture_output=True, text=True, check=False, timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return "unknown"
    return out.stdout.strip() or "unknown"


@dataclass(frozen=True)
class Executable:
    """A compiled AUTO program for one equation source."""

    path: Path
    source_hash: str
    compiled: bool  # True if this call compiled it, False if it came from the cache


def compile_equations(source: str | Callable[[], str], name: str,
                      source_key: str | None = None) -> Executable:
    """Compile and link a free-form .f90 source once; later calls reuse the cached program.

    ``source`` may be a function producing the text, called only on a cache miss; then
    ``source_key`` must identify the text it would produce.
    """
    compiler = gfortran()
    objects = runtime_objects()
    if source_key is None:
        assert isinstance(source, str)
        source_key = hashlib.sha256(source.encode()).hexdigest()
    key = hashlib.sha256()
    for part in (source_key, _compiler_identity(compiler), " ".join(FFLAGS),
                 *(f"{o.name}:{o.stat().st_size}:{o.stat().st_mtime_ns}" for o in objects)):
        key.update(part.encode())
        key.update(b"\0")
    digest = key.hexdigest()[:24]
    final = cache_dir() / "exe" / f"{name}-{digest}"
    exe = final / f"{name}.exe"
    if exe.exists():
        return Executable(exe, digest, compiled=False)
    final.parent.mkdir(parents=True, exist_ok=True)
    _remove_stale_builds(final.parent)
    build = Path(tempfile.mkdtemp(prefix=f".{name}-", dir=final.parent))
    try:
        (build / f"{name}.f90").write_text(source if isinstance(source, str) else source())
        for command in (
            [compiler, *FFLAGS, "-c", f"{name}.f90", "-o", f"{name}.o"],
            [compiler, *FFLAGS, f"{name}.o", "-o", f"{name}.exe", *map(str, objects)],
        ):
            done = subprocess.run(command, cwd=build, capture_output=True, text=True, check=False)
            if done.returncode != 0:
                raise ToolchainError(f"compiling {name}.f90 failed ({command[0]} exit "
                                     f"{done.returncode}):\n{done.stderr.strip()[-2000:]}")
        try:
            build.rename(final)  # atomic: another process may have won the race
        except OSError:
            if not exe.exists():
                raise
        return Executable(exe, digest, compiled=True)
    finally:
        shutil.rmtree(build, ignore_errors=True)


def _remove_stale_builds(root: Path, age: float = 3600.0) -> None:
    """Remove build directories (``.<name>-*``) left by a compile that was killed."""
    now = time.time()
    for build in root.glob(".*-*"):
        try:
            if build.is_dir() and now - build.stat().st_mtime > age:
                shutil.rmtree(build, ignore_errors=True)
        except OSError:
            pass

