"""HDF5 output: the one writer and the one reader of whirl's result files (schema 2; reads 1).

:func:`read` is the one place files of an older whirl are upgraded: a file without the
``provenance`` group gets what newer files hold from the study stored with it
(:func:`whirl_cli.output.provenance.upgraded`); nothing else reading a result knows its age.

The layout, group by group, is described in ``docs/hdf5-layout.md`` (a test checks that it
names every field declared below).

The groups holding collections (continuations, branches, orbits, explorations, sweeps,
boundaries, loci, polygons, contour lines, simulations, runs) track the creation order of their
members, so a round trip keeps the order of the study and its results; older files list (and
read) by name. Each collection records the number of its members (attribute ``whirl_count``),
every other group their names (``whirl_parts``); reading checks both (older files lack them).

Every dataclass field's place in that layout is declared once, below (:data:`BRANCH`,
:data:`SPECIAL_POINT`, ...), and both :func:`write` and :func:`read` go by those declarations
(:mod:`whirl_cli.output.mapping`).

The file is built in memory and published by :mod:`whirl_cli.output.atomic`: written to an
unnamed file in the output directory (O_TMPFILE) and linked into place, so an output path never
holds a partial file and an interrupted write (even SIGKILL) leaves no temporary file; an
existing file is only replaced with ``overwrite`` (removed, then the new one linked: see
:func:`whirl_cli.output.atomic._link_unnamed` for the trade-off).
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

import h5py
import numpy as np

from ..errors import OutputError
from ..results import (
    ROOT_FIELDS,
    Boundary,
    BoundaryMethod,
    Branch,
    BranchKind,
    CheckKind,
    ContinuationKind,
    ContinuationResult,
    Criticality,
    CrossCheck,
    Exploration,
    FixedParameter,
    FreeplayAmplitudes,
    LawCurve,
    LinearGrid,
    LinearSweep,
    LocateStatus,
    LocusKind,
    MotionKind,
    Orbit,
    Origin,
    ParameterValue,
    PointType,
    Provenance,
    RunRecord,
    RunStatus,
    SeedKind,
    SeedOutcome,
    Simulation,
    SimulationLaw,
    SliceLabel,
    Spacing,
    SpecialPoint,
    StudyResult,
    UnsafeCause,
    UnsafeInterval,
)
from .atomic import publish
from .guard import RESULT, check
from .mapping import (
    Damaged,
    Field,
    attribute,
    member,
    read_record,
    read_table,
    text,
    texts,
    word,
    write_record,
    write_table,
)

SCHEMA = 2
#: Schemas :func:`read` reads (1: before units on every dataset and the parameter set).
READABLE = (1, 2)

# ------------------------------------------------------------------------- the declarations
def _runs(text: str) -> tuple[str, ...]:
    """A branch's AUTO runs from their stored text, "+"-joined ("": none)."""
    return tuple(text.split("+")) if text else ()


_PERIODIC = BranchKind.PERIODIC

#: A :class:`Branch` in ``branches/<name>`` (its name is the group's).
BRANCH = (
    Field("kind", "attribute", "text", vocabulary=BranchKind),
    Field("origin", "attribute", "text", vocabulary=Origin.parse),
    Field("status", "attribute", "text", vocabulary=RunStatus),
    Field("message", "attribute", "text"),
    Field("runs", "attribute", "text", key="run", vocabulary=_runs, spelled="+".join),
    Field("end", "attribute", "text"),
    Field("parameters", columns=("parameter_names", "parameter_units"),
          shape=("points", "parameter_names")),
    Field("state_max", columns=("state_names", "state_units"), shape=("points", "state_names")),
    Field("state_min", columns=("state_names", "state_units"), shape=("points", "state_names")),
    Field("l2_norm", units="1", shape=("points",)),
    Field("period", units="s", shape=("points",)),
    Field("stable", kind="bool", shape=("points",)),
    Field("stability_known", kind="bool", default=None,  # older files: known everywhere
          shape=("points",)),
    Field("point_type", kind="int", shape=("points",), codes=PointType),
    Field("label", kind="int", shape=("points",)),
    Field("eigenvalues",
          key=lambda kind: "floquet_multipliers" if kind == _PERIODIC else "eigenvalues",
          units=lambda kind: "1" if kind == _PERIODIC else "1/s",
          shape=("points", "state_names")),
    Field("torus_angle", units="rad", default=None, shape=("points",)),  # torus loci only
)
#: An :class:`Orbit` in ``orbits/<label>`` of its branch.
ORBIT = (
    Field("point_type", "attribute", "int"), Field("index", "attribute", "int"),
    Field("period", "attribute", "float"), Field("parameters", "attribute"),
    Field("time", units="s", shape=("samples",)), Field("states", shape=("samples", "states")),
)
#: The :class:`SpecialPoint` table of a continuation (``special_points/``), one column each.
SPECIAL_POINT = (
    Field("branch", kind="text"), Field("index", kind="int"),
    Field("point_type", kind="int", codes=PointType),
    Field("type_name", kind="text", derived=True),
    Field("label", kind="int"),
    Field("parameters", width="parameters", columns=("parameter_names", "parameter_units")),
    Field("state", width="states"),  # names and units: the continuation's states
    Field("period", kind="float", units="s"), Field("stable", kind="bool"),
    Field("status", kind="text", vocabulary=LocateStatus),
    Field("criticality", kind="text", vocabulary=Criticality), Field("note", kind="text"),
    Field("bracket", width=2),  # units: the principal parameter's
    Field("residual", kind="float", units="1"),
    Field("lyapunov", kind="float", default=float("nan")),  # units: see lyapunov_unit
    Field("refined", width=2, default=lambda: np.full(2, np.nan)),  # units: the bracket's
    Field("artefact", kind="bool", default=False),
    Field("refined_by", kind="text", default=""),  # older files: not recorded
    Field("torus_angle", kind="float", units="rad", default=float("nan")),
)
#: The resolved :class:`ParameterValue` table of a study (``parameters/``; schema 2).
PARAMETER = (
    Field("name", kind="text"), Field("value", kind="float"), Field("datum", kind="float"),
    Field("unit", kind="text"),
)
#: The :class:`CrossCheck` table of a continuation (``cross_checks/``).
CROSS_CHECK = (
    Field("branch", kind="text"), Field("index", kind="int"),
    Field("kind", kind="text", vocabulary=CheckKind),
    Field("parameter", kind="float"), Field("expected", kind="float"),
    Field("simulated", kind="float"), Field("passed", kind="bool"),
    Field("state", kind="text", default=""),  # older files: not recorded
    Field("exact", kind="optional_float", default=None),  # NaN in the file where none
)
#: The :class:`SeedOutcome` table of a continuation (``seeds/``).
SEED = (
    Field("index", kind="int"), Field("seed", width="states"),
    Field("kind", kind="text", vocabulary=SeedKind),
    Field("period", kind="float", units="s"), Field("branch", kind="text"),
    Field("message", kind="text"),
)
#: An :class:`Exploration` of a continuation, in ``explorations/<k>`` (k from 0, in the
#: order of the study's ``explore``).
EXPLORATION = (
    Field("parameter", "attribute", "text"),
    Field("kind", "attribute", "text", vocabulary=MotionKind),
    Field("multiplicity", "attribute", "int"), Field("evidence", "attribute", "text"),
    Field("value", kind="float", unit_field="unit", shape=()),
    Field("initial", columns=("state_names", "state_units"), shape=("state_names",)),
    Field("lyapunov", kind="float", units="1/s", shape=()),
    Field("lyapunov_error", kind="float", units="1/s", shape=()),
    Field("frequencies", units="Hz", shape=("frequencies",)),
    Field("section", columns=("state_names", "state_units"), shape=("crossings", "state_names")),
    Field("section_dimension", kind="float", units="1", shape=()),
    Field("peaks", units="Hz", shape=("peaks",)),
    Field("broadband", kind="float", units="1", shape=()),
)
#: The :class:`FreeplayAmplitudes` of a periodic branch, in ``<branch>/freeplay_<dof>``.
FREEPLAY = (
    Field("dof", "attribute", "text"),
    Field("amplitude_ratio", units="1", shape=("points",)),
    Field("estimate_ratio", key="describing_function/amplitude_ratio", units="1",
          shape=("estimates",)),
    Field("estimate_stiffness", key="describing_function/stiffness",
          unit_field="stiffness_unit", shape=("estimates",)),
    Field("estimate_parameter", key="describing_function/parameter",
          unit_field="parameter_unit", shape=("estimates",)),
    Field("onset", key="linear_onset", unit_field="parameter_unit",
          default=lambda: np.empty(0)),
)
#: A :class:`LinearSweep` in ``linear/sweeps/<parameter>``.
LINEAR_SWEEP = (
    Field("parameter", "attribute", "text"),
    Field("values", unit_field="unit", shape=("values",)),
    Field("eigenvalues", units="1/s", shape=("values", "modes")),
    Field("damping_ratio", units="1", shape=("values", "modes")),
    Field("frequency", units="rad/s", shape=("values", "modes")),
    Field("whirl", kind="text", shape=("values", "modes")),
    Field("mode_group", kind="text", default=None, shape=("values", "modes")),
    Field("datum", kind="float", unit_field="unit", default=None,  # older files: none
          shape=()),
    Field("multiples", "attribute", "bool", default=False),
    Field("spacing", "attribute", "text", vocabulary=Spacing,  # older files: linear
          default=Spacing.LINEAR),
)
#: A :class:`LinearGrid` in ``linear/grid`` (its contour lines: collections of their own).
LINEAR_GRID = (
    Field("x_parameter", "attribute", "text"), Field("y_parameter", "attribute", "text"),
    Field("x", unit_field="x_unit", shape=("x",)), Field("y", unit_field="y_unit", shape=("y",)),
    Field("max_real", units="1/s", shape=("y", "x")), Field("oscillatory", shape=("y", "x")),
    Field("x_spacing", "attribute", "text", vocabulary=Spacing,  # older files: linear
          default=Spacing.LINEAR),
    Field("y_spacing", "attribute", "text", vocabulary=Spacing, default=Spacing.LINEAR),
)
#: A :class:`Boundary` in ``boundaries/<name>`` (its loci and polygons: collections).
BOUNDARY = (
    Field("parameter_names", "attribute", "text", key="parameters"),
    Field("parameter_units", "attribute", "text", key="units"),
    Field("method", "attribute", "text", vocabulary=BoundaryMethod),
    Field("slices", "attribute", "float"),
    Field("first_range", "attribute", "float", default=(np.nan, np.nan)),
    Field("second_range", "attribute", "float", default=(np.nan, np.nan)),
)
#: The :class:`UnsafeInterval` table of a boundary (``unsafe_intervals/``).
UNSAFE_INTERVAL = (
    Field("slice_value", kind="float"), Field("lower", kind="float"),
    Field("upper", kind="float"), Field("cause", kind="text", vocabulary=UnsafeCause),
)
#: A :class:`Simulation` in ``simulations/<name>`` (its name is the group's).
SIMULATION = (
    Field("law", "attribute", "text", vocabulary=SimulationLaw),
    Field("status", "attribute", "int"),
    Field("message", "attribute", "text"),
    Field("parameter_values", key="parameters", columns=("parameter_names", "parameter_units"),
          shape=("parameter_names",)),
    Field("initial", columns=("state_names", "state_units"), shape=("state_names",)),
    Field("time", units="s", shape=("samples",)),
    Field("states", columns=("state_names", "state_units"), shape=("samples", "state_names")),
    Field("hub", unit_field="hub_unit", shape=("samples", 2)),
)
#: A :class:`ContinuationResult`'s own attributes in ``continuations/<name>``.
CONTINUATION = (Field("kind", "attribute", "text", vocabulary=ContinuationKind),)
#: The text fields of :class:`Provenance`: root attributes of the file, each written only
#: where recorded (not "").
PROVENANCE_ROOT = tuple(Field(name, "attribute", "text", default="") for name in ROOT_FIELDS)
#: The rest of :class:`Provenance`, in ``provenance/`` (files before it: read off the study
#: stored with them, :func:`whirl_cli.output.provenance.upgraded`).
PROVENANCE = (
    Field("plot_state", "attribute", "text"), Field("dofs", "attribute", "text"),
    Field("family", "attribute", "text", default=""),  # not recorded: read off the study
)
#: The :class:`FixedParameter` table of ``provenance/fixed``.
FIXED_PARAMETER = (
    Field("name", kind="text"), Field("value", kind="float"), Field("unit", kind="text"),
)
#: The :class:`SliceLabel` table of ``provenance/slice_labels``.
SLICE_LABEL = (
    Field("continuation", kind="text"), Field("index", kind="int"), Field("label", kind="text"),
)
#: A :class:`LawCurve` in ``provenance/laws/<dof>`` (its dof is the group's name).
LAW_CURVE = (
    Field("law", "attribute", "text"), Field("linear", "attribute", "bool"),
    Field("coefficient_names", "attribute", "text"),
    Field("coefficient_values", "attribute", "float"),
    Field("stiffness", "attribute", "text"), Field("stiffness_value", "attribute", "float"),
    Field("force_unit", "attribute", "text"), Field("dof_unit", "attribute", "text"),
    Field("breakpoints", "attribute", "float"),
    Field("x", unit_field="dof_unit", shape=("samples",)),
    Field("force", unit_field="force_unit", shape=("samples",)),
    Field("exact", unit_field="force_unit", default=None, shape=("samples",)),
)
#: A :class:`RunRecord` in ``runs/<name>``.
RUN = (
    Field("status", "attribute", "text", vocabulary=RunStatus),
    Field("message", "attribute", "text"),
    Field("constants", "attribute", "text"), Field("returncode", "attribute", "int"),
    Field("wall_seconds", "attribute", "float"), Field("n_points", "attribute", "int"),
)


# ------------------------------------------------------------------------------ writing
def _collection(parent: h5py.Group, name: str) -> h5py.Group:
    """The group ``name`` of ``parent`` that holds a collection (continuations, branches,
    orbits, sweeps, boundaries, loci, runs, ...), created tracking the order in which its
    members are written, so that :func:`read` returns them in that order; HDF5 lists them by
    name otherwise (``periodic_10`` before ``periodic_2``)."""
    if name in parent:
        return parent[name]
    return parent.create_group(name, track_order=True)


def _write_branch(group: h5py.Group, branch: Branch) -> None:
    write_record(group, branch, BRANCH)
    for orbit in branch.orbits:
        sub = _collection(group, "orbits").create_group(str(orbit.label))
        write_record(sub, orbit, ORBIT)
        sub["states"].attrs.update(names=list(branch.state_names),
                                   units=list(branch.state_units))


def _write_continuation(group: h5py.Group, continuation: ContinuationResult) -> None:
    write_record(group, continuation, CONTINUATION)
    branches = _collection(group, "branches")  # also where there are none: it is required
    for branch in continuation.branches:
        _write_branch(branches.create_group(branch.name), branch)
    for found in continuation.freeplay:
        _write_freeplay(group["branches"][found.branch], found)
    points = continuation.special_points
    first = continuation.branches[0] if continuation.branches else None
    states = {"names": list(first.state_names) if first else [],
              "units": list(first.state_units) if first else []}
    write_table(group.create_group("special_points"), points, SPECIAL_POINT, {
        "parameters": len(points[0].parameter_names) if points else 1,
        "states": len(first.state_names) if first else 0}, {
        "state": states,
        "bracket": {"units": first.parameter_units[0] if first else ""},
        "refined": {"units": first.parameter_units[0] if first else ""},
        "lyapunov": {"units": lyapunov_unit(first.state_units) if first else ""}})
    if continuation.seeds:
        write_table(group.create_group("seeds"), continuation.seeds, SEED,
                    {"states": len(first.state_names) if first else 0}, {"seed": states})
    for k, found in enumerate(continuation.explorations):
        write_record(_collection(group, "explorations").create_group(str(k)), found,
                     EXPLORATION)
    if continuation.cross_checks and first is not None:
        write_table(group.create_group("cross_checks"), continuation.cross_checks,
                    CROSS_CHECK, attributes=_cross_check_units(continuation.cross_checks, first))


def _cross_check_units(checks, branch: Branch) -> dict[str, dict]:
    """Units of the cross-check columns: the principal parameter's (the value a check is at),
    and per row those of expected and simulated: the compared state's unit for an orbit, the
    dofs' typical amplitudes for an equilibrium."""
    units = dict(zip(branch.state_names, branch.state_units, strict=True))
    rows = [units.get(c.state, "") if c.kind == CheckKind.ORBIT else "typical amplitudes"
            for c in checks]
    return {"parameter": {"names": [branch.parameter_names[0]],
                          "units": [branch.parameter_units[0]]},
            "expected": {"units": rows}, "simulated": {"units": rows},
            "exact": {"units": rows}}


def lyapunov_unit(state_units: tuple[str, ...]) -> str:
    """The unit of the first Lyapunov coefficient with SI states, 1/(s u^2) where every dof
    is in u (the first half of the states are the dofs)."""
    dofs = set(state_units[: len(state_units) // 2])
    unit = dofs.pop() if len(dofs) == 1 else "state_unit"
    return f"1/(s {unit}^2)" if unit != "1" else "1/s"


def _write_freeplay(branch: h5py.Group, found: FreeplayAmplitudes) -> None:
    write_record(branch.create_group(f"freeplay_{found.dof}"), found, FREEPLAY)


def _read_freeplay(name: str, branch: h5py.Group) -> list[FreeplayAmplitudes]:
    """The freeplay groups of the branch group ``name`` (none in files without freeplay)."""
    return [FreeplayAmplitudes(branch=name, **read_record(branch[key], FREEPLAY))
            for key in branch if key.startswith("freeplay_")]


def _write_boundary(group: h5py.Group, boundary: Boundary) -> None:
    write_record(group, boundary, BOUNDARY)
    pair = {"names": list(boundary.parameter_names), "units": list(boundary.parameter_units)}
    for name, (kind, curve) in boundary.loci.items():
        data = _collection(group, "loci").create_dataset(name, data=curve.reshape(-1, 2))
        data.attrs.update(kind=str(kind), **pair)  # the word, as text (h5py: no enums)
        if name in boundary.bounding_ends:
            data.attrs["bounding_ends"] = np.array(boundary.bounding_ends[name], dtype=np.int8)
    for k, polygon in enumerate(boundary.polygons):
        _collection(group, "unsafe").create_dataset(f"polygon_{k}", data=polygon).attrs.update(
            pair)
    first, second = boundary.parameter_units
    write_table(group.create_group("unsafe_intervals"), boundary.intervals, UNSAFE_INTERVAL,
                attributes={"slice_value": {"units": second}, "lower": {"units": first},
                            "upper": {"units": first}})


def _write_provenance(group: h5py.Group, found: Provenance) -> None:
    write_record(group, found, PROVENANCE)
    write_table(group.create_group("fixed"), found.fixed, FIXED_PARAMETER,
                attributes={"value": {"units": [p.unit for p in found.fixed]}})
    write_table(group.create_group("slice_labels"), found.slices, SLICE_LABEL)
    laws = _collection(group, "laws")
    for law in found.laws:
        write_record(laws.create_group(law.dof), law, LAW_CURVE)


def _read_provenance(handle: h5py.File) -> Provenance:
    """The provenance of a file: its root attributes, and ``provenance/`` where the file has
    it (else empty there: :func:`read` upgrades it)."""
    found = Provenance(**read_record(handle, PROVENANCE_ROOT))
    if "provenance" not in handle:
        return found
    group = handle["provenance"]
    laws = group.get("laws", {})
    return replace(
        found, **read_record(group, PROVENANCE),
        fixed=read_table(member(group, "fixed"), FixedParameter, FIXED_PARAMETER),
        slices=read_table(member(group, "slice_labels"), SliceLabel, SLICE_LABEL),
        laws=tuple(LawCurve(dof=dof, **read_record(laws[dof], LAW_CURVE))
                   for dof in _members(laws)))


def _write_grid(group: h5py.Group, grid: LinearGrid) -> None:
    write_record(group, grid, LINEAR_GRID)
    for kind in ("flutter", "divergence"):
        for k, line in enumerate(getattr(grid, kind)):
            _collection(group, kind).create_dataset(f"line_{k}", data=line).attrs.update(
                names=[grid.x_parameter, grid.y_parameter], units=[grid.x_unit, grid.y_unit])


def write(result: StudyResult, path: Path, overwrite: bool = False) -> Path:
    """Write ``result`` to ``path`` atomically; refuses to replace a file unless ``overwrite``.

    The file is built in memory and appears at ``path`` complete or not at all: it is written to
    an unnamed file in the output directory (Linux ``O_TMPFILE``) and linked into place, so even
    SIGKILL leaves no partial file and no temporary file behind. Without ``overwrite`` the link
    fails if ``path`` exists (also if it appeared meanwhile); with it, the old file, if a whirl
    result file (never anything else: :mod:`whirl_cli.output.guard`), is removed
    and the new one linked in its place (a SIGKILL in between leaves neither, see
    :func:`whirl_cli.output.atomic._link_unnamed`). Where ``O_TMPFILE`` is unavailable a
    hidden named temporary is written and renamed into place (a SIGKILL before the rename
    leaves it).
    """
    path = Path(path)
    check(path, RESULT, overwrite)
    if not path.parent.is_dir():
        raise OutputError(f"{path}: the output directory {path.parent} does not exist")
    return publish(_image(result), path, overwrite, what="the output", own=RESULT)


def _image(result: StudyResult) -> bytes:
    """The complete HDF5 file of ``result``, built in memory (never touches the disk)."""
    with h5py.File(f"whirl-{os.getpid()}-{id(result)}.h5", "w", driver="core",
                   backing_store=False) as handle:
        handle.attrs["whirl_schema"] = SCHEMA
        for key, value in sorted(result.root_attributes().items()):
            handle.attrs[key] = value
        _write_provenance(handle.create_group("provenance"), result.provenance)
        handle.attrs["study_name"] = result.study_name
        handle.attrs["model"] = result.model
        for continuation in result.continuations:
            _write_continuation(_collection(handle, "continuations").create_group(
                continuation.name), continuation)
        for sweep in result.linear_sweeps:
            write_record(_collection(handle.require_group("linear"), "sweeps").create_group(
                sweep.parameter), sweep, LINEAR_SWEEP)
        if result.linear_grid is not None:
            _write_grid(handle.create_group("linear/grid"), result.linear_grid)
        for boundary in result.boundaries:
            _write_boundary(_collection(handle, "boundaries").create_group(boundary.name),
                            boundary)
        units = [p.unit for p in result.parameters]
        write_table(handle.create_group("parameters"), result.parameters, PARAMETER,
                    attributes={"value": {"units": units}, "datum": {"units": units}})
        for found in result.simulations:
            write_record(_collection(handle, "simulations").create_group(found.name), found,
                         SIMULATION)
        runs = _collection(handle, "runs")
        for record in result.runs:
            write_record(runs.create_group(record.name), record, RUN)
        _record_contents(handle)
        handle.flush()
        return handle.id.get_file_image()


#: Attributes each group of a file gets last (files of this whirl): the names of its members,
#: or, for a collection (:func:`_collection`), their number. :func:`_check_contents` holds the
#: file to them, so that a deleted group or dataset is found, never read as none.
PARTS, COUNT = "whirl_parts", "whirl_count"
#: Both (what comparing two files leaves out: older files lack them).
CONTENTS = frozenset({PARTS, COUNT})


def _record_contents(handle: h5py.File) -> None:
    def record(group: h5py.Group) -> None:
        if _is_collection(group):
            group.attrs[COUNT] = len(group)
        else:
            group.attrs[PARTS] = sorted(group)

    record(handle["/"])
    handle.visititems(lambda _name, item: record(item) if isinstance(item, h5py.Group)
                      else None)


def _is_collection(group: h5py.Group) -> bool:
    """Whether ``group`` holds a collection: it tracks the order of its members."""
    order = group.id.get_create_plist().get_link_creation_order()
    return bool(order & h5py.h5p.CRT_ORDER_TRACKED)


def check_contents(handle: h5py.File) -> None:
    """:class:`Damaged` where a group lacks a member it was written with (its :data:`PARTS`)
    or has fewer or more members than written (its :data:`COUNT`), or, in an older file
    without them, where AUTO runs are recorded but no continuations."""
    def check(group: h5py.Group) -> None:
        for name in texts(np.atleast_1d(group.attrs.get(PARTS, ()))):
            member(group, name)
        if COUNT in group.attrs and len(group) != int(group.attrs[COUNT]):
            raise Damaged(group.name, f"{len(group)} of its {int(group.attrs[COUNT])} "
                          "members")

    check(handle["/"])
    handle.visititems(lambda _name, item: check(item) if isinstance(item, h5py.Group)
                      else None)
    if len(handle.get("runs", ())) and "continuations" not in handle:
        raise Damaged("/continuations", f"missing (the file records {len(handle['runs'])} "
                      "AUTO runs of continuations)")


# ------------------------------------------------------------------------------ reading
def _members(group, old_order=None) -> list[str]:
    """Names of the members of ``group`` in the order they were written (files since whirl
    tracks it, see :func:`_collection`); in older files by name, or sorted by ``old_order``."""
    names = list(group)  # h5py lists by creation order where it is tracked, else by name
    tracked = isinstance(group, h5py.Group) and _is_collection(group)
    return names if tracked or old_order is None else sorted(names, key=old_order)


def _number(name: str) -> int:
    """The number ending a member name: ``polygon_12`` -> 12."""
    return int(name.rsplit("_", 1)[-1])


def _read_branch(name: str, group: h5py.Group) -> Branch:
    orbits = group.get("orbits", {})
    return Branch(name=name, **read_record(group, BRANCH), orbits=tuple(
        Orbit(label=int(label), **read_record(orbits[label], ORBIT))
        for label in _members(orbits, int)))


def _read_continuation(name: str, group: h5py.Group) -> ContinuationResult:
    branches = member(group, "branches")
    found = ContinuationResult(
        name, read_record(group, CONTINUATION)["kind"],
        tuple(_read_branch(b, g) for b, g in branches.items()),
        read_table(member(group, "special_points"), SpecialPoint, SPECIAL_POINT),
        read_table(group["cross_checks"], CrossCheck, CROSS_CHECK)
        if "cross_checks" in group else (),
        tuple(f for b, g in branches.items() for f in _read_freeplay(b, g)),
        read_table(group["seeds"], SeedOutcome, SEED) if "seeds" in group else (),
        _read_explorations(group.get("explorations", {})))
    for table, rows in (("special_points", found.special_points),
                        ("cross_checks", found.cross_checks)):
        _check_branches(group, table, rows, {b.name for b in found.branches})
    return found


def _check_branches(group: h5py.Group, table: str, rows, names: set[str]) -> None:
    """:class:`Damaged` where a row of ``table`` is on a branch the file does not hold."""
    missing = sorted({row.branch for row in rows} - names)
    if missing:
        raise Damaged(f"{group.name}/{table}/branch", f"names branch {missing[0]!r}, "
                      f"which is not in {group.name}/branches")


def _read_explorations(group) -> tuple[Exploration, ...]:
    """The explorations of a continuation, in their order (none in older files)."""
    found = []
    for key in _members(group, int):
        values = read_record(group[key], EXPLORATION)
        for name in ("value", "lyapunov", "lyapunov_error", "section_dimension", "broadband"):
            values[name] = float(values[name])
        found.append(Exploration(**values))
    return tuple(found)


def _read_boundary(name: str, group: h5py.Group) -> Boundary:
    loci = {key: (word(LocusKind, text(attribute(data, "kind")), data.name, "locus kind"),
                  data[()]) for key, data in group.get("loci", {}).items()}
    polygons = tuple(group["unsafe"][key][()] for key in _members(group.get("unsafe", {}),
                                                                   _number))
    ends = {key: tuple(bool(v) for v in data.attrs["bounding_ends"])
            for key, data in group.get("loci", {}).items() if "bounding_ends" in data.attrs}
    return Boundary(name=name, **read_record(group, BOUNDARY), loci=loci, polygons=polygons,
                    intervals=read_table(member(group, "unsafe_intervals"), UnsafeInterval,
                                         UNSAFE_INTERVAL), bounding_ends=ends)


def _read_grid(group: h5py.Group) -> LinearGrid:
    def lines(kind: str) -> tuple[np.ndarray, ...]:
        found = group.get(kind, {})
        return tuple(found[k][()] for k in _members(found, _number))

    return LinearGrid(**read_record(group, LINEAR_GRID), flutter=lines("flutter"),
                      divergence=lines("divergence"))


#: What reading a file that does not hold what a whirl result file holds can raise (h5py
#: raises KeyError for a missing group or attribute, OSError for unreadable data, ValueError,
#: TypeError or IndexError for data of the wrong type or shape).
_DAMAGED = (KeyError, OSError, ValueError, TypeError, IndexError)


@contextmanager
def opened(path: Path) -> Iterator[h5py.File]:
    """``path`` opened with h5py for reading, for the readers of result files (:func:`read`,
    :mod:`whirl_cli.output.compare`). A file that is not HDF5, a truncated or unreadable one,
    and one missing what its reader looks up inside the ``with`` block raise
    :class:`OutputError` as one line ``<path>: <reason>``, never an h5py traceback."""
    try:
        handle = h5py.File(path, "r")
    except OSError as error:
        raise OutputError(f"{path}: {_open_failure(error)}") from None
    try:
        with handle:
            yield handle
    except Damaged as error:
        raise OutputError(f"{path}: a damaged whirl result file ({error})") from None
    except _DAMAGED as error:
        raise OutputError(f"{path}: not a complete whirl result file "
                          f"({_reason(error)})") from None


def _reason(error: Exception) -> str:
    """h5py's reason of an error: the text in its ``Unable to ... (reason)`` message."""
    text = str(error.args[0]) if isinstance(error, KeyError) and error.args else str(error)
    found = re.search(r"\((.*)\)\s*$", text)
    return found.group(1) if found else text


def _open_failure(error: OSError) -> str:
    """Why h5py could not open a file, in words."""
    reason = _reason(error)
    if "file signature not found" in reason:
        return "not an HDF5 file"
    truncated = re.search(r"truncated file: eof = (\d+).*stored_eof = (\d+)", reason)
    if truncated:
        return (f"truncated HDF5 file ({truncated.group(1)} of its {truncated.group(2)} "
                "bytes)")
    if "Permission denied" in reason or "errno = 13" in reason:
        return "cannot read the file (permission denied)"
    return f"cannot read as HDF5 ({reason})"


def read(path: Path) -> StudyResult:
    """The :class:`StudyResult` stored in a whirl HDF5 file, upgraded if an older whirl wrote
    it (module doc); :class:`OutputError` (one line naming the file) for a file that is not
    HDF5, not a whirl file, truncated or damaged."""
    with opened(path) as handle:
        if "whirl_schema" not in handle.attrs:
            raise OutputError(f"{path}: an HDF5 file but not a whirl result file (no "
                              "whirl_schema attribute)")
        schema = int(handle.attrs["whirl_schema"])
        if schema not in READABLE:
            raise OutputError(f"{path}: a whirl result file of schema {schema}; this whirl "
                              f"reads schemas {', '.join(map(str, READABLE))}")
        check_contents(handle)
        continuations = tuple(_read_continuation(name, group)
                              for name, group in handle.get("continuations", {}).items())
        sweeps = tuple(LinearSweep(**read_record(group, LINEAR_SWEEP))
                       for group in handle.get("linear/sweeps", {}).values())
        runs = tuple(RunRecord(name=name, **read_record(group, RUN))
                     for name, group in member(handle, "runs").items())
        grid = _read_grid(handle["linear/grid"]) if "linear/grid" in handle else None
        boundaries = tuple(_read_boundary(name, group)
                           for name, group in handle.get("boundaries", {}).items())
        skip = {"whirl_schema", "study_name", "model", PARTS, *ROOT_FIELDS}
        attributes = {k: (text(v) if isinstance(v, bytes | str) else v)
                      for k, v in handle.attrs.items() if k not in skip}
        parameters = read_table(member(handle, "parameters"), ParameterValue, PARAMETER) \
            if schema >= 2 else ()
        found = _read_provenance(handle)
        simulations = tuple(Simulation(name=name, **read_record(group, SIMULATION),
                                       first_order=found.first_order)
                            for name, group in handle.get("simulations", {}).items())
        result = StudyResult(text(attribute(handle, "study_name")),
                             text(attribute(handle, "model")),
                             continuations, sweeps, runs, attributes, boundaries, grid,
                             parameters, simulations, found)
        if "provenance" in handle:
            return result
    from .provenance import upgraded  # a file of an older whirl: the one place it is upgraded

    return upgraded(result)
