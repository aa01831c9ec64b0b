"""Concurrency: two ``whirl run`` processes on different studies at the same time, one with
``--jobs 2``, sharing an EMPTY compile cache (both compile the same model variant at once) and
one ``--keep-runs`` directory. Neither corrupts the other: each run has its own directory
with its own constants, both outputs are right (Hopf points equal to the eigenvalue ones of
whirl_cli.analysis.linear.critical_points), and the cache ends with exactly one executable for the
variant and no half-built entries."""

from __future__ import annotations

import subprocess

import h5py
import numpy as np
import pytest

from whirl_cli.analysis.linear import critical_points
from whirl_cli.study import load_study

from .helpers import STUDIES, WHIRL, environment

pytestmark = pytest.mark.auto

STUDY_FILES = ("linear_case2", "linear_datum_airspeed")


def auto_hopf_points(path, continuation: str) -> np.ndarray:
    """Parameter values of the Hopf points AUTO found on the main branches."""
    with h5py.File(path, "r") as handle:
        points = handle[f"continuations/{continuation}/special_points"]
        branch = points["branch"].asstr()[()]
        kind = points["point_type"][()]
        values = points["parameters"][:, 0]
    main = np.char.startswith(branch.astype(str), "main_")
    return np.sort(values[(kind == 3) & main])


def test_two_runs_at_once_with_an_empty_shared_cache(tmp_path):
    cache = tmp_path / "cache"
    cache.mkdir()
    keep = tmp_path / "keep"
    env = environment(cache, TMPDIR=str(tmp_path))
    processes = {}
    for name, jobs in zip(STUDY_FILES, ("2", "1"), strict=True):
        command = [str(WHIRL), "run", str(STUDIES / f"{name}.yaml"), "-o",
                   str(tmp_path / "out" / f"{name}.h5"), "--jobs", jobs, "--no-plots",
                   "--keep-runs", str(keep)]
        processes[name] = subprocess.Popen(command, env=env, stdout=subprocess.PIPE,
                                           stderr=subprocess.PIPE, text=True)
    for name, process in processes.items():
        stdout, stderr = process.communicate(timeout=300)
        assert process.returncode == 0, (name, stdout, stderr)

    # the cache: one executable for the variant, no build directories left
    entries = sorted(p.name for p in (cache / "exe").iterdir())
    assert len(entries) == 1 and entries[0].startswith("classical_poly-"), entries
    assert sorted(p.name for p in (cache / "exe" / entries[0]).iterdir()) == [
        f"classical_poly.{x}" for x in ("exe", "f90", "o")]
    assert len(list(cache.rglob("*.exe"))) == 1

    # the work directories: one per process, one per run, each with its own constants only
    roots = sorted(p for p in keep.iterdir())
    assert len(roots) == 2
    seen = set()
    for root in roots:
        for constants in root.rglob("c.*"):
            run_dir = constants.parent
            assert run_dir not in seen
            seen.add(run_dir)
            run_name = f"{run_dir.parent.name}.{run_dir.name}"
            assert constants.name == f"c.{run_name}"
            names = {p.name for p in run_dir.glob("[bcsd].*")}
            assert names - {"s.restart"} == {f"{k}.{run_name}" for k in "bcds"}, names
            assert not (run_dir / "fort.2").exists()

    # both outputs are right: AUTO's Hopf points = the eigenvalue ones
    for name in STUDY_FILES:
        study = load_study(STUDIES / f"{name}.yaml")
        (spec,) = study.continuations
        expected = sorted(p.value for p in critical_points(
            study.variant(), study.parameter_values(), spec.parameter, *spec.range)
            if p.kind == "hopf")
        found = auto_hopf_points(tmp_path / "out" / f"{name}.h5", spec.name)
        assert len(expected) >= 1 and len(found) == len(expected), (name, found, expected)
        np.testing.assert_allclose(found, expected, atol=1e-4, rtol=0)
        with h5py.File(tmp_path / "out" / f"{name}.h5") as handle:
            assert handle.attrs["study_name"] == study.name
            assert all(g.attrs["status"] == "ok" for g in handle["runs"].values())
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        f"{name}.h5" for name in sorted(STUDY_FILES)]
