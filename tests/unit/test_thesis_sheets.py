"""Shipped sheets of the linear model's figures (3.7, 3.8, 3.12, 3.13), drawn from their own
studies (numpy and scipy only, no AUTO) and checked from the figure's own artists against the
model written out apart from whirl (tests.classical_exact)."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pytest
from matplotlib.collections import QuadMesh

from tests.classical_exact import linear_matrix
from whirl_cli.api import run
from whirl_cli.figures.draw import draw_sheet
from whirl_cli.figures.sheet import load_sheet
from whirl_cli.plots.files import rendered_formats

SHEETS = Path(__file__).resolve().parents[2] / "sheets" / "thesis_ch3"


@cache
def _result(study: Path):
    return run(study, jobs=1)


def drawn(number: str):
    """The shipped sheet of figure ``number`` drawn from its studies, run here."""
    sheet = load_sheet(SHEETS / f"fig{number.replace('.', '_')}.yaml")
    return draw_sheet(sheet, {path: _result(path) for path in sheet.studies()})


def max_real(k_theta: float, k_psi: float) -> float:
    return float(np.linalg.eigvals(linear_matrix({"K_theta": k_theta, "K_psi": k_psi}))
                 .real.max())


def test_3_13_is_the_max_re_lambda_surface():
    figure = drawn("3.13")
    meshes = [c for c in figure.axes[0].collections if isinstance(c, QuadMesh)]
    assert len(meshes) == 1
    mesh = meshes[0]
    x, y = (np.unique(c) for c in mesh.get_coordinates().reshape(-1, 2).T)
    values = np.asarray(mesh.get_array()).reshape(-1)
    # shading "nearest": cell centres are the grid points, cell edges halfway between them
    centres_x, centres_y = 0.5 * (x[1:] + x[:-1]), 0.5 * (y[1:] + y[:-1])
    assert values.size == centres_x.size * centres_y.size
    surface = values.reshape(centres_y.size, centres_x.size)
    for i, j in [(0, 0), (10, 150), (60, 60), (120, 40), (200, 200), (30, 190)]:
        expected = max_real(centres_x[j], centres_y[i])
        assert surface[i, j] == pytest.approx(expected, rel=1e-6, abs=1e-9)
    assert surface.min() < 0 < surface.max()  # stable and unstable parts both shown


def test_3_13_and_3_15_differ_in_content():
    """3.15 draws the continuation's loci over the grey region; 3.13 the surface itself."""
    assert load_sheet(SHEETS / "fig3_13.yaml").studies() != load_sheet(
        SHEETS / "fig3_15.yaml").studies()
    figure = drawn("3.13")
    assert figure.axes[0].get_legend() is None  # the one figure legend
    labels = {t.get_text() for legend in figure.legends for t in legend.get_texts()}
    assert not any("locus" in label for label in labels)


@pytest.mark.parametrize("number", ["3.13"])
def test_linear_sheets_are_pixel_identical_run_to_run(number):
    first = rendered_formats(drawn(number), ("png",), 80)["png"]
    assert rendered_formats(drawn(number), ("png",), 80)["png"] == first
