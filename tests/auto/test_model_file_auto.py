"""A model file on the real AUTO: the classical model written as a file by hand
(tests/data/classical_as_file.yaml) reproduces the built-in model's special points, and a study
finds its model file relative to itself."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from whirl_cli import api
from whirl_cli.results import PointType
from whirl_cli.study import load_study

ROOT = Path(__file__).resolve().parents[2]
MODEL = ROOT / "tests" / "data" / "classical_as_file.yaml"


def points(result, kind: PointType) -> np.ndarray:
    """(K_theta, period) of every special point of ``kind``, sorted."""
    found = [(p.parameters[0], p.period) for c in result.continuations
             for p in c.special_points if p.point_type == kind]
    return np.array(sorted(found))


def twin(tmp_path: Path, study: str) -> tuple:
    """The shipped study ``study`` run as it is, and with its model as the file copied beside
    it (``model: ./classical_as_file.yaml``)."""
    shutil.copy(MODEL, tmp_path / MODEL.name)
    text = (ROOT / "studies" / "thesis_ch3" / f"{study}.yaml").read_text()
    assert "model: classical\n" in text
    copy = tmp_path / f"{study}.yaml"
    copy.write_text(text.replace("model: classical\n", f"model: ./{MODEL.name}\n"))
    return api.run(load_study(ROOT / "studies" / "thesis_ch3" / f"{study}.yaml")), \
        api.run(load_study(copy))


def test_linear_case2_hopf_and_branch_points(tmp_path):
    built_in, from_file = twin(tmp_path, "linear_case2")
    assert from_file.model == "classical_file_poly"
    for kind in (PointType.HB, PointType.BP):
        expected, found = points(built_in, kind), points(from_file, kind)
        assert len(expected) > 0 and expected.shape == found.shape, kind
        np.testing.assert_allclose(found[:, 0], expected[:, 0], rtol=0, atol=1e-9)


def test_combined_case2_fold_of_cycles(tmp_path):
    built_in, from_file = twin(tmp_path, "combined_case2")
    expected, found = points(built_in, PointType.LPC), points(from_file, PointType.LPC)
    assert len(expected) > 0 and expected.shape == found.shape
    np.testing.assert_allclose(found, expected, rtol=0, atol=1e-6)


def test_results_carry_the_model_file(tmp_path):
    """The HDF5 file stores the model file's text and hash; read back, its stored study
    validates against the stored model even after the file is gone."""
    shutil.copy(MODEL, tmp_path / MODEL.name)
    study = tmp_path / "s.yaml"
    study.write_text(f"name: s\nmodel: ./{MODEL.name}\nparameters: {{K_psi: 0.3}}\n"
                     "continuations:\n  - {name: k1, type: one-parameter, parameter: K1, "
                     "start: 0.5, range: [-0.3, 0.5], periodic: false}\n")
    result = api.run(load_study(study))
    api.save(result, tmp_path / "s.h5")
    (tmp_path / MODEL.name).unlink()
    stored = api.read(tmp_path / "s.h5").provenance
    assert stored.model_file_yaml == MODEL.read_text()
    assert len(stored.model_file_sha256) == 64
    from whirl_cli.study import stored_study

    assert stored_study(stored).variant().family.name == "classical_file"


@pytest.mark.parametrize("edit", ["comment", "equation"])
def test_sweep_sees_a_changed_model_file(tmp_path, edit):
    from whirl_cli.sweep.plan import RUN, SKIP, _decide

    shutil.copy(MODEL, tmp_path / MODEL.name)
    study = tmp_path / "s.yaml"
    study.write_text(f"name: s\nmodel: ./{MODEL.name}\n"
                     "continuations:\n  - {name: k1, type: one-parameter, parameter: K1, "
                     "start: 0.5, range: [0.2, 0.5], periodic: false}\n")
    api.save(api.run(load_study(study)), tmp_path / "s.h5")
    assert _decide(load_study(study), tmp_path / "s.h5", False)[0] == SKIP
    text = (tmp_path / MODEL.name).read_text()
    changed = "# edited\n" + text if edit == "comment" else text.replace("(C_psi + c_a)*dpsi",
                                                                       "(C_psi + 2*c_a)*dpsi")
    (tmp_path / MODEL.name).write_text(changed)
    assert _decide(load_study(study), tmp_path / "s.h5", False)[0] == (SKIP if edit == "comment"
                                                               else RUN)


def test_a_model_file_is_generated_once_then_run_without_sympy(tmp_path):
    """A model file's code goes into the user's cache (WHIRL_CACHE_DIR): the first run
    generates it (sympy imported), a second run in a fresh process only reads it (no sympy),
    and nothing is written into the package."""
    import os
    import subprocess
    import sys

    study = ROOT / "tests" / "data" / "lagged_spring_mu.yaml"
    code = ("import sys; from whirl_cli import api; api.run(api.load(sys.argv[1]), jobs=1); "
            "print('sympy' in sys.modules)")
    env = {**os.environ, "WHIRL_CACHE_DIR": str(tmp_path / "cache")}
    before = sorted(p.name for p in (ROOT / "whirl_cli" / "models").iterdir())
    runs = [subprocess.run([sys.executable, "-c", code, str(study)], env=env, text=True,
                           capture_output=True, timeout=300) for _ in range(2)]
    assert [r.returncode for r in runs] == [0, 0], runs[0].stderr + runs[1].stderr
    assert [r.stdout.split()[-1] for r in runs] == ["True", "False"]
    generated = list((tmp_path / "cache").rglob("lagged_spring*"))
    assert any(p.suffix == ".py" for p in generated), generated
    assert sorted(p.name for p in (ROOT / "whirl_cli" / "models").iterdir()) == before
