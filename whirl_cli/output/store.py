"""HDF5 output: the one writer and the one reader of whirl's result files (schema 1).

Layout (units in a ``units`` attribute on every physical dataset)::

    /                               attrs: whirl_schema, whirl_version, auto_version, study_name,
                                           study_yaml, study_sha256, model, created, git_describe
    /continuations/<name>/          attrs: kind (one-parameter | two-parameter)
        branches/<branch>/          attrs: kind, origin, status, message, run
            parameters   (N, P)     attrs: names, units
            state_max, state_min (N, n)  attrs: names, units
            l2_norm (N,) ; period (N,) [s] ; stable (N,) bool (AUTO's flag) ;
            stability_known (N,) bool (False: no eigenvalues/multipliers, or a locus;
                                       absent in older files: all known)
            point_type (N,) int (whirl PointType = AUTO TY codes) ; label (N,) int
            eigenvalues (N, n) complex [1/s]   (equilibria)  or
            floquet_multipliers (N, n) complex (periodic orbits)
            orbits/<label>/ time (K,) [s], states (K, n)  attrs: point_type, index, period,
                                                                parameters
            freeplay_<dof>/ (periodic, freeplay law on dof) amplitude_ratio (N,) = A/delta;
                            describing_function/ amplitude_ratio, stiffness, parameter (M,)
        special_points/             columns: branch, index, point_type, type_name, label,
                                    parameters (K, P), state (K, n), period, stable, status,
                                    criticality, note, bracket (K, 2), residual,
                                    lyapunov (first Lyapunov coefficient of Hopf points)
        cross_checks/               (study `cross_check: true`) columns: branch, index, kind
                                    (orbit | equilibrium), parameter, expected, simulated,
                                    passed, state (the dof an orbit check compares),
                                    exact (an orbit's max by the exact piecewise law; NaN)
    /linear/sweeps/<parameter>/     values, eigenvalues [1/s], damping_ratio, frequency [rad/s],
                                    whirl (FW | BW | --)
    /linear/grid/                   x, y, max_real (Ny, Nx) [1/s], oscillatory (Ny, Nx),
                                    flutter/line_<k>, divergence/line_<k> (K, 2): zero contour
    /boundaries/<name>/             attrs: parameters, units, method (loci | slices), slices
        loci/<branch>               (K, 2) locus curve in the two parameters; attrs kind
        unsafe/polygon_<k>          (K, 2) closed outline of the unsafe region
        unsafe_intervals/           slice_value, lower, upper, cause (flutter | divergence)
    /runs/<run>                     attrs: status, message, constants, returncode,
                                           wall_seconds, n_points

The groups holding collections (continuations, branches, orbits, sweeps, boundaries, loci,
polygons, contour lines, runs) track the creation order of their members, so a round trip
keeps the order of the study and its results; older files list (and read) by name.

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
from pathlib import Path

import h5py
import numpy as np

from ..errors import OutputError
from ..results import (
    Boundary,
    Branch,
    BranchKind,
    ContinuationResult,
    CrossCheck,
    FreeplayAmplitudes,
    LinearGrid,
    LinearSweep,
    Orbit,
    RunRecord,
    SpecialPoint,
    StudyResult,
    UnsafeInterval,
)
from .atomic import publish

SCHEMA = 1
_STR = h5py.string_dtype()


def _strings(values) -> np.ndarray:
    return np.array([str(v) for v in values], dtype=object)


def _collection(parent: h5py.Group, name: str) -> h5py.Group:
    """The group ``name`` of ``parent`` that holds a collection (continuations, branches,
    orbits, sweeps, boundaries, loci, runs, ...), created tracking the order in which its
    members are written, so that :func:`read` returns them in that order; HDF5 lists them by
    name otherwise (``periodic_10`` before ``periodic_2``)."""
    if name in parent:
        return parent[name]
    return parent.create_group(name, track_order=True)


def _write_branch(group: h5py.Group, branch: Branch) -> None:
    group.attrs.update(kind=branch.kind, origin=branch.origin, status=branch.status,
                       message=branch.message, run=branch.run, end=branch.end)
    params = group.create_dataset("parameters", data=np.reshape(
        branch.parameters, (len(branch), len(branch.parameter_names))))
    params.attrs.update(names=list(branch.parameter_names), units=list(branch.parameter_units))
    for key in ("state_max", "state_min"):
        data = group.create_dataset(key, data=getattr(branch, key))
        data.attrs.update(names=list(branch.state_names), units=list(branch.state_units))
    group.create_dataset("l2_norm", data=branch.l2_norm).attrs["units"] = "1"
    group.create_dataset("period", data=branch.period).attrs["units"] = "s"
    group.create_dataset("stable", data=branch.stable.astype(bool))
    group.create_dataset("stability_known", data=branch.stability_known.astype(bool))
    group.create_dataset("point_type", data=branch.point_type.astype(np.int64))
    group.create_dataset("label", data=branch.label.astype(np.int64))
    if branch.is_periodic:
        group.create_dataset("floquet_multipliers", data=branch.eigenvalues).attrs["units"] = "1"
    else:
        group.create_dataset("eigenvalues", data=branch.eigenvalues).attrs["units"] = "1/s"
    for orbit in branch.orbits:
        sub = _collection(group, "orbits").create_group(str(orbit.label))
        sub.attrs.update(point_type=orbit.point_type, index=orbit.index, period=orbit.period,
                         parameters=orbit.parameters)
        sub.create_dataset("time", data=orbit.time).attrs["units"] = "s"
        states = sub.create_dataset("states", data=orbit.states)
        states.attrs.update(names=list(branch.state_names), units=list(branch.state_units))


def _write_special_points(group: h5py.Group, points: tuple[SpecialPoint, ...],
                          n_states: int) -> None:
    n_params = len(points[0].parameter_names) if points else 1
    group.create_dataset("branch", data=_strings(p.branch for p in points), dtype=_STR)
    group.create_dataset("index", data=np.array([p.index for p in points], dtype=np.int64))
    group.create_dataset("point_type",
                         data=np.array([p.point_type for p in points], dtype=np.int64))
    group.create_dataset("type_name", data=_strings(p.type_name for p in points), dtype=_STR)
    group.create_dataset("label", data=np.array([p.label for p in points], dtype=np.int64))
    params = group.create_dataset(
        "parameters", data=np.array([p.parameters for p in points]).reshape(-1, n_params))
    params.attrs["names"] = list(points[0].parameter_names) if points else []
    group.create_dataset("state",
                         data=np.array([p.state for p in points]).reshape(-1, n_states))
    group.create_dataset("period", data=np.array([p.period for p in points], dtype=float))
    group.create_dataset("stable", data=np.array([p.stable for p in points], dtype=bool))
    for key in ("status", "criticality", "note"):
        group.create_dataset(key, data=_strings(getattr(p, key) for p in points), dtype=_STR)
    group.create_dataset("bracket", data=np.array([p.bracket for p in points]).reshape(-1, 2))
    group.create_dataset("residual", data=np.array([p.residual for p in points], dtype=float))
    lyapunov = group.create_dataset("lyapunov",
                                    data=np.array([p.lyapunov for p in points], dtype=float))
    lyapunov.attrs["units"] = "1/(s*state_unit^2)"


def _write_cross_checks(group: h5py.Group, checks: tuple[CrossCheck, ...]) -> None:
    group.create_dataset("branch", data=_strings(c.branch for c in checks), dtype=_STR)
    group.create_dataset("index", data=np.array([c.index for c in checks], dtype=np.int64))
    group.create_dataset("kind", data=_strings(c.kind for c in checks), dtype=_STR)
    for key in ("parameter", "expected", "simulated"):
        group.create_dataset(key, data=np.array([getattr(c, key) for c in checks], dtype=float))
    group.create_dataset("exact", data=np.array(
        [np.nan if c.exact is None else c.exact for c in checks], dtype=float))
    group.create_dataset("passed", data=np.array([c.passed for c in checks], dtype=bool))
    group.create_dataset("state", data=_strings(c.state for c in checks), dtype=_STR)


def _read_cross_checks(group: h5py.Group) -> tuple[CrossCheck, ...]:
    columns = {key: group[key][()] for key in group}
    return tuple(
        CrossCheck(_text(columns["branch"][k]), int(columns["index"][k]),
                   _text(columns["kind"][k]), float(columns["parameter"][k]),
                   float(columns["expected"][k]), float(columns["simulated"][k]),
                   bool(columns["passed"][k]),
                   _text(columns["state"][k]) if "state" in columns else "",
                   _exact(columns, k))
        for k in range(len(columns["index"])))


def _write_freeplay(branch: h5py.Group, found: FreeplayAmplitudes) -> None:
    """``<branch>/freeplay_<dof>/``: amplitude_ratio (N,) = A/delta; describing_function/
    amplitude_ratio, stiffness, parameter (M,) (results.FreeplayAmplitudes)."""
    group = branch.create_group(f"freeplay_{found.dof}")
    group.attrs["dof"] = found.dof
    group.create_dataset("amplitude_ratio", data=found.amplitude_ratio).attrs["units"] = "1"
    estimate = group.create_group("describing_function")
    estimate.create_dataset("amplitude_ratio", data=found.estimate_ratio)
    estimate.create_dataset("stiffness", data=found.estimate_stiffness)
    estimate.create_dataset("parameter", data=found.estimate_parameter)


def _read_freeplay(name: str, branch: h5py.Group) -> list[FreeplayAmplitudes]:
    """The freeplay groups of the branch group ``name`` (none in files without freeplay)."""
    found = []
    for key in (k for k in branch if k.startswith("freeplay_")):
        group = branch[key]
        estimate = group["describing_function"]
        found.append(FreeplayAmplitudes(
            name, _text(group.attrs["dof"]), group["amplitude_ratio"][()],
            estimate["amplitude_ratio"][()], estimate["stiffness"][()],
            estimate["parameter"][()]))
    return found


def _exact(columns: dict, k: int) -> float | None:
    """The exact-law maximum of cross-check ``k`` (None: not simulated, or an older file)."""
    value = float(columns["exact"][k]) if "exact" in columns else float("nan")
    return value if np.isfinite(value) else None


def _write_boundary(group: h5py.Group, boundary: Boundary) -> None:
    group.attrs.update(parameters=list(boundary.parameter_names),
                       units=list(boundary.parameter_units), method=boundary.method,
                       slices=np.array(boundary.slices, dtype=float))
    for name, (kind, curve) in boundary.loci.items():
        data = _collection(group, "loci").create_dataset(name, data=curve.reshape(-1, 2))
        data.attrs["kind"] = kind
    for k, polygon in enumerate(boundary.polygons):
        _collection(group, "unsafe").create_dataset(f"polygon_{k}", data=polygon)
    table = group.create_group("unsafe_intervals")
    rows = boundary.intervals
    for key in ("slice_value", "lower", "upper"):
        table.create_dataset(key, data=np.array([getattr(r, key) for r in rows], dtype=float))
    table.create_dataset("cause", data=_strings(r.cause for r in rows), dtype=_STR)


def _read_boundary(name: str, group: h5py.Group) -> Boundary:
    loci = {key: (_text(data.attrs["kind"]), data[()])
            for key, data in group.get("loci", {}).items()}
    polygons = tuple(group["unsafe"][key][()] for key in _members(group.get("unsafe", {}),
                                                                   _number))
    table = group["unsafe_intervals"]
    intervals = tuple(
        UnsafeInterval(float(v), float(lo), float(hi), _text(c)) for v, lo, hi, c in zip(
            table["slice_value"][()], table["lower"][()], table["upper"][()],
            table["cause"][()], strict=True))
    return Boundary(name, _texts(group.attrs["parameters"]), _texts(group.attrs["units"]),
                    _text(group.attrs["method"]), loci, intervals, polygons,
                    tuple(float(v) for v in group.attrs["slices"]))


def _write_grid(group: h5py.Group, grid: LinearGrid) -> None:
    group.attrs.update(x_parameter=grid.x_parameter, y_parameter=grid.y_parameter)
    group.create_dataset("x", data=grid.x).attrs["units"] = grid.x_unit
    group.create_dataset("y", data=grid.y).attrs["units"] = grid.y_unit
    group.create_dataset("max_real", data=grid.max_real).attrs["units"] = "1/s"
    group.create_dataset("oscillatory", data=grid.oscillatory)
    for kind in ("flutter", "divergence"):
        for k, line in enumerate(getattr(grid, kind)):
            _collection(group, kind).create_dataset(f"line_{k}", data=line)


def _read_grid(group: h5py.Group) -> LinearGrid:
    def lines(kind: str) -> tuple[np.ndarray, ...]:
        found = group.get(kind, {})
        return tuple(found[k][()] for k in _members(found, _number))

    return LinearGrid(_text(group.attrs["x_parameter"]), _text(group.attrs["y_parameter"]),
                      _text(group["x"].attrs["units"]), _text(group["y"].attrs["units"]),
                      group["x"][()], group["y"][()], group["max_real"][()],
                      group["oscillatory"][()], lines("flutter"), lines("divergence"))


def _write_sweep(group: h5py.Group, sweep: LinearSweep) -> None:
    group.attrs["parameter"] = sweep.parameter
    group.create_dataset("values", data=sweep.values).attrs["units"] = sweep.unit
    group.create_dataset("eigenvalues", data=sweep.eigenvalues).attrs["units"] = "1/s"
    group.create_dataset("damping_ratio", data=sweep.damping_ratio).attrs["units"] = "1"
    group.create_dataset("frequency", data=sweep.frequency).attrs["units"] = "rad/s"
    group.create_dataset("whirl", data=sweep.whirl.astype(object), dtype=_STR)


def write(result: StudyResult, path: Path, overwrite: bool = False) -> Path:
    """Write ``result`` to ``path`` atomically; refuses to replace a file unless ``overwrite``.

    The file is built in memory and appears at ``path`` complete or not at all: it is written to
    an unnamed file in the output directory (Linux ``O_TMPFILE``) and linked into place, so even
    SIGKILL leaves no partial file and no temporary file behind. Without ``overwrite`` the link
    fails if ``path`` exists (also if it appeared meanwhile); with it, the old file is removed
    and the new one linked in its place (a SIGKILL in between leaves neither, see
    :func:`whirl_cli.output.atomic._link_unnamed`). Where ``O_TMPFILE`` is unavailable a
    hidden named temporary is written and renamed into place (a SIGKILL before the rename
    leaves it).
    """
    path = Path(path)
    if path.exists() and not overwrite:
        raise OutputError(f"{path}: output exists; pass --overwrite to replace it")
    if not path.parent.is_dir():
        raise OutputError(f"{path}: the output directory {path.parent} does not exist")
    return publish(_image(result), path, overwrite, what="the output")


def _image(result: StudyResult) -> bytes:
    """The complete HDF5 file of ``result``, built in memory (never touches the disk)."""
    with h5py.File(f"whirl-{os.getpid()}-{id(result)}.h5", "w", driver="core",
                   backing_store=False) as handle:
        handle.attrs["whirl_schema"] = SCHEMA
        for key, value in sorted(result.attributes.items()):
            handle.attrs[key] = value
        handle.attrs["study_name"] = result.study_name
        handle.attrs["model"] = result.model
        for continuation in result.continuations:
            group = _collection(handle, "continuations").create_group(continuation.name)
            group.attrs["kind"] = continuation.kind
            n_states = len(continuation.branches[0].state_names) if continuation.branches \
                else 0
            for branch in continuation.branches:
                _write_branch(_collection(group, "branches").create_group(branch.name), branch)
            for found in continuation.freeplay:
                _write_freeplay(group["branches"][found.branch], found)
            _write_special_points(group.create_group("special_points"),
                                  continuation.special_points, n_states)
            if continuation.cross_checks:
                _write_cross_checks(group.create_group("cross_checks"),
                                    continuation.cross_checks)
        for sweep in result.linear_sweeps:
            _write_sweep(_collection(handle.require_group("linear"), "sweeps").create_group(
                sweep.parameter), sweep)
        if result.linear_grid is not None:
            _write_grid(handle.create_group("linear/grid"), result.linear_grid)
        for boundary in result.boundaries:
            _write_boundary(_collection(handle, "boundaries").create_group(boundary.name),
                            boundary)
        runs = _collection(handle, "runs")
        for record in result.runs:
            runs.create_group(record.name).attrs.update(
                status=record.status, message=record.message, constants=record.constants,
                returncode=record.returncode, wall_seconds=record.wall_seconds,
                n_points=record.n_points)
        handle.flush()
        return handle.id.get_file_image()


def _text(value) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def _texts(values) -> tuple[str, ...]:
    return tuple(_text(v) for v in values)


def _members(group, old_order=None) -> list[str]:
    """Names of the members of ``group`` in the order they were written (files since whirl
    tracks it, see :func:`_collection`); in older files by name, or sorted by ``old_order``."""
    names = list(group)  # h5py lists by creation order where it is tracked, else by name
    tracked = isinstance(group, h5py.Group) and \
        group.id.get_create_plist().get_link_creation_order() & h5py.h5p.CRT_ORDER_TRACKED
    return names if tracked or old_order is None else sorted(names, key=old_order)


def _number(name: str) -> int:
    """The number ending a member name: ``polygon_12`` -> 12."""
    return int(name.rsplit("_", 1)[-1])


def _read_branch(name: str, group: h5py.Group) -> Branch:
    params = group["parameters"]
    kind = _text(group.attrs["kind"])
    key = "floquet_multipliers" if kind == BranchKind.PERIODIC else "eigenvalues"
    orbits = []
    if "orbits" in group:
        for label in _members(group["orbits"], int):
            sub = group["orbits"][label]
            orbits.append(Orbit(int(label), int(sub.attrs["point_type"]),
                                int(sub.attrs["index"]), np.asarray(sub.attrs["parameters"]),
                                float(sub.attrs["period"]), sub["time"][()],
                                sub["states"][()]))
    return Branch(
        name=name, kind=kind, origin=_text(group.attrs["origin"]),
        parameter_names=_texts(params.attrs["names"]),
        parameter_units=_texts(params.attrs["units"]),
        state_names=_texts(group["state_max"].attrs["names"]),
        state_units=_texts(group["state_max"].attrs["units"]),
        parameters=params[()], state_max=group["state_max"][()],
        state_min=group["state_min"][()], l2_norm=group["l2_norm"][()],
        period=group["period"][()], stable=group["stable"][()].astype(bool),
        stability_known=group["stability_known"][()].astype(bool)
        if "stability_known" in group else None,  # files from before: known everywhere
        point_type=group["point_type"][()], label=group["label"][()],
        eigenvalues=group[key][()], status=_text(group.attrs["status"]),
        message=_text(group.attrs["message"]), run=_text(group.attrs["run"]),
        orbits=tuple(orbits), end=_text(group.attrs["end"]))


def _read_special_points(group: h5py.Group) -> tuple[SpecialPoint, ...]:
    names = _texts(group["parameters"].attrs["names"])
    columns = {key: group[key][()] for key in group}
    return tuple(
        SpecialPoint(
            branch=_text(columns["branch"][k]), index=int(columns["index"][k]),
            point_type=int(columns["point_type"][k]), parameter_names=names,
            parameters=columns["parameters"][k], state=columns["state"][k],
            period=float(columns["period"][k]), stable=bool(columns["stable"][k]),
            label=int(columns["label"][k]), status=_text(columns["status"][k]),
            criticality=_text(columns["criticality"][k]), note=_text(columns["note"][k]),
            bracket=columns["bracket"][k], residual=float(columns["residual"][k]),
            lyapunov=float(columns["lyapunov"][k]) if "lyapunov" in columns else float("nan"))
        for k in range(len(columns["index"])))


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
    """The :class:`StudyResult` stored in a whirl HDF5 file; :class:`OutputError` (one line
    naming the file) for a file that is not HDF5, not a whirl file, truncated or damaged."""
    with opened(path) as handle:
        if "whirl_schema" not in handle.attrs:
            raise OutputError(f"{path}: an HDF5 file but not a whirl result file (no "
                              "whirl_schema attribute)")
        schema = int(handle.attrs["whirl_schema"])
        if schema != SCHEMA:
            raise OutputError(f"{path}: not a whirl result file of schema {SCHEMA} "
                              f"(found {schema})")
        continuations = []
        for name, group in handle.get("continuations", {}).items():
            branches = tuple(_read_branch(b, g) for b, g in group.get("branches", {}).items())
            checks = _read_cross_checks(group["cross_checks"]) if "cross_checks" in group \
                else ()
            freeplay = tuple(f for b, g in group.get("branches", {}).items()
                             for f in _read_freeplay(b, g))
            continuations.append(ContinuationResult(
                name, _text(group.attrs["kind"]), branches,
                _read_special_points(group["special_points"]), checks, freeplay))
        sweeps = []
        for parameter, group in handle.get("linear/sweeps", {}).items():
            sweeps.append(LinearSweep(
                parameter, _text(group["values"].attrs["units"]), group["values"][()],
                group["eigenvalues"][()], group["damping_ratio"][()],
                group["frequency"][()],
                np.array(_texts(group["whirl"][()].ravel())).reshape(group["whirl"].shape)))
        runs = tuple(
            RunRecord(name, _text(g.attrs["status"]), _text(g.attrs["message"]),
                      _text(g.attrs["constants"]), int(g.attrs["returncode"]),
                      float(g.attrs["wall_seconds"]), int(g.attrs["n_points"]))
            for name, g in handle.get("runs", {}).items())
        grid = _read_grid(handle["linear/grid"]) if "linear/grid" in handle else None
        boundaries = tuple(_read_boundary(name, group)
                           for name, group in handle.get("boundaries", {}).items())
        skip = {"whirl_schema", "study_name", "model"}
        attributes = {k: (_text(v) if isinstance(v, bytes | str) else v)
                      for k, v in handle.attrs.items() if k not in skip}
        return StudyResult(_text(handle.attrs["study_name"]), _text(handle.attrs["model"]),
                           tuple(continuations), tuple(sweeps), runs, attributes, boundaries,
                           grid)

