"""Both AUTO engines (WHIRL_AUTO_ENGINE=debian|bifpy) on the real solver: each one compiles
whirl's equations into its own cache entry, reports itself, and gives the reference numbers;
the two agree point for point. No skips: `make setup` installs both engines (Debian's package
and the PyPI package bifpy), and a missing one fails here with its install hint."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from whirl_cli.auto import codegen, toolchain
from whirl_cli.cli import cli
from whirl_cli.models import get_model
from whirl_cli.pipeline import run_study
from whirl_cli.results import PointType
from whirl_cli.study import load_study

from ..conftest import STUDIES


def _study(engine: str, name: str, workdir, monkeypatch):
    """Run studies/thesis_ch3/<name>.yaml with ``engine`` in ``workdir``."""
    monkeypatch.setenv(toolchain.ENGINE_VARIABLE, engine)
    return run_study(load_study(STUDIES / f"{name}.yaml"), workdir, jobs=2)


def _points(result, kind):
    return sorted(float(p.parameters[0]) for c in result.continuations
                  for p in c.special_points if p.point_type == kind and p.status == "located")


@pytest.mark.parametrize("engine", toolchain.ENGINES)
def test_engine_compiles_into_its_own_cache_entry(engine, monkeypatch):
    """The cache key holds the engine: the same source gives one executable per engine."""
    model = get_model("classical")
    built = {}
    for name in toolchain.ENGINES:
        monkeypatch.setenv(toolchain.ENGINE_VARIABLE, name)
        built[name] = toolchain.compile_equations(lambda: codegen.fortran_source(model),
                                                  model.name, codegen.source_key(model))
        assert built[name].path.is_file()
    assert len({b.path for b in built.values()}) == len(toolchain.ENGINES)
    monkeypatch.setenv(toolchain.ENGINE_VARIABLE, engine)
    chosen = toolchain.engine()
    assert chosen.name == engine and all(o.is_file() for o in chosen.objects)
    assert toolchain.auto_version() == chosen.version != "unknown"


@pytest.mark.parametrize("engine", toolchain.ENGINES)
def test_doctor_names_the_engine_that_runs(engine):
    """`whirl doctor` says which engine runs, with its version, and that its AUTO run works."""
    done = CliRunner().invoke(cli, ["doctor"], env={toolchain.ENGINE_VARIABLE: engine})
    assert done.exit_code == 0, done.output
    assert f"AUTO engine: {engine} (" in done.output
    assert toolchain.auto_version(engine) in done.output
    assert "AUTO run: ok" in done.output and "everything needed is installed" in done.output


@pytest.mark.parametrize("engine", toolchain.ENGINES)
def test_engine_gives_softening_case2_reference_numbers(engine, tmp_path, monkeypatch):
    """Softening case 2 (K_psi = 0.3, K2 = -10) with each engine: every run ok, Hopf points at
    K1 = 0.0807 and 0.2888, the pitchfork at 0.03598 (models.md 4), folds of cycles that are
    folds: the periodic family turns there (three points on either side lie on the same
    side in K1) and no point near it goes further in K1 than AUTO's location accuracy
    (2e-4 relative); and the engine stored as auto_version."""
    result = _study(engine, "softening_case2", tmp_path, monkeypatch)
    assert [r.status for r in result.runs] == ["ok"] * len(result.runs), result.runs
    assert _points(result, PointType.HB) == pytest.approx([0.0807, 0.2888], abs=1e-4)
    assert _points(result, PointType.BP) == pytest.approx([0.03598], abs=1e-5)
    folds = [(c, p) for c in result.continuations for p in c.special_points
             if p.point_type == PointType.LPC and p.status == "located"]
    assert folds
    for continuation, fold in folds:
        (branch,) = [b for b in continuation.branches if b.name == fold.branch]
        k1, i = branch.parameters[:, 0], fold.index
        assert k1[i] == pytest.approx(float(fold.parameters[0]), abs=1e-12)
        assert 3 <= i < len(k1) - 3, fold
        side = np.sign(k1[i] - k1[i - 3])  # +1: the family turns back at a largest K1
        assert side != 0 and side == np.sign(k1[i] - k1[i + 3]), fold
        extreme = side * (side * k1[i - 3:i + 4]).max()
        assert k1[i] == pytest.approx(extreme, rel=2e-4), fold
    assert result.provenance.auto_version == toolchain.auto_version(engine)


def test_engines_agree_on_combined_case2(tmp_path, monkeypatch):
    """Combined case 2 (18 runs: equilibria, periodic families, a fold of cycles) with both
    engines: the same special points, types and branches, parameters and amplitudes equal to
    1e-6 (relative to the largest value)."""
    found = {}
    for engine in toolchain.ENGINES:
        result = _study(engine, "combined_case2", tmp_path / engine, monkeypatch)
        assert all(r.status == "ok" for r in result.runs), (engine, result.runs)
        found[engine] = [
            ((p.branch, int(p.point_type)), np.concatenate([p.parameters, p.state]))
            for c in result.continuations for p in c.special_points
            if p.status == "located"]
    reference, other = (found[e] for e in toolchain.ENGINES)
    assert [key for key, _ in reference] == [key for key, _ in other]
    scale = max(float(np.abs(v).max()) for _, v in reference)
    for (key, a), (_, b) in zip(reference, other, strict=True):
        assert a == pytest.approx(b, abs=1e-6 * scale), key


def test_without_debians_auto_whirl_runs_on_bifpy(tmp_path):
    """Debian's AUTO hidden (WHIRL_AUTO_DIR at an empty folder) and no WHIRL_AUTO_ENGINE: the
    console script runs linear case 2 on bifpy's AUTO-07p, stores that engine, and finds the
    Hopf points of the Debian engine's run (to 1e-9 of K_theta); `whirl doctor` says why."""
    import os
    import subprocess
    import sys

    import h5py

    from whirl_cli.output import store

    env = {k: v for k, v in os.environ.items() if k != toolchain.ENGINE_VARIABLE}
    env["WHIRL_AUTO_DIR"] = str(tmp_path / "no-auto")
    (tmp_path / "no-auto").mkdir()
    whirl = [str(Path(sys.executable).parent / "whirl")]
    study = STUDIES / "linear_case2.yaml"
    hidden = subprocess.run([*whirl, "run", str(study), "-o", str(tmp_path / "b.h5"),
                             "--no-plots"], env=env, capture_output=True, text=True, timeout=600)
    assert hidden.returncode == 0, hidden.stderr
    with h5py.File(tmp_path / "b.h5") as handle:
        assert handle.attrs["auto_version"].startswith("bifpy ")
    debian = run_study(load_study(study), tmp_path / "work", jobs=2)
    assert debian.provenance.auto_version == toolchain.auto_version("debian")
    on_bifpy = store.read(tmp_path / "b.h5")
    assert _points(on_bifpy, PointType.HB) == pytest.approx(_points(debian, PointType.HB),
                                                            abs=1e-9)
    doctor = subprocess.run([*whirl, "doctor"], env=env, capture_output=True, text=True,
                            timeout=300)
    assert doctor.returncode == 0, doctor.stdout + doctor.stderr
    assert (f"AUTO engine: bifpy (Debian's auto-07p not found in {tmp_path / 'no-auto'}; "
            "bifpy's AUTO-07p is installed") in doctor.stdout
