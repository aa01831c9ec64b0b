"""`whirl figures` on a sheet whose panels come from a study of a model file: the study runs
into the results folder, the figure is drawn, a second call finds everything up to date, and
a changed model file (not a changed comment) makes the study and its figure stale."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import h5py

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "studies" / "nacelle_on_wing"
SHEET = """\
figure: "9.1"
caption: The nacelle on a twisting wing, hardening pitch stiffness.
panels:
  - {kind: bifurcation, study: study/airspeed_hardening.yaml}
size: [6.4, 4.0]
"""


def figures(folder: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "whirl_cli", "figures", "sheet.yaml", "-o",
                           "out", "--results", "results"], cwd=folder, capture_output=True,
                          text=True, timeout=600)


def test_a_sheet_of_a_model_file_study(tmp_path):
    shutil.copytree(EXAMPLE, tmp_path / "study")
    (tmp_path / "sheet.yaml").write_text(SHEET)
    first = figures(tmp_path)
    assert first.returncode == 0, first.stderr
    result = tmp_path / "results" / "nacelle-on-wing-airspeed.h5"
    assert (tmp_path / "out" / "fig9_1.png").stat().st_size > 0
    with h5py.File(result) as handle:
        assert handle.attrs["model_file"].endswith("nacelle_on_wing.model.yaml")
    model = tmp_path / "study" / "nacelle_on_wing.model.yaml"
    model.write_text(model.read_text() + "# a comment changes nothing\n")
    again = figures(tmp_path)
    assert again.returncode == 0, again.stderr
    assert "1 of 1 figures (1 up to date, not redrawn)" in again.stdout + again.stderr
    text = model.read_text()
    assert "value: 1.5," in text  # K_phi's datum
    model.write_text(text.replace("value: 1.5,", "value: 1.6,", 1))
    stamp = result.stat().st_mtime_ns
    changed = figures(tmp_path)
    assert changed.returncode == 0, changed.stderr
    assert "1 of 1 figures (0 up to date, not redrawn)" in changed.stdout + changed.stderr
    assert result.stat().st_mtime_ns != stamp  # the study ran again
    with h5py.File(result) as handle:
        assert "value: 1.6," in handle.attrs["model_file_yaml"]
