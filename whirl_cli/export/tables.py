"""A result's parts as labelled tables, the one description every export format is made from.

A :class:`Table` is rows of one kind (the points of a branch, the special points of a
continuation, the values of a linear sweep, the parameter set) and its columns, each named as
in the HDF5 file, with its dimensions (``point``, ``state``, ``parameter``, ``mode``, ...) and
units; :class:`Axis` labels a column dimension (the state names and their units). MATLAB
structs, NetCDF groups, CSV files and pandas DataFrames are written from these
(:mod:`whirl_cli.export`); nothing here imports more than numpy.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..output.store import lyapunov_unit
from ..results import Branch, BranchKind, ContinuationResult, LinearSweep, PointType, StudyResult
from ..units import axis_label


@dataclass(frozen=True)
class Axis:
    """The labels of a column dimension: ``names``, their ``units`` (None: unitless labels,
    e.g. mode numbers); ``labelled``: the names are worth storing (not just 1..n)."""

    names: tuple[str, ...]
    units: tuple[str, ...] | None = None
    labelled: bool = True


@dataclass(frozen=True)
class Column:
    """One quantity: ``values`` (rows,) or (rows, k) along ``dims``, in ``units`` (one unit
    for all; "" where the second dimension's :class:`Axis` gives one per column, or none);
    ``flat``: the header of one of its columns in a flat table, ``{label}`` the label."""

    name: str
    values: np.ndarray
    dims: tuple[str, ...]
    units: str = ""
    long_name: str = ""
    flat: str = "{label}"


@dataclass(frozen=True)
class Table:
    """Rows along ``dims[0]`` of every column, its column ``axes`` by dimension, and
    ``attributes`` (scalars: a branch's kind, origin, status, ...); ``index``: the column
    naming the rows, if one does (the parameter set's ``name``)."""

    name: str
    columns: tuple[Column, ...]
    axes: dict[str, Axis] = field(default_factory=dict)
    attributes: dict[str, object] = field(default_factory=dict)
    index: str | None = None

    def __getitem__(self, name: str) -> Column:
        return next(c for c in self.columns if c.name == name)


#: Names of every point type, by code (the ``flag_values``/``flag_meanings`` of NetCDF).
POINT_TYPES = tuple((int(t), t.name) for t in PointType)


def type_names(codes) -> np.ndarray:
    """The point types' names (``HB``, ``LPC``, ...) of ``codes``; an unknown code as text."""
    known = dict(POINT_TYPES)
    return np.array([known.get(int(c), str(int(c))) for c in np.asarray(codes).ravel()],
                    dtype=object)


def _modes(n: int) -> Axis:
    return Axis(tuple(str(k) for k in range(1, n + 1)), None, labelled=False)


def branch_table(branch: Branch) -> Table:
    """The points of ``branch``: its parameters, state extremes, norm, period, stability,
    point types (codes and names), labels and eigenvalues (Floquet multipliers on periodic
    branches), with the HDF5 file's names."""
    periodic = branch.kind == BranchKind.PERIODIC
    point = ("point",)
    columns = [
        Column("parameters", np.asarray(branch.parameters, float), ("point", "parameter"),
               long_name="continuation parameters"),
        Column("state_max", np.asarray(branch.state_max, float), ("point", "state"),
               long_name="maximum of each state over the orbit", flat="{label} max"),
        Column("state_min", np.asarray(branch.state_min, float), ("point", "state"),
               long_name="minimum of each state over the orbit", flat="{label} min"),
        Column("l2_norm", np.asarray(branch.l2_norm, float), point, "1", "AUTO's L2 norm"),
        Column("period", np.asarray(branch.period, float), point, "s", "period of the orbit"),
        Column("stable", np.asarray(branch.stable, bool), point, long_name="stable"),
        Column("stability_known", np.asarray(branch.stability_known, bool), point,
               long_name="stability known"),
        Column("point_type", np.asarray(branch.point_type, np.int64), point,
               long_name="point type code"),
        Column("type_name", type_names(branch.point_type), point, long_name="point type"),
        Column("label", np.asarray(branch.label, np.int64), point, long_name="AUTO label"),
        Column("floquet_multipliers" if periodic else "eigenvalues",
               np.asarray(branch.eigenvalues, complex), ("point", "mode"),
               "1" if periodic else "1/s",
               "Floquet multipliers" if periodic else "Jacobian eigenvalues",
               flat="multiplier {label}" if periodic else "eigenvalue {label}"),
    ]
    if branch.torus_angle is not None:
        columns.append(Column("torus_angle", np.asarray(branch.torus_angle, float), point,
                              "rad", "Neimark-Sacker angle"))
    axes = {"parameter": Axis(branch.parameter_names, branch.parameter_units),
            "state": Axis(branch.state_names, branch.state_units),
            "mode": _modes(np.shape(branch.eigenvalues)[1])}
    attributes = {"name": branch.name, "kind": str(branch.kind), "origin": str(branch.origin),
                  "status": str(branch.status), "message": branch.message,
                  "run": "+".join(branch.runs),
                  "end": branch.end}
    return Table(branch.name, tuple(columns), axes, attributes)


def plain(value):
    """``value``, a word of whirl's vocabulary as a plain str (export formats take no
    subclass of str)."""
    return str(value) if isinstance(value, str) else value


def special_point_table(continuation: ContinuationResult) -> Table:
    """The special points of ``continuation``, one row each, the columns of its HDF5
    ``special_points`` group (type names beside the codes)."""
    points = continuation.special_points
    first = continuation.branches[0] if continuation.branches else None
    names = points[0].parameter_names if points else (first.parameter_names if first else ())
    units = points[0].parameter_units if points and points[0].parameter_units else \
        _units_of(names, continuation.branches)
    states = Axis(first.state_names, first.state_units) if first else Axis(())
    principal = units[0] if units else ""
    rows = ("special_point",)

    def column(name: str, dtype, dims=rows, unit="", long_name="", flat="{label}") -> Column:
        values = np.array([plain(getattr(p, name)) for p in points], dtype=dtype)
        if len(dims) == 2:
            width = {"parameter": len(names), "state": len(states.names)}.get(dims[1], 2)
            values = values.reshape(len(points), width)
        return Column(name, values, dims, unit, long_name, flat)

    columns = (
        column("branch", object, long_name="branch"),
        column("index", np.int64, long_name="row of the point on its branch"),
        column("point_type", np.int64, long_name="point type code"),
        Column("type_name", type_names([p.point_type for p in points]), rows,
               long_name="point type"),
        column("label", np.int64, long_name="AUTO label"),
        column("parameters", float, ("special_point", "parameter"),
               long_name="continuation parameters"),
        column("state", float, ("special_point", "state"),
               long_name="state (maximum over the orbit at periodic points)"),
        column("period", float, unit="s", long_name="period"),
        column("stable", bool, long_name="stable"),
        column("status", object, long_name="located or bracketed"),
        column("criticality", object, long_name="criticality"),
        column("note", object, long_name="note"),
        column("bracket", float, ("special_point", "bound"), principal,
               "bracket of the principal parameter", "bracket {label}"),
        column("residual", float, unit="1", long_name="relative fit residual"),
        column("lyapunov", float, unit=lyapunov_unit(states.units) if first else "",
               long_name="first Lyapunov coefficient"),
        column("refined", float, ("special_point", "refinement"), principal,
               "principal parameter with the smoothing halved and quartered",
               "refined {label}"),
        column("artefact", bool, long_name="smoothing artefact"),
        column("refined_by", object, long_name="how refined was computed"),
        column("torus_angle", float, unit="rad", long_name="Neimark-Sacker angle"),
    )
    axes = {"parameter": Axis(names, units), "state": states,
            "bound": Axis(("lower", "upper")), "refinement": Axis(("half", "quarter"))}
    return Table("special_points", columns, axes, {"name": continuation.name,
                                                   "kind": str(continuation.kind)})


def _units_of(names: Sequence[str], branches: Sequence[Branch]) -> tuple[str, ...]:
    """The units of the parameters ``names`` on the first branch holding each, else ""."""
    found = {n: u for b in reversed(branches)
             for n, u in zip(b.parameter_names, b.parameter_units, strict=True)}
    return tuple(found.get(n, "") for n in names)


def sweep_table(sweep: LinearSweep) -> Table:
    """A linear sweep: the swept values, and per mode the eigenvalue, damping ratio,
    frequency, whirl direction (and mode group)."""
    point, modes = ("point",), ("point", "mode")
    columns = [
        Column("values", np.asarray(sweep.values, float), point, sweep.unit, sweep.parameter),
        Column("eigenvalues", np.asarray(sweep.eigenvalues, complex), modes, "1/s",
               "eigenvalues", "eigenvalue {label}"),
        Column("damping_ratio", np.asarray(sweep.damping_ratio, float), modes, "1",
               "damping ratio", "damping ratio {label}"),
        Column("frequency", np.asarray(sweep.frequency, float), modes, "rad/s", "frequency",
               "frequency {label}"),
        Column("whirl", np.asarray(sweep.whirl, dtype=object), modes,
               long_name="whirl direction (FW, BW, -- for real eigenvalues)",
               flat="whirl {label}"),
    ]
    if sweep.mode_group is not None:
        columns.append(Column("mode_group", np.asarray(sweep.mode_group, dtype=object), modes,
                              long_name="mode group", flat="mode group {label}"))
    attributes = {"parameter": sweep.parameter, "unit": sweep.unit,
                  "multiples": int(sweep.multiples), "spacing": str(sweep.spacing)}
    if sweep.datum is not None:
        attributes["datum"] = float(sweep.datum)
    return Table(sweep.parameter, tuple(columns),
                 {"mode": _modes(np.shape(sweep.eigenvalues)[1])}, attributes)


def parameter_table(result: StudyResult) -> Table:
    """The resolved parameter set of the study (value, datum, unit of each)."""
    rows = ("parameter",)
    found = result.parameters
    units = tuple(p.unit for p in found)
    return Table("parameters", (
        Column("name", np.array([p.name for p in found], dtype=object), rows, long_name="name"),
        Column("value", np.array([p.value for p in found], dtype=float), rows,
               long_name="value the study ran"),
        Column("datum", np.array([p.datum for p in found], dtype=float), rows,
               long_name="the model's datum"),
        Column("unit", np.array(units, dtype=object), rows, long_name="unit"),
    ), index="name")


def root_attributes(result: StudyResult) -> dict[str, object]:
    """The HDF5 file's root attributes: study name, model and provenance (texts and
    numbers; lists joined by ", ")."""
    found: dict[str, object] = {"study_name": result.study_name, "model": result.model}
    for key, value in sorted(result.root_attributes().items()):
        if isinstance(value, str | int | float):
            found[key] = value
        elif isinstance(value, list | tuple | np.ndarray):
            found[key] = ", ".join(str(v) for v in value)
    return found


def _labels(column: Column, table: Table) -> list[tuple[str, str]]:
    """(label, unit) of each of a 2-D column's columns."""
    axis = table.axes.get(column.dims[1])
    width = np.shape(column.values)[1]
    names = axis.names if axis is not None and len(axis.names) == width else \
        tuple(str(k) for k in range(1, width + 1))
    units = axis.units if axis is not None and axis.units is not None and \
        len(axis.units) == width else (column.units,) * width
    return list(zip(names, units, strict=True))


def flat_columns(table: Table, split_complex: bool = False
                 ) -> list[tuple[str, np.ndarray]]:
    """``table`` as named 1-D columns, headers ``name [unit]``: a 2-D column split into one
    per label (``theta max [rad]``), complex values into ``... real`` and ``... imag`` if
    ``split_complex``."""
    flat: list[tuple[str, np.ndarray]] = []
    for column in table.columns:
        values = np.asarray(column.values)
        if len(column.dims) == 1:
            parts = [(column.name, column.units, values)]
        else:
            parts = [(column.flat.format(label=label), unit, values[:, k])
                     for k, (label, unit) in enumerate(_labels(column, table))]
        for name, unit, part in parts:
            if split_complex and np.iscomplexobj(part):
                flat += [(_header(f"{name} real", unit), part.real),
                         (_header(f"{name} imag", unit), part.imag)]
            else:
                flat.append((_header(name, unit), part))
    return flat


def _header(name: str, unit: str) -> str:
    """``name [unit]`` for a quantity with a unit, ``name`` alone for one without."""
    return axis_label(name, unit) if unit else name
