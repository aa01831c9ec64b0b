"""A result as a MATLAB/Octave MAT-file (version 5, compressed), written with scipy.

Variables, as the HDF5 file's groups: ``attributes`` (study name, model, provenance),
``parameters`` (the resolved set), ``continuations.<name>`` and ``linear.sweeps.<parameter>``.
A continuation holds ``branches.<name>`` (one struct per branch: its columns named as in the
HDF5 file, ``parameter_names``/``parameter_units``, ``state_names``/``state_units`` as
cellstr, ``type_name`` beside the ``point_type`` codes, ``units`` of the other columns, and
its attributes), ``special_points`` (a table-like struct: one field per column, one row per
point, ``struct2table`` takes it) with its labels beside it. Complex values are MATLAB
complex; names that are not MATLAB identifiers become ones (``name`` keeps the original).
"""

from __future__ import annotations

import io
import re

import numpy as np

from ..results import ContinuationResult, StudyResult
from .tables import (
    Table,
    branch_table,
    parameter_table,
    root_attributes,
    special_point_table,
    sweep_table,
)

#: Longest MATLAB identifier (field and variable names).
NAME_MAX = 63


def render(result: StudyResult) -> bytes:
    """The MAT-file of ``result``."""
    from scipy.io import savemat

    data: dict[str, object] = {
        "attributes": root_attributes(result),
        "parameters": _columns(parameter_table(result)),
        "continuations": _named({c.name: _continuation(c) for c in result.continuations}),
    }
    if result.linear_sweeps:
        data["linear"] = {"sweeps": _named({s.parameter: _record(sweep_table(s))
                                            for s in result.linear_sweeps})}
    buffer = io.BytesIO()
    savemat(buffer, data, format="5", long_field_names=True, do_compression=True,
            oned_as="column")
    return buffer.getvalue()


def identifier(name: str) -> str:
    """``name`` as a MATLAB identifier: other characters as ``_``, a leading ``x`` unless it
    starts with a letter, at most :data:`NAME_MAX` characters."""
    word = re.sub(r"\W", "_", name, flags=re.ASCII)
    word = word if re.match(r"[A-Za-z]", word) else f"x{word}"
    return word[:NAME_MAX]


def _named(members: dict[str, dict]) -> dict[str, dict]:
    """``members`` keyed by MATLAB identifiers (distinct: ``_2``, ``_3``, ... where two
    names become the same one)."""
    found: dict[str, dict] = {}
    for name, value in members.items():
        key = base = identifier(name)
        count = 1
        while key in found:
            count += 1
            key = f"{base[:NAME_MAX - len(str(count)) - 1]}_{count}"
        found[key] = value
    return found


def _continuation(continuation: ContinuationResult) -> dict[str, object]:
    points = special_point_table(continuation)
    found: dict[str, object] = {
        "name": continuation.name, "kind": str(continuation.kind),
        "branches": _named({b.name: _record(branch_table(b)) for b in continuation.branches}),
        "special_points": _columns(points),
        "special_point_units": _units(points),
    }
    found.update(_labels(points))
    return found


def _record(table: Table) -> dict[str, object]:
    """A table as one struct: its attributes, columns, column labels and units."""
    return {**table.attributes, **_columns(table), **_labels(table), "units": _units(table)}


def _columns(table: Table) -> dict[str, object]:
    return {column.name: _value(column.values) for column in table.columns}


def _labels(table: Table) -> dict[str, object]:
    """``<dimension>_names`` and ``<dimension>_units`` (cellstr rows) of the labelled column
    dimensions the table's columns use."""
    used = {dim for column in table.columns for dim in column.dims[1:]}
    found: dict[str, object] = {}
    for dim in sorted(used):
        axis = table.axes.get(dim)
        if axis is None or not axis.labelled:
            continue
        found[f"{dim}_names"] = _cells(axis.names, row=True)
        if axis.units is not None:
            found[f"{dim}_units"] = _cells(axis.units, row=True)
    return found


def _units(table: Table) -> dict[str, str]:
    """The unit of each column with one unit for all its values."""
    return {column.name: column.units for column in table.columns if column.units}


def _cells(texts, row: bool = False) -> np.ndarray:
    """A cellstr: a column (a row if ``row``)."""
    cells = np.empty(len(texts), dtype=object)
    cells[:] = [str(t) for t in texts]
    return cells.reshape((1, -1) if row else (-1, 1))


def _value(values: np.ndarray):
    """An array as savemat stores it: text as a cellstr, the rest as is."""
    values = np.asarray(values)
    if values.dtype == object or values.dtype.kind in "US":
        if values.ndim == 1:
            return _cells(values)
        cells = np.empty(values.shape, dtype=object)
        cells[...] = np.vectorize(str, otypes=[object])(values) if values.size else cells
        return cells
    return values
