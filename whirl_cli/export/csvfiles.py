"""A result as CSV: its special points (the table of ``whirl summary --format csv``) and,
if asked for, one file per branch (``<stem>_<continuation>_<branch>.csv``: a ``point``
column, then :func:`~whirl_cli.export.tables.flat_columns` with complex values split into
real and imaginary parts). Numbers at full precision; empty cells where there is no value."""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Callable
from functools import partial
from pathlib import Path

import numpy as np

from ..output.summary import render as summary
from ..results import Branch, StudyResult
from .tables import branch_table, flat_columns

#: How every branch file's header starts (how whirl recognises its own branch files).
BRANCH_HEADER = "point,"


def files(result: StudyResult, output: Path, branches: bool = False
          ) -> list[tuple[Path, Callable[[], bytes]]]:
    """(path, content to come) of the special points' file ``output`` and, with
    ``branches``, of each branch's file beside it."""
    found: list[tuple[Path, Callable[[], bytes]]] = [
        (output, lambda: summary(result, "csv", _dofs(result)).encode())]
    if branches:
        for continuation in result.continuations:
            for branch in continuation.branches:
                name = f"{output.stem}_{continuation.name}_{branch.name}{output.suffix}"
                found.append((output.parent / name, partial(_encoded, branch)))
    return found


def _encoded(branch: Branch) -> bytes:
    return branch_csv(branch).encode()


def _dofs(result: StudyResult):
    """The dofs of the model of ``result`` (None if not recorded), as ``whirl summary`` shows
    them."""
    return result.provenance.dofs or None


def branch_csv(branch: Branch) -> str:
    """The points of ``branch`` as CSV."""
    columns = flat_columns(branch_table(branch), split_complex=True)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["point", *(name for name, _ in columns)])
    for k in range(len(branch)):
        writer.writerow([k, *(_cell(values[k]) for _, values in columns)])
    return buffer.getvalue()


def _cell(value) -> str:
    """A value as the CSV holds it: floats at full precision, "" for NaN."""
    if isinstance(value, np.bool_ | bool):
        return str(bool(value))
    if isinstance(value, np.floating | float):
        number = float(value)
        return repr(number) if math.isfinite(number) else ""
    if isinstance(value, np.integer):
        return str(int(value))
    return str(value)
