"""Subprocess helpers for the registry tests: whirl run from a copy of its package with
modules added (a new kind is one more file), and which modules an import loads."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "whirl_cli"


def run_in_a_copy(tmp_path: Path, added: dict[str, str], script: str, *args: str
                  ) -> subprocess.CompletedProcess:
    """``python -c script args`` in ``tmp_path``, importing a copy of the package there into
    which ``added`` (path inside the package -> text) is written."""
    package = tmp_path / "whirl_cli"
    shutil.copytree(PACKAGE, package, ignore=shutil.ignore_patterns("__pycache__"))
    for name, text in added.items():
        (package / name).write_text(text)
    return subprocess.run([sys.executable, "-c", script, *args], capture_output=True,
                          text=True, timeout=300, cwd=tmp_path,
                          env={**os.environ, "PYTHONPATH": str(tmp_path)})


def loaded_after(code: str, watched: set[str]) -> list[str]:
    """Which of the modules ``watched`` a fresh interpreter has loaded after running
    ``code``, sorted."""
    script = (f"import json, sys\n{code}\n"
              f"print(json.dumps(sorted(set({sorted(watched)!r}) & set(sys.modules))))")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          check=True)
    return json.loads(done.stdout)
