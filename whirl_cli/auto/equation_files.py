"""The committed AUTO files under ``auto_equations/``: what ``whirl generate`` writes and
``whirl generate --check`` compares (per model variant its equations and an example constants
file).
"""

from __future__ import annotations

from pathlib import Path

from ..models import Model, all_variants
from .codegen import fortran_source
from .constants import constants_text, example_constants


def generated_files(model: Model) -> dict[str, str]:
    """Relative path -> text of every file ``whirl generate`` writes for ``model``."""
    return {
        f"{model.name}/{model.name}.f90": fortran_source(model),
        f"{model.name}/c.{model.name}": constants_text(example_constants(model)),
    }


def all_generated_files() -> dict[str, str]:
    files: dict[str, str] = {}
    for model in all_variants():
        files.update(generated_files(model))
    return files


def _stale(root: Path, files: dict[str, str]) -> list[Path]:
    """Files under ``root`` that no shipped variant generates (e.g. of a removed variant)."""
    if not root.is_dir():
        return []
    return sorted(p for p in root.rglob("*") if p.is_file()
                  and p.relative_to(root).as_posix() not in files)


def write_generated(root: Path) -> list[Path]:
    """(Re)write ``auto_equations/`` under ``root`` (removing files no variant generates any
    more); returns the files that changed."""
    files = all_generated_files()
    changed = []
    for path in _stale(root, files):
        path.unlink()
        changed.append(path)
        if not any(path.parent.iterdir()):
            path.parent.rmdir()
    for rel, text in files.items():
        path = root / rel
        if not path.exists() or path.read_text() != text:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
            changed.append(path)
    return changed


def drifted(root: Path) -> list[str]:
    """Generated files under ``root`` that differ from what the models generate now, and
    files there that no variant generates."""
    files = all_generated_files()
    return [rel for rel, text in files.items()
            if not (root / rel).exists() or (root / rel).read_text() != text] + [
        f"{p.relative_to(root).as_posix()} (no variant generates it)" for p in _stale(root, files)]

