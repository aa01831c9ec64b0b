"""Determinism: the same study run twice (once with one AUTO job, once with two in parallel)
gives equal files: a one-parameter study, and a boundary whose slices and loci run side by
side. Every dataset is equal (numpy array_equal, NaN positions included), every
attribute too, except the provenance attribute ``created`` (root) and ``wall_seconds``
(each run record). Groups and datasets are the same, in the same order."""

from __future__ import annotations

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

from whirl_cli.cli import cli

from .helpers import STUDIES

pytestmark = pytest.mark.auto

#: Attributes that may differ between two runs of one study.
VOLATILE = {("/", "created"), ("runs", "wall_seconds")}


def contents(path) -> dict:
    """name -> ("group" | dataset array, attributes) for every object of an HDF5 file; the
    object references of dimension scales (``DIMENSION_LIST``, ``REFERENCE_LIST``) as the
    names of the objects they refer to (a reference itself is particular to its file)."""
    found: dict = {}
    with h5py.File(path, "r") as handle:
        def named(value):
            if isinstance(value, h5py.Reference):
                return handle[value].name
            if isinstance(value, np.void):
                return tuple(named(v) for v in value)
            if isinstance(value, np.ndarray) and value.dtype.kind in "OV":
                return str([named(v) for v in value.ravel()])
            return value

        def visit(name: str, item) -> None:
            data = "group" if isinstance(item, h5py.Group) else item[()]
            found[name] = (data, {key: named(value) for key, value in item.attrs.items()})

        visit("/", handle)
        handle.visititems(visit)
    return found


def volatile(name: str, key: str) -> bool:
    return (name, key) in VOLATILE or (name.startswith("runs/") and ("runs", key) in VOLATILE)


def equal(a, b) -> bool:
    if isinstance(a, str) or isinstance(b, str):
        return a == b
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype != b.dtype or a.shape != b.shape:
        return False
    if a.dtype.kind in "fc":
        return bool(np.array_equal(a, b, equal_nan=True))
    return bool(np.array_equal(a, b))


def run_twice(study, tmp_path, plots: bool = False) -> tuple[dict, dict]:
    """The contents of ``study`` run with one AUTO job and with two (and, with ``plots``,
    each plot file's bytes under ``png:<name>``)."""
    found = []
    for k, jobs in enumerate(("1", "2")):
        path = tmp_path / f"run{k}" / "study.h5"
        result = CliRunner().invoke(cli, ["run", str(study), "-o", str(path), "--jobs", jobs,
                                          "--plots" if plots else "--no-plots"])
        assert result.exit_code == 0, result.output
        drawn = {f"png:{png.name}": (png.read_bytes(), {})
                 for png in sorted(path.parent.glob("*.png"))}
        found.append({**contents(path), **drawn})
    return found[0], found[1]


def differences(first: dict, second: dict) -> list[str]:
    """What differs between two files' contents, volatile attributes apart."""
    assert list(first) == list(second)  # same objects, same order
    found = []
    for name, (data, attributes) in first.items():
        other_data, other_attributes = second[name]
        if not equal(data, other_data):
            found.append(f"{name}: data")
        assert list(attributes) == list(other_attributes), name
        for key, value in attributes.items():
            if not volatile(name, key) and not equal(value, other_attributes[key]):
                found.append(f"{name}@{key}: {value!r} != {other_attributes[key]!r}")
    return found


def test_the_same_study_twice_gives_equal_files(tmp_path):
    study = STUDIES / "softening_case2.yaml"  # periodic branches (NaN periods), cross-checks
    # with two jobs the cross-checks run in a worker forked before AUTO and the plots are
    # drawn beside them; with one, all in turn here: the same file and the same plots
    first, second = run_twice(study, tmp_path, plots=True)
    assert not differences(first, second)
    assert len([n for n in first if n.startswith("png:")]) >= 3
    checks = [n for n in first if n.endswith("/cross_checks") or "/cross_checks/" in n]
    assert checks
    nan_datasets = sum(isinstance(data, np.ndarray) and data.dtype.kind in "fc"
                       and bool(np.isnan(data).any()) for data, _ in first.values())
    assert nan_datasets > 0  # the comparison did see NaN positions
    periodic = [n for n in first if "/branches/periodic_" in n and n.endswith("/period")]
    assert periodic and any(n.startswith("runs/") for n in first)


def test_a_boundary_twice_gives_equal_files(tmp_path):
    """Two slices (run side by side with two jobs) whose fold-of-cycles loci grow chunk by
    chunk: the same loci, cut and dropped at the same points, whatever the timing."""
    text = (STUDIES / "boundary_softening.yaml").read_text()
    study = tmp_path / "boundary.yaml"
    study.write_text(text.replace("slices: [0.4, 0.3, 0.2, 0.05, 0.037]", "slices: [0.3, 0.2]")
                     .replace("points: 321", "points: 41").replace("points: 201", "points: 21"))
    first, second = run_twice(study, tmp_path)
    assert not differences(first, second)
    loci = [n for n in first if n.startswith("continuations/boundary/branches/fold_of_cycles")
            and n.count("/") == 3]
    chunked = [n for n in first if n.startswith("runs/") and "fold_of_cycles" in n
               and n.rsplit("_", 1)[-1].rstrip("0123456789").endswith("c")]
    assert loci, "no fold-of-cycles locus traced"
    print(f"{len(loci)} fold-of-cycles loci, {len(chunked)} chunk continuations")
