"""Where whirl keeps what it builds once and reuses: compiled AUTO programs and generated
numeric modules, under ``$WHIRL_CACHE_DIR`` (default ``$XDG_CACHE_HOME/whirl``, else
``~/.cache/whirl``). Every entry is keyed by a hash of what produced it, and appears
atomically (written under a private name, then renamed), so concurrent processes share it."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


def cache_dir() -> Path:
    root = os.environ.get("WHIRL_CACHE_DIR")
    if root:
        return Path(root)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "whirl"


def write_atomically(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` so that readers see the whole file or none."""
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}-", dir=path.parent)
    try:
        with os.fdopen(handle, "w") as stream:
            stream.write(text)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
