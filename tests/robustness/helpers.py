"""Shared helpers of the robustness tests: the real ``whirl`` executable, its environment, and
a /proc scan for AUTO processes (no psutil)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from ..conftest import ROOT, STUDIES

__all__ = ["ROOT", "STUDIES", "WHIRL", "auto_processes", "environment", "whirl"]

#: The console script of this virtual environment (``.venv/bin/whirl``).
WHIRL = Path(sys.executable).with_name("whirl")


def environment(cache: Path | None = None, **extra: str) -> dict[str, str]:
    """The test process's environment with WHIRL_CACHE_DIR (shared session cache by default)
    and ``extra`` set; WHIRL_DEBUG removed unless given."""
    env = {k: v for k, v in os.environ.items() if k != "WHIRL_DEBUG"}
    if cache is not None:
        env["WHIRL_CACHE_DIR"] = str(cache)
    env.update(extra)
    return env


def whirl(*args: str | Path, env: dict[str, str] | None = None, cwd: Path | None = None,
          timeout: float = 120) -> subprocess.CompletedProcess:
    """Run the real ``whirl`` console script; stdout and stderr as text."""
    return subprocess.run([str(WHIRL), *map(str, args)], env=env or environment(), cwd=cwd,
                          capture_output=True, text=True, timeout=timeout, check=False)


def auto_processes(root: Path) -> list[int]:
    """PIDs of live processes whose executable lies under ``root`` (a WHIRL_CACHE_DIR)."""
    root = root.resolve()
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            command = (entry / "cmdline").read_bytes().split(b"\0")[0].decode()
            state = next(line for line in (entry / "status").read_text().splitlines()
                         if line.startswith("State:"))
        except (OSError, StopIteration, UnicodeDecodeError):
            continue
        if command.startswith(str(root)) and "zombie" not in state:
            found.append(int(entry.name))
    return found
