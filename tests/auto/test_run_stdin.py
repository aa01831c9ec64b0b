"""``whirl run -`` runs the study given on standard input, as if read from a file."""

from __future__ import annotations

import subprocess
import sys

from whirl_cli import api
from whirl_cli.study import stored_study

from ..conftest import STUDIES


def test_run_reads_the_study_from_standard_input(tmp_path):
    text = (STUDIES / "linear_case2.yaml").read_text()
    done = subprocess.run([sys.executable, "-m", "whirl_cli", "run", "-", "--no-plots",
                           "-j", "2"], input=text, capture_output=True, text=True,
                          cwd=tmp_path, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "whirl " in done.stderr and ": <stdin> -> linear-case2.h5" in done.stderr
    result = api.read(tmp_path / "linear-case2.h5")
    assert result.provenance.study_yaml == text
    assert stored_study(result.provenance).name == "linear-case2"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["linear-case2.h5"]
