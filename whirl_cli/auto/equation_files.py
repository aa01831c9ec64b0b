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


def write_generated(root: Path) -> list[Path]:
    """(Re)write ``auto_equations/`` under ``root``; returns the files that changed."""
    changed = []
    for rel, text in all_generated_files().items():
        path = root / rel
        if not path.exists() or path.read_text() != text:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
            changed.append(path)
    return changed


def drifted(root: Path) -> list[str]:
    """Generated files under ``root`` that differ from what the models generate now."""
    return [rel for rel, text in all_generated_files().items()
            if not (root / rel).exists() or (root / rel).read_text() != text]

