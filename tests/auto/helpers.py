"""Helpers shared by the tests that run the real AUTO-07p."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from whirl_cli.results import PointType

from ..conftest import STUDIES

SMALL = ("linear_case2", "linear_datum_airspeed")  # about a second of AUTO each


def copy_studies(directory: Path, names=SMALL) -> list[Path]:
    """Copies of the shipped studies ``names`` in ``directory``, in order."""
    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for name in names:
        path = directory / f"{name}.yaml"
        path.write_text((STUDIES / f"{name}.yaml").read_text())
        paths.append(path)
    return paths


def offset_equilibria_at_zero(continuation):
    """(branch, row) of each secondary equilibrium branch of a continuation in K_in at its
    labelled point K_in = 0 (``orbits_at: [0.0]``)."""
    for branch in continuation.branches:
        if branch.name.startswith("secondary"):
            (row,) = np.flatnonzero(branch.point_type == PointType.UZ)
            assert abs(branch.parameters[row, 0]) < 1e-9
            yield branch, row
