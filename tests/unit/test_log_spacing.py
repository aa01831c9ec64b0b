"""Log-spaced linear sweeps and grid axes (``spacing: log``): declared in the schema (a positive
range only, refused otherwise with one clean line), sampled with a constant ratio between
neighbours, stored beside the values and read back, and drawn on a log axis."""

from __future__ import annotations

from dataclasses import replace

import h5py
import matplotlib.pyplot as plt
import numpy as np
import pytest

from whirl_cli.kinds import Spacing
from whirl_cli.output import store
from whirl_cli.output.compare import compare_linear_sweep
from whirl_cli.pipeline import run_study
from whirl_cli.plots.files import study_figures
from whirl_cli.plots.linear import damping_multiples_plot
from whirl_cli.plots.maps import boundary_plot
from whirl_cli.results import Boundary
from whirl_cli.study import StudyError, validate_text

#: K_beta over 1.02/rev to beyond 11/rev (thesis K_beta = 10) on a log grid; V evenly.
STUDY = """\
name: logspaced
model: gimballed
parameters: {K_psi: 0.3}
linear:
  sweeps:
    - {parameter: K_beta, range: [0.0033, 10.5], points: 13, spacing: log}
    - {parameter: I_x, range: [0.5, 4.0], points: 7, spacing: log, multiples: true}
    - {parameter: V, range: [0.0, 8.0], points: 9}
  grid:
    x: {parameter: K_beta, range: [0.0033, 10.5], points: 11, spacing: log}
    y: {parameter: V, range: [0.0, 8.0], points: 9}
plots: [boundary, linear]
"""


def geometric(lower: float, upper: float, points: int) -> np.ndarray:
    """lower (upper/lower)^(k/(points - 1)), k = 0 .. points - 1, written out."""
    return np.array([lower * (upper / lower) ** (k / (points - 1)) for k in range(points)])


def test_the_schema_takes_a_log_spacing_on_sweeps_and_grid_axes():
    study = validate_text(STUDY, "s.yaml")
    k_beta, multiples, airspeed = study.linear.sweeps
    assert (k_beta.spacing, multiples.spacing, airspeed.spacing) == (
        Spacing.LOG, Spacing.LOG, Spacing.LINEAR)
    assert (study.linear.grid.x.spacing, study.linear.grid.y.spacing) == (
        Spacing.LOG, Spacing.LINEAR)


@pytest.mark.parametrize("spec, expected", [
    ("{parameter: V, range: [0, 8], spacing: log}",
     "s.yaml:5: linear.sweeps[0].range: with spacing: log the range must be > 0, got 0.0"),
    ("{parameter: V, range: [-2, 8], points: 5, spacing: log}",  # V's bounds say so too
     "s.yaml:5: linear.sweeps[0].range: the range reaches -2.0, outside the bounds of V "
     "(>= 0 m/s)\n"
     "s.yaml:5: linear.sweeps[0].range: with spacing: log the range must be > 0, got -2.0"),
    ("{parameter: V, range: [1, 8], spacing: logarithmic}",
     "s.yaml:5: linear.sweeps[0].spacing: expected one of linear, log, got 'logarithmic'"),
])
def test_a_log_sweep_over_a_range_reaching_zero_or_below_is_refused(spec, expected):
    text = f"name: s\nmodel: classical\nlinear:\n  sweeps:\n    - {spec}\n"
    with pytest.raises(StudyError) as error:
        validate_text(text, "s.yaml")
    assert error.value.message.splitlines() == expected.splitlines()


def test_a_log_grid_axis_reaching_zero_is_refused_at_its_range():
    text = ("name: s\nmodel: gimballed\nlinear:\n  grid:\n"
            "    x: {parameter: V, range: [1, 8]}\n"
            "    y: {parameter: K_beta, range: [0, 10], spacing: log}\n")
    with pytest.raises(StudyError) as error:
        validate_text(text, "g.yaml")
    assert error.value.message.splitlines() == [
        "g.yaml:6: linear.grid.y.range: with spacing: log the range must be > 0, got 0.0"]


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    """The study run (numpy only, no AUTO), written and read back: (result, file)."""
    directory = tmp_path_factory.mktemp("logspaced")
    result = run_study(validate_text(STUDY, "s.yaml"), directory / "work")
    path = store.write(result, directory / "r.h5")
    return store.read(path), path


def test_log_values_have_a_constant_ratio_from_lower_to_upper(stored):
    result, path = stored
    k_beta, multiples, airspeed = result.linear_sweeps
    np.testing.assert_allclose(k_beta.values, geometric(0.0033, 10.5, 13), rtol=1e-12)
    ratios = k_beta.values[1:] / k_beta.values[:-1]
    np.testing.assert_allclose(ratios, (10.5 / 0.0033) ** (1 / 12), rtol=1e-12)
    np.testing.assert_allclose(multiples.values / multiples.datum, geometric(0.5, 4.0, 7),
                               rtol=1e-12)
    np.testing.assert_allclose(airspeed.values, np.arange(9.0), atol=1e-12)
    np.testing.assert_allclose(result.linear_grid.x, geometric(0.0033, 10.5, 11), rtol=1e-12)
    np.testing.assert_allclose(result.linear_grid.y, np.arange(9.0), atol=1e-12)
    assert [s.spacing for s in result.linear_sweeps] == [Spacing.LOG, Spacing.LOG,
                                                         Spacing.LINEAR]
    assert (result.linear_grid.x_spacing, result.linear_grid.y_spacing) == (
        Spacing.LOG, Spacing.LINEAR)
    with h5py.File(path) as handle:
        assert handle["linear/sweeps/K_beta"].attrs["spacing"] == "log"
        assert handle["linear/sweeps/V"].attrs["spacing"] == "linear"
        grid = handle["linear/grid"].attrs
        assert (grid["x_spacing"], grid["y_spacing"]) == ("log", "linear")


def test_a_file_without_spacing_reads_as_linear(stored, tmp_path):
    _, path = stored
    copy = tmp_path / "old.h5"
    copy.write_bytes(path.read_bytes())
    with h5py.File(copy, "r+") as handle:
        for group in (*handle["linear/sweeps"].values(), handle["linear/grid"]):
            for key in ("spacing", "x_spacing", "y_spacing"):
                group.attrs.pop(key, None)
    read = store.read(copy)
    assert {s.spacing for s in read.linear_sweeps} == {Spacing.LINEAR}
    assert (read.linear_grid.x_spacing, read.linear_grid.y_spacing) == (Spacing.LINEAR,
                                                                        Spacing.LINEAR)


def test_a_log_spaced_parameter_is_drawn_on_a_log_axis(stored):
    result, _ = stored
    figures = dict(study_figures(result, ("boundary", "linear"), "s"))
    try:
        (grid_ax, *_) = figures["s_linear_grid.png"].axes
        assert (grid_ax.get_xscale(), grid_ax.get_yscale()) == ("log", "linear")
        low, high = grid_ax.get_xlim()
        assert low == pytest.approx(0.0033) and high == pytest.approx(10.5)
        for name in ("s_linear_K_beta.png", "s_linear_I_x.png"):
            axes = figures[name].axes
            assert [ax.get_xscale() for ax in axes] == ["log", "log"], name
        k_beta = next(s for s in result.linear_sweeps if s.parameter == "K_beta")
        drawn = [line.get_xdata() for line in figures["s_linear_K_beta.png"].axes[0].lines
                 if len(line.get_xdata()) == len(k_beta.values)]
        assert drawn and all(np.array_equal(x, k_beta.values) for x in drawn)
        assert [ax.get_xscale() for ax in figures["s_linear_V.png"].axes] == ["linear"] * 2
    finally:
        for figure in figures.values():
            plt.close(figure)


@pytest.mark.parametrize("spacing, scale", [(Spacing.LOG, "log"), (Spacing.LINEAR, "linear")])
def test_a_log_grid_axis_is_log_over_its_parameter_on_a_boundary_in_the_other_order(
        stored, spacing, scale):
    """Over the tiltrotor gimbals alone (K_beta 0.0033-0.0173, under the decades rule's
    factor) the axis is log because the grid samples it log, and only then; the boundary's
    parameters are the grid's in the other order, so K_beta is the map's y axis."""
    result, _ = stored
    grid = replace(result.linear_grid, x=geometric(0.0033, 0.0173, 11), x_spacing=spacing)
    locus = np.column_stack([np.linspace(0.6, 1.4, 5), np.geomspace(0.0033, 0.0173, 5)])
    boundary = Boundary("onset", ("V", "K_beta"), ("m/s", "N m/rad"), "loci",
                        {"hopf_1": ("hopf", locus)}, (), (), ())
    figure = boundary_plot(boundary, grid)
    try:
        (ax, *_) = figure.axes
        assert (ax.get_xscale(), ax.get_yscale()) == ("linear", scale)
        assert ax.get_ylim() == pytest.approx((0.0033, 0.0173))
    finally:
        plt.close(figure)


def test_multiples_sampled_log_are_drawn_on_a_log_axis(stored):
    """I_x from 0.5 to 4 times its datum (under the decades rule's factor): log when the sweep
    samples log, linear when it does not."""
    result, _ = stored
    multiples = next(s for s in result.linear_sweeps if s.parameter == "I_x")
    for sweep, scale in ((multiples, "log"), (replace(multiples, spacing=Spacing.LINEAR),
                                              "linear")):
        figure = damping_multiples_plot([sweep])
        try:
            assert [ax.get_xscale() for ax in figure.axes] == [scale, scale]
        finally:
            plt.close(figure)


def test_compare_reports_a_sweep_sampled_with_another_spacing(stored):
    """The same values stored as log- and as linear-spaced: compare names the attribute."""
    result, _ = stored
    sweep = result.linear_sweeps[0]
    found = compare_linear_sweep(sweep, replace(sweep, spacing=Spacing.LINEAR), 1e-9)
    assert [(d.path, d.a, d.b) for d in found] == [
        ("/linear/sweeps/K_beta/@spacing", "log", "linear")]
    assert compare_linear_sweep(sweep, sweep, 1e-9) == []
