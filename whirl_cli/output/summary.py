"""The special points of a study as a summary a person reads (a text table per continuation)
or a script reads (CSV, JSON): type, parameter values, amplitude of every dof, period,
stability, criticality and status.

:func:`summary_rows` is a pure function of a :class:`~whirl_cli.results.StudyResult` (read
from a file with :func:`whirl_cli.output.store.read`, or fresh from ``whirl run``);
:func:`records` flattens its rows into named columns, which :func:`to_csv`, :func:`to_json`
and :func:`tables` render. Nothing here knows a model's states: the dofs are named by the
caller (the study's model variant), else they are the first half of the stored states (a
variant's state is its dofs, then their rates).

Units: parameters in their stored (SI) units, amplitudes in each dof's declared unit with
angles in degrees (rad -> deg), periods in s. A dof's amplitude is its value at an
equilibrium point and its maximum over the orbit at a point of a periodic family.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..results import (
    Branch,
    ContinuationResult,
    LocateStatus,
    PointType,
    SpecialPoint,
    StudyResult,
    positions,
)
from ..units import axis_label, display_unit
from ..verdict import range_warnings, truncation, unjudged_seeds

FORMATS = ("table", "csv", "json")
"""Formats of ``whirl summary --format``."""

FIXED_COLUMNS = ("continuation", "branch", "type")
"""The first columns of :func:`records`; parameters and amplitudes follow, then
:data:`LAST_COLUMNS`."""

LAST_COLUMNS = ("period [s]", "stability", "criticality", "status")


@dataclass(frozen=True)
class Quantity:
    """A named value in a stated unit (as shown: angles already in degrees)."""

    name: str
    unit: str
    value: float

    @property
    def column(self) -> str:
        """Its column name, ``"name [unit]"``."""
        return axis_label(self.name, self.unit)


@dataclass(frozen=True)
class SummaryRow:
    """One special point as the summary shows it.

    ``stability``: "stable", "unstable", :data:`ONE_SIDE_STABLE` (a fold whose two sides
    differ) or "unknown" (where the branch has no stability verdict at the point, e.g. on
    loci); ``period``: s, NaN where there is none.
    """

    continuation: str
    branch: str
    type: str
    parameters: tuple[Quantity, ...]
    amplitudes: tuple[Quantity, ...]
    period: float
    stability: str
    criticality: str
    status: str


def summary_rows(result: StudyResult, dofs: Sequence[str] | None = None) -> list[SummaryRow]:
    """One row per special point of every continuation of ``result``, in stored order.

    Plain points (regular, labelled, user, end and no-convergence points) are left out.
    ``dofs``: the states whose amplitude is shown; None: every state but the dofs' rates.
    """
    return [row for continuation in result.continuations
            for row in continuation_rows(continuation, dofs, result.first_order)]


def continuation_rows(continuation: ContinuationResult, dofs: Sequence[str] | None = None,
                      first_order: tuple[str, ...] = ()) -> list[SummaryRow]:
    """The rows of :func:`summary_rows` of one continuation (``first_order``: the model's
    first-order states)."""
    by_name = {b.name: b for b in continuation.branches}
    return [_row(continuation, point, by_name.get(point.branch), continuation.branches,
                 dofs, first_order)
            for point in continuation.special_points if _listed(point.point_type)]


def _listed(code: int) -> bool:
    """Whether a point of type ``code`` is listed (unknown codes are)."""
    try:
        return PointType(int(code)).is_special
    except ValueError:
        return True


def type_name(code: int) -> str:
    """The point type's name (HB, LPC, HOMOCLINIC, ...), or the code for an unknown one."""
    try:
        return PointType(int(code)).name
    except ValueError:
        return str(int(code))


def _row(continuation: ContinuationResult, point: SpecialPoint, branch: Branch | None,
         branches: Sequence[Branch], dofs: Sequence[str] | None,
         first_order: tuple[str, ...]) -> SummaryRow:
    reference = branch if branch is not None else (branches[0] if branches else None)
    parameters = tuple(Quantity(name, _parameter_unit(name, branch, branches), float(value))
                       for name, value in zip(point.parameter_names,
                                              np.asarray(point.parameters, dtype=float),
                                              strict=False))
    return SummaryRow(continuation.name, point.branch, type_name(point.point_type), parameters,
                      _amplitudes(point, reference, dofs, first_order), float(point.period),
                      _stability(point, branch), point.criticality,
                      point.status + (" (smoothing artefact)" if point.artefact else ""))


def _parameter_unit(name: str, branch: Branch | None, branches: Sequence[Branch]) -> str:
    """The unit of parameter ``name`` on the point's branch, else on any branch, else ""."""
    for candidate in ([branch] if branch is not None else []) + list(branches):
        if name in candidate.parameter_names:
            return candidate.parameter_units[candidate.parameter_names.index(name)]
    return ""


def _amplitudes(point: SpecialPoint, branch: Branch | None, dofs: Sequence[str] | None,
                first_order: tuple[str, ...]) -> tuple[Quantity, ...]:
    """The point's state for each of ``dofs`` (None: every state but the dofs' rates), in
    its unit (rad shown in deg)."""
    if branch is None:
        return ()
    names = branch.state_names
    shown = [name for name in (positions(names, first_order) if dofs is None else dofs)
             if name in names]
    state = np.asarray(point.state, dtype=float)
    amplitudes = []
    for name in shown:
        k = names.index(name)
        factor, unit = display_unit(branch.state_units[k])
        amplitudes.append(Quantity(name, unit, float(state[k]) * factor))
    return tuple(amplitudes)


#: The stability shown on a fold (LP, LPC) whose two sides differ.
ONE_SIDE_STABLE = "stable/unstable"


def _stability(point: SpecialPoint, branch: Branch | None) -> str:
    """The point's stability; on a fold that of the branch on either side of it (one side
    stable, the other not, or both the same)."""
    on_branch = branch is not None and 0 <= point.index < len(branch)
    if on_branch and not branch.stability_known[point.index]:
        return "unknown"
    sides = _sides(branch, point.index) if on_branch and point.point_type in FOLDS else ()
    if len(sides) == 2:
        return ONE_SIDE_STABLE if sides[0] != sides[1] else _verdict(sides[0])
    return _verdict(point.stable)


def _verdict(stable: bool) -> str:
    return "stable" if stable else "unstable"


#: Fold points, shown with the stability of both sides.
FOLDS = (PointType.LP, PointType.LPC)


def _sides(branch: Branch, index: int) -> tuple[bool, ...]:
    """The branch's stability at the nearest row with a known verdict before and after
    ``index`` (fewer where it has none on a side)."""
    known = np.flatnonzero(branch.stability_known)
    before, after = known[known < index], known[known > index]
    return tuple(bool(branch.stable[rows[k]]) for rows, k in ((before, -1), (after, 0))
                 if len(rows))


# ---------------------------------------------------------------------------- flat records
def columns(rows: Sequence[SummaryRow]) -> list[str]:
    """Column names of :func:`records`: the fixed ones, every parameter and amplitude column
    in order of first appearance, then :data:`LAST_COLUMNS`."""
    seen: dict[str, None] = {}
    for row in rows:
        for quantity in row.parameters:
            seen.setdefault(quantity.column)
    for row in rows:
        for quantity in row.amplitudes:
            seen.setdefault(quantity.column)
    return [*FIXED_COLUMNS, *seen, *LAST_COLUMNS]


def records(rows: Sequence[SummaryRow]) -> list[dict[str, object]]:
    """``rows`` as dicts over :func:`columns` (None where a row has no such value: another
    continuation's parameter, or no period)."""
    names = columns(rows)
    return [{name: record.get(name) for name in names}
            for record in (_record(row) for row in rows)]


def _record(row: SummaryRow) -> dict[str, object]:
    record: dict[str, object] = {"continuation": row.continuation, "branch": row.branch,
                                 "type": row.type}
    for quantity in row.parameters + row.amplitudes:
        record[quantity.column] = _finite(quantity.value)
    record.update({"period [s]": _finite(row.period), "stability": row.stability,
                   "criticality": row.criticality, "status": row.status})
    return record


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None


def to_json(rows: Sequence[SummaryRow]) -> str:
    """:func:`records` as a JSON array of objects (null for missing values; numbers at full
    precision)."""
    return json.dumps(records(rows), indent=1)


def to_csv(rows: Sequence[SummaryRow]) -> str:
    """:func:`records` as CSV with a header line (empty cells for missing values; numbers at
    full precision)."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns(rows), lineterminator="\n")
    writer.writeheader()
    for record in records(rows):
        writer.writerow({k: "" if v is None else (repr(v) if isinstance(v, float) else v)
                         for k, v in record.items()})
    return buffer.getvalue()


# ---------------------------------------------------------------------------- tables
def number(value: float | None) -> str:
    """A value as the table shows it: 6 significant digits, "-" where there is none."""
    return "-" if value is None or not math.isfinite(value) else f"{value:.6g}"


def _cell(value: object) -> str:
    return number(value) if value is None or isinstance(value, float) else str(value)


RUN_SHOWN = 3
"""A table shows runs of at most this many consecutive points of one type on one branch in
full; a longer run as its first and last row with one "... N more" row between them."""


@dataclass(frozen=True)
class Skipped:
    """Where :func:`compact` left out ``count`` records of points of ``type`` with one
    ``status``."""

    count: int
    type: str
    status: str = LocateStatus.LOCATED

    def text(self) -> str:
        """What the "..." row says: "6 more GH", "203 more GH, rejected" (a status other
        than located is named)."""
        named = "" if self.status == LocateStatus.LOCATED else f", {self.status}"
        return f"{self.count} more {self.type}{named}"


def compact(records_: Sequence[dict[str, object]], longest: int = RUN_SHOWN
            ) -> list[dict[str, object] | Skipped]:
    """``records_`` with every run of more than ``longest`` consecutive records of the same
    branch, type and status replaced by its first record, a :class:`Skipped` and its last
    record (e.g. the many GH points AUTO flags along a Hopf locus of a linear model, which
    whirl's check rejects)."""
    def key(record: dict[str, object]) -> tuple:
        return record["branch"], record["type"], record["status"]

    shown: list[dict[str, object] | Skipped] = []
    start = 0
    while start < len(records_):
        end = start
        while end + 1 < len(records_) and key(records_[end + 1]) == key(records_[start]):
            end += 1
        run = list(records_[start:end + 1])
        skipped = Skipped(len(run) - 2, str(run[0]["type"]), str(run[0]["status"]))
        shown += run if len(run) <= longest else [run[0], skipped, run[-1]]
        start = end + 1
    return shown


@dataclass(frozen=True)
class Table:
    """A continuation's special points as the table shows them: ``title``, column ``names``
    (``right``: right-aligned, the numbers), ``rows`` of cell texts and ``notes``, lines
    below them (branches stopped short of their range)."""

    title: str
    names: tuple[str, ...]
    right: tuple[bool, ...]
    rows: tuple[tuple[str, ...], ...]
    notes: tuple[str, ...] = ()

    def lines(self) -> list[str]:
        """The title, the header and a line per row, columns two spaces apart, each as wide
        as its widest cell (numbers are never cut); "none" centred under the header if no rows."""
        widths = [max(len(cell) for cell in column)
                  for column in zip(self.names, *self.rows, strict=True)]

        def line(cells: tuple[str, ...]) -> str:
            return "  ".join(cell.rjust(w) if right else cell.ljust(w) for cell, w, right
                             in zip(cells, widths, self.right, strict=True)).rstrip()

        header = line(self.names)
        body = [line(row) for row in self.rows] or ["none".center(len(header)).rstrip()]
        return [self.title, header, *body, *self.notes]


def counted(rows: Sequence[SummaryRow]) -> str:
    """"3 special points", or "221 special points, 203 of them rejected by whirl's checks"
    (AUTO labelled them; whirl's own check says they are not that point)."""
    rejected = sum(row.status == LocateStatus.REJECTED for row in rows)
    text = f"{len(rows)} special point{'s' if len(rows) != 1 else ''}"
    return text + (f", {rejected} of them rejected by whirl's checks" if rejected else "")


def tables(result: StudyResult, dofs: Sequence[str] | None = None) -> list[Table]:
    """One :class:`Table` per continuation of ``result`` (its special points, as in
    :func:`summary_rows`, long runs of one type on one branch shortened by :func:`compact`;
    a continuation without any gets a table whose body is "none")."""
    drawn = []
    for continuation in result.continuations:
        rows = continuation_rows(continuation, dofs, result.first_order)
        names = tuple(columns(rows)[1:])  # the continuation is the title
        cells = []
        for record in compact(records(rows)):
            if isinstance(record, Skipped):
                cells.append(("...", record.text(),
                              *[""] * (len(names) - 2)))
            else:
                cells.append(tuple(_cell(record[name]) for name in names))
        drawn.append(Table(
            f"{continuation.name} ({continuation.kind}): {counted(rows)}", names,
            tuple(name not in ("branch", "type", *LAST_COLUMNS[1:]) for name in names),
            tuple(cells), tuple(f"note: {truncation(b)}" for b in continuation.branches
                                if b.truncated)
            + tuple(f"note: {n}" for n in (unjudged_seeds(continuation),) if n)
            + tuple(f"warning: {w}" for b in result.boundaries if b.name == continuation.name
                    for w in range_warnings(b))))
    return drawn


def render(result: StudyResult, output_format: str, dofs: Sequence[str] | None = None) -> str:
    """The summary of ``result`` as text in ``output_format`` (one of :data:`FORMATS`);
    tables one after another, a blank line between them, as wide as they need."""
    if output_format == "csv":
        return to_csv(summary_rows(result, dofs))
    if output_format == "json":
        return to_json(summary_rows(result, dofs)) + "\n"
    if output_format != "table":
        raise ValueError(f"unknown summary format {output_format!r}; choose from {FORMATS}")
    return "\n\n".join("\n".join(table.lines()) for table in tables(result, dofs)) + "\n"
