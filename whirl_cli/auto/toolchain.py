"""The AUTO-07p toolchain: gfortran, an AUTO engine, and compiled equation files.

Equation files are compiled and linked against the runtime of one **AUTO engine**, chosen by
the environment variable ``WHIRL_AUTO_ENGINE``:

* ``debian``: Debian's package ``auto-07p`` (0.9.2), its runtime objects
  ``/usr/lib/auto-07p/lib/*.o`` (``WHIRL_AUTO_DIR`` moves the directory);
* ``bifpy``: the PyPI package ``bifpy``, which builds a current upstream AUTO-07p with gfortran
  when it is installed and ships it as ``bifpy/auto/_lib/main.o`` and ``libbifpy.a``
  (``pip install -e '.[bifpy]'``, also in ``.[dev]``).

Unset, it is ``debian`` where Debian's runtime is installed, else ``bifpy`` where that is (a
machine without Debian's package: another Linux, a container, macOS with gfortran), else
``debian`` (whose error says how to install either); :func:`engine_choice` says why.

Executables are cached under ``$WHIRL_CACHE_DIR`` (default ``~/.cache/whirl``) keyed by a hash
of the source, the engine, the compiler, the flags and the runtime files. The cache entry
appears atomically (a directory rename), so concurrent processes never see a half-written
executable.
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import importlib.util
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
#: bifpy's runtime is built without OpenMP; the equations are compiled as for Debian otherwise.
BIFPY_FFLAGS = ("-g", "-O2", "-fstack-protector-strong", "-fPIC", "-std=legacy")
INSTALL_HINT = ("install them with: sudo apt-get install auto-07p gfortran   (or: make setup); "
                "or, without Debian's package, AUTO-07p from PyPI: pip install 'bifpy>=0.3,<0.4'")
BIFPY_HINT = ("install it with: .venv/bin/pip install 'bifpy>=0.3,<0.4' (it compiles AUTO-07p "
              "with gfortran, about 20 s), or: pip install -e '.[bifpy]', or: make setup")

#: The environment variable that picks the engine, its values, and the default where neither
#: engine is installed (:func:`engine_choice`).
ENGINE_VARIABLE = "WHIRL_AUTO_ENGINE"
ENGINES = ("debian", "bifpy")
DEFAULT_ENGINE = "debian"
#: The upstream AUTO-07p commit each bifpy release vendors (its sdist's auto/UPSTREAM_COMMIT;
#: the installed package does not record it).
BIFPY_UPSTREAM = {"0.3.0": "44cc1c4"}


@dataclass(frozen=True)
class Engine:
    """An AUTO-07p runtime to link equations against.

    ``objects`` are linked after the equations' object file, in this order; ``fflags`` are
    the gfortran flags for compiling and linking; ``version`` is what ``whirl doctor`` prints and
    result files store as ``auto_version``."""

    name: str
    location: Path
    objects: tuple[Path, ...]
    fflags: tuple[str, ...]
    version: str


def engine_name() -> str:
    """The engine whirl runs (:func:`engine_choice`)."""
    return engine_choice()[0]


def engine_choice() -> tuple[str, str]:
    """(engine, why): the one ``WHIRL_AUTO_ENGINE`` asks for; unset, Debian's where it is
    installed, else bifpy's where that is, else Debian's (the module doc)."""
    given = os.environ.get(ENGINE_VARIABLE, "").strip().lower()
    if given:
        if given not in ENGINES:
            raise ToolchainError(f"{ENGINE_VARIABLE}={os.environ[ENGINE_VARIABLE]!r} is not an "
                                 f"AUTO engine; choose one of: {', '.join(ENGINES)}")
        return given, f"{ENGINE_VARIABLE}={given}"
    if any((AUTO_DIR / "lib").glob("*.o")):
        return "debian", f"Debian's auto-07p found in {AUTO_DIR}"
    try:
        bifpy_library()
    except ToolchainError:
        return DEFAULT_ENGINE, f"neither Debian's auto-07p (in {AUTO_DIR}) nor bifpy is installed"
    return "bifpy", f"Debian's auto-07p not found in {AUTO_DIR}; bifpy's AUTO-07p is installed"


def engine(name: str | None = None) -> Engine:
    """The AUTO engine ``name`` (default: :func:`engine_name`), checked to be installed."""
    name = name or engine_name()
    return _debian_engine() if name == "debian" else _bifpy_engine()


def runtime_objects() -> list[Path]:
    """Debian's AUTO runtime objects."""
    objects = sorted((AUTO_DIR / "lib").glob("*.o"))
    if not objects:
        raise ToolchainError(f"AUTO-07p runtime objects not found in {AUTO_DIR / 'lib'}; "
                             + INSTALL_HINT)
    return objects


def _debian_engine() -> Engine:
    return Engine("debian", AUTO_DIR, tuple(runtime_objects()), FFLAGS, auto_version("debian"))


def bifpy_library() -> Path:
    """The directory of bifpy's AUTO runtime (``main.o``, ``libbifpy.a``), found without
    importing bifpy."""
    try:
        spec = importlib.util.find_spec("bifpy")
    except (ImportError, ValueError):
        spec = None
    if spec is None or not spec.submodule_search_locations:
        raise ToolchainError(f"{ENGINE_VARIABLE}=bifpy: the Python package bifpy is not "
                             f"installed; " + BIFPY_HINT)
    library = Path(next(iter(spec.submodule_search_locations))) / "auto" / "_lib"
    missing = [n for n in ("main.o", "libbifpy.a") if not (library / n).is_file()]
    if missing:
        raise ToolchainError(f"{ENGINE_VARIABLE}=bifpy: {', '.join(missing)} not found in "
                             f"{library} (bifpy installed without its AUTO build?); "
                             + BIFPY_HINT)
    return library


def _bifpy_engine() -> Engine:
    library = bifpy_library()
    return Engine("bifpy", library, (library / "main.o", library / "libbifpy.a"),
                  BIFPY_FFLAGS, auto_version("bifpy"))


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


def auto_version(name: str | None = None) -> str:
    """The version of engine ``name`` (default: the chosen one): Debian's package version,
    or ``bifpy <version> (AUTO-07p <commit>)``; 'unknown' if it cannot be told."""
    return _version(name or engine_name())


@cache
def _version(name: str) -> str:
    if name == "bifpy":
        try:
            version = importlib.metadata.version("bifpy")
        except importlib.metadata.PackageNotFoundError:
            return "unknown"
        commit = BIFPY_UPSTREAM.get(version, "commit unknown to whirl")
        return f"bifpy {version} (AUTO-07p {commit})"
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
    chosen = engine()
    objects = chosen.objects
    if source_key is None:
        assert isinstance(source, str)
        source_key = hashlib.sha256(source.encode()).hexdigest()
    key = hashlib.sha256()
    for part in (source_key, chosen.name, _compiler_identity(compiler),
                 " ".join(chosen.fflags),
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
            [compiler, *chosen.fflags, "-c", f"{name}.f90", "-o", f"{name}.o"],
            [compiler, *chosen.fflags, f"{name}.o", "-o", f"{name}.exe", *map(str, objects)],
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

