"""HDF5 output: the one writer and the one reader of whirl's result files (schema 1).

Layout (units in a ``units`` attribute on every physical dataset)::

    /                               attrs: whirl_schema, whirl_version, auto_version, study_name,
                                           study_yaml, study_sha256, model, created, git_describe
    /continuations/<name>/          attrs: kind (one-parameter | two-parameter)
        branches/<branch>/          attrs: kind, origin, status, message, run
            parameters   (N, P)     attrs: names, units
            state_max, state_min (N, n)  attrs: names, units
            l2_norm (N,) ; period (N,) [s] ; stable (N,) bool
            point_type (N,) int (whirl PointType = AUTO TY codes) ; label (N,) int
            eigenvalues (N, n) complex [1/s]   (equilibria)  or
            floquet_multipliers (N, n) complex (periodic orbits)
            orbits/<label>/ time (K,) [s], states (K, n)  attrs: point_type, index, period,
                                                                parameters
        special_points/             columns: branch, index, point_type, type_name, label,
                                    parameters (K, P), state (K, n), period, stable, status,
                                    criticality, note, bracket (K, 2), residual
        cross_checks/               (study `cross_check: true`) columns: branch, index, kind
                                    (orbit | equilibrium), parameter, expected, simulated,
                                    passed
    /linear/sweeps/<parameter>/     values, eigenvalues [1/s], damping_ratio, frequency [rad/s],
                                    whirl (FW | BW | --)
    /runs/<run>                     attrs: status, message, constants, returncode,
                                           wall_seconds, n_points

The file is written to a temporary name in the output directory and renamed into place, so an
output path never holds a partial file.
"""

from __future__ import annotations

import os
from pathlib import Path

import h5py
import numpy as np

from .errors import OutputError
from .results import (
    Branch,
    BranchKind,
    ContinuationResult,
    CrossCheck,
    LinearSweep,
    Orbit,
    RunRecord,
    SpecialPoint,
    StudyResult,
)

SCHEMA = 1
_STR = h5py.string_dtype()


def _strings(values) -> np.ndarray:
    return np.array([str(v) for v in values], dtype=object)


def _write_branch(group: h5py.Group, branch: Branch) -> None:
    group.attrs.update(kind=branch.kind, origin=branch.origin, status=branch.status,
                       message=branch.message, run=branch.run, end=branch.end)
    params = group.create_dataset("parameters", data=branch.parameters.reshape(len(branch), -1))
    params.attrs.update(names=list(branch.parameter_names), units=list(branch.parameter_units))
    for key in ("state_max", "state_min"):
        data = group.create_dataset(key, data=getattr(branch, key))
        data.attrs.update(names=list(branch.state_names), units=list(branch.state_units))
    group.create_dataset("l2_norm", data=branch.l2_norm).attrs["units"] = "1"
    group.create_dataset("period", data=branch.period).attrs["units"] = "s"
    group.create_dataset("stable", data=branch.stable.astype(bool))
    group.create_dataset("point_type", data=branch.point_type.astype(np.int64))
    group.create_dataset("label", data=branch.label.astype(np.int64))
    if branch.is_periodic:
        group.create_dataset("floquet_multipliers", data=branch.eigenvalues).attrs["units"] = "1"
    else:
        group.create_dataset("eigenvalues", data=branch.eigenvalues).attrs["units"] = "1/s"
    for orbit in branch.orbits:
        sub = group.create_group(f"orbits/{orbit.label}")
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


def _write_cross_checks(group: h5py.Group, checks: tuple[CrossCheck, ...]) -> None:
    group.create_dataset("branch", data=_strings(c.branch for c in checks), dtype=_STR)
    group.create_dataset("index", data=np.array([c.index for c in checks], dtype=np.int64))
    group.create_dataset("kind", data=_strings(c.kind for c in checks), dtype=_STR)
    for key in ("parameter", "expected", "simulated"):
        group.create_dataset(key, data=np.array([getattr(c, key) for c in checks], dtype=float))
    group.create_dataset("passed", data=np.array([c.passed for c in checks], dtype=bool))


def _read_cross_checks(group: h5py.Group) -> tuple[CrossCheck, ...]:
    columns = {key: group[key][()] for key in group}
    return tuple(
        CrossCheck(_text(columns["branch"][k]), int(columns["index"][k]),
                   _text(columns["kind"][k]), float(columns["parameter"][k]),
                   float(columns["expected"][k]), float(columns["simulated"][k]),
                   bool(columns["passed"][k]))
        for k in range(len(columns["index"])))


def _write_sweep(group: h5py.Group, sweep: LinearSweep) -> None:
    group.attrs["parameter"] = sweep.parameter
    group.create_dataset("values", data=sweep.values).attrs["units"] = sweep.unit
    group.create_dataset("eigenvalues", data=sweep.eigenvalues).attrs["units"] = "1/s"
    group.create_dataset("damping_ratio", data=sweep.damping_ratio).attrs["units"] = "1"
    group.create_dataset("frequency", data=sweep.frequency).attrs["units"] = "rad/s"
    group.create_dataset("whirl", data=sweep.whirl.astype(object), dtype=_STR)


def write(result: StudyResult, path: Path, overwrite: bool = False) -> Path:
    """Write ``result`` to ``path`` atomically; refuses to replace a file unless ``overwrite``."""
    path = Path(path)
    if path.exists() and not overwrite:
        raise OutputError(f"{path}: output exists; pass --overwrite to replace it")
    if not path.parent.is_dir():
        raise OutputError(f"{path}: the output directory {path.parent} does not exist")
    temporary = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    try:
        with h5py.File(temporary, "w") as handle:
            handle.attrs["whirl_schema"] = SCHEMA
            for key, value in sorted(result.attributes.items()):
                handle.attrs[key] = value
            handle.attrs["study_name"] = result.study_name
            handle.attrs["model"] = result.model
            for continuation in result.continuations:
                group = handle.create_group(f"continuations/{continuation.name}")
                group.attrs["kind"] = continuation.kind
                n_states = len(continuation.branches[0].state_names) if continuation.branches \
                    else 0
                for branch in continuation.branches:
                    _write_branch(group.create_group(f"branches/{branch.name}"), branch)
                _write_special_points(group.create_group("special_points"),
                                      continuation.special_points, n_states)
                if continuation.cross_checks:
                    _write_cross_checks(group.create_group("cross_checks"),
                                        continuation.cross_checks)
            for sweep in result.linear_sweeps:
                _write_sweep(handle.create_group(f"linear/sweeps/{sweep.parameter}"), sweep)
            runs = handle.create_group("runs")
            for record in result.runs:
                runs.create_group(record.name).attrs.update(
                    status=record.status, message=record.message, constants=record.constants,
                    returncode=record.returncode, wall_seconds=record.wall_seconds,
                    n_points=record.n_points)
            handle.flush()
            os.fsync(handle.id.get_vfd_handle())
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    return path


# ----------------------------------------------------------------------------------- reading
def _text(value) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def _texts(values) -> tuple[str, ...]:
    return tuple(_text(v) for v in values)


def _read_branch(name: str, group: h5py.Group) -> Branch:
    params = group["parameters"]
    kind = _text(group.attrs["kind"])
    key = "floquet_multipliers" if kind == BranchKind.PERIODIC else "eigenvalues"
    orbits = []
    if "orbits" in group:
        for label in sorted(group["orbits"], key=int):
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
            bracket=columns["bracket"][k], residual=float(columns["residual"][k]))
        for k in range(len(columns["index"])))


def read(path: Path) -> StudyResult:
    """The :class:`StudyResult` stored in a whirl HDF5 file."""
    with h5py.File(path, "r") as handle:
        schema = int(handle.attrs.get("whirl_schema", -1))
        if schema != SCHEMA:
            raise OutputError(f"{path}: not a whirl result file of schema {SCHEMA} "
                              f"(found {schema})")
        continuations = []
        for name, group in handle.get("continuations", {}).items():
            branches = tuple(_read_branch(b, g) for b, g in group["branches"].items())
            checks = _read_cross_checks(group["cross_checks"]) if "cross_checks" in group \
                else ()
            continuations.append(ContinuationResult(
                name, _text(group.attrs["kind"]), branches,
                _read_special_points(group["special_points"]), checks))
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
        skip = {"whirl_schema", "study_name", "model"}
        attributes = {k: (_text(v) if isinstance(v, bytes | str) else v)
                      for k, v in handle.attrs.items() if k not in skip}
        return StudyResult(_text(handle.attrs["study_name"]), _text(handle.attrs["model"]),
                           tuple(continuations), tuple(sweeps), runs, attributes)
