"""The API notebook examples/api.ipynb runs headless: every code cell, in order, in one
namespace, from the repository's root (as a reader would run it), without Jupyter. Its last
cell's onset (eigenvalues of the model's Jacobian changing sign) must be where AUTO found the
Hopf points."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]


def test_the_api_notebook_runs(monkeypatch):
    notebook = json.loads((ROOT / "examples" / "api.ipynb").read_text())
    monkeypatch.chdir(ROOT)
    namespace: dict = {}
    for cell in notebook["cells"]:
        if cell["cell_type"] == "code":
            exec(compile("".join(cell["source"]), "api.ipynb", "exec"), namespace)  # noqa: S102
    out = namespace["out"]
    assert {p.name for p in out.iterdir()} >= {"linear-case2.png", "linear-case2.h5",
                                              "linear-case2.mat", "linear-case2.nc"}
    onset, hopf = namespace["onset"], namespace["hopf"]
    assert len(onset) == len(hopf) > 0
    np.testing.assert_allclose(onset, hopf, atol=1e-4)  # the grid step
    assert os.getcwd() == str(ROOT)
