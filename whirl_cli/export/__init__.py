"""A result file's contents in the formats other tools read: MATLAB/Octave (``.mat``),
NetCDF (``.nc``, for xarray and the NetCDF tools) and CSV (``.csv``), chosen by the output's
suffix (:data:`FORMATS`). ``whirl export`` and :func:`whirl_cli.api.export` call
:func:`export`.

Every file is made in memory first; then, with the output directory locked and interrupts
held, each is published complete or not at all (:func:`whirl_cli.output.atomic.publish`),
nothing is written unless every file may be (an existing file only with ``overwrite``, and
only if it is the kind of file this format writes), and if one cannot be written the ones
already written are removed again.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path

from ..errors import OutputError
from ..output.guard import Own, check, starting, whirl_marked
from ..results import StudyResult
from . import csvfiles, matlab, netcdf


@dataclass(frozen=True)
class Format:
    """An export format: its ``suffix``, what it is, the files it writes for a result
    (``files(result, output, branches)``: pairs of a path and a function making its
    content), the kind of file it may replace (``own``), and whether it writes each branch
    to a file of its own on request (``branch_files``; otherwise all are in the one file)."""

    suffix: str
    description: str
    files: Callable[[StudyResult, Path, bool], list[tuple[Path, Callable[[], bytes]]]]
    own: Own
    branch_files: bool = False


def _netcdf(fd: int) -> str:
    """"" for a NetCDF-4 file that is not a whirl result file (HDF5 without whirl's
    ``whirl_schema`` attribute)."""
    marked = whirl_marked(fd)
    if marked is None:
        return "a file that is not NetCDF-4 (or a damaged one)"
    return "a whirl result file" if marked else ""


#: Why a file of another kind is not replaced.
OTHER = "another kind of file"

FORMATS: dict[str, Format] = {f.suffix: f for f in (
    Format(".mat", "MATLAB/Octave MAT-file (version 5)",
           lambda result, output, _: [(output, partial(matlab.render, result))],
           Own("a MAT-file", starting(OTHER, b"MATLAB 5.0 MAT-file", any_case=False))),
    Format(".nc", "NetCDF-4 (xarray, groups as in the HDF5 file)",
           lambda result, output, _: [(output, partial(netcdf.render, result))],
           Own("a NetCDF-4 file", _netcdf)),
    Format(".csv", "CSV: the special points; with branches, one file per branch",
           csvfiles.files,
           Own("a CSV file whirl wrote", starting(OTHER, b"continuation,branch,type,",
                                                  csvfiles.BRANCH_HEADER.encode(),
                                                  any_case=False)),
           branch_files=True),
)}


def format_of(output: Path) -> Format:
    """The format of ``output``'s suffix; :class:`OutputError` for another suffix."""
    found = FORMATS.get(output.suffix.lower())
    if found is None:
        known = ", ".join(FORMATS)
        got = f"the suffix {output.suffix!r}" if output.suffix else "no suffix"
        raise OutputError(f"{output}: {got}; the output's suffix chooses the format, one "
                          f"of {known}")
    return found


def export(result: StudyResult, output: str | os.PathLike[str], branches: bool = False,
           overwrite: bool = False) -> tuple[Path, ...]:
    """Write ``result`` to ``output`` in the format of its suffix (:data:`FORMATS`), and
    for CSV with ``branches`` each branch to a file beside it; the paths written."""
    from ..output import atomic
    from ..runtime import held_signals

    output = Path(output)
    chosen = format_of(output)
    if branches and not chosen.branch_files:
        raise OutputError(f"{output}: a file per branch is for .csv only ({chosen.suffix} "
                          "holds every branch in the one file)")
    files = chosen.files(result, output, branches)
    for path, _ in files:
        check(path, chosen.own, overwrite)  # before any work
    made = [(path, make()) for path, make in files]
    _directory(output)
    written: list[Path] = []
    with atomic.locked(output.parent), held_signals():
        for path, _ in made:
            check(path, chosen.own, overwrite)
        try:
            for path, data in made:
                written.append(atomic.publish(data, path, overwrite, what="the export",
                                              own=chosen.own))
        except BaseException:  # e.g. a full disk: none of the new files stays
            for path in written:
                path.unlink(missing_ok=True)
            raise
    return tuple(written)


def _directory(output: Path) -> None:
    try:
        output.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputError(f"{output}: cannot create the output directory "
                          f"({error.strerror or error})") from None
