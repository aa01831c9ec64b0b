"""Unit tests of whirl_cli.plots: stability splitting, plotted data and styles, PNG output."""

from __future__ import annotations

import io
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from matplotlib.colors import same_color, to_hex
from matplotlib.container import ErrorbarContainer
from matplotlib.contour import QuadContourSet
from matplotlib.patches import Polygon

from whirl_cli.errors import WhirlError
from whirl_cli.plots import files, maps
from whirl_cli.plots.diagrams import (
    bifurcation_diagram,
    period_plot,
    phase_plane,
    projections_figure,
)
from whirl_cli.plots.files import PLOT_KINDS, save_study_plots
from whirl_cli.plots.key import (
    POSITION_STEP,
    _round_positions,
    new_figure,
    stability_curves,
    stability_segments,
)
from whirl_cli.plots.linear import linear_sweep_plot
from whirl_cli.plots.maps import boundary_plot, overhang_diagram, slice_continuation
from whirl_cli.results import (
    Boundary,
    Branch,
    BranchKind,
    ContinuationResult,
    LinearGrid,
    Orbit,
    PointType,
    SpecialPoint,
    StudyResult,
    UnsafeInterval,
)

from .plot_data import STATES, UNITS, branch_lines, make_branch, make_point, make_sweep

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def line_style(line) -> tuple[str, str]:
    """(colour name, linestyle) of a line; colours normalised so "g" or "#008000" match "green"."""
    names = {to_hex(name): name for name in ("green", "magenta", "blue", "red", "black")}
    return names.get(to_hex(line.get_color()), line.get_color()), line.get_linestyle()


def marker_lines(ax):
    return [line for line in ax.lines if line.get_marker() not in ("None", "none", "", None)]


# -- stability_segments ---------------------------------------------------------------------------

def test_segments_split_with_shared_switching_points():
    x = np.arange(6.0)
    y = 10 * x
    segments = stability_segments(x, y, np.array([1, 1, 0, 0, 0, 1], bool))
    assert [s for _, _, s in segments] == [True, False, True]
    np.testing.assert_array_equal(segments[0][0], [0, 1, 2])
    np.testing.assert_array_equal(segments[1][0], [2, 3, 4, 5])
    np.testing.assert_array_equal(segments[2][0], [5])
    np.testing.assert_array_equal(segments[1][1], [20, 30, 40, 50])
    for (xa, _, _), (xb, _, _) in zip(segments, segments[1:], strict=False):
        assert xa[-1] == xb[0]  # no gaps
    assert sum(len(xs) for xs, _, _ in segments) == len(x) + len(segments) - 1


@pytest.mark.parametrize("flag", [True, False])
def test_segments_uniform_stability_is_one_piece(flag):
    x, y = np.linspace(0, 1, 4), np.linspace(2, 3, 4)
    (segment,) = stability_segments(x, y, np.full(4, flag))
    np.testing.assert_array_equal(segment[0], x)
    np.testing.assert_array_equal(segment[1], y)
    assert segment[2] is flag


def test_segments_single_point_and_empty():
    ((xs, ys, stable),) = stability_segments(np.array([1.0]), np.array([2.0]),
                                             np.array([False]))
    assert xs.tolist() == [1.0] and ys.tolist() == [2.0] and stable is False
    assert stability_segments(np.array([]), np.array([]), np.array([], bool)) == []


def test_segments_alternating_every_point():
    segments = stability_segments(np.arange(3.0), np.arange(3.0), [True, False, True])
    assert [xs.tolist() for xs, _, _ in segments] == [[0, 1], [1, 2], [2]]


def test_segments_reject_mismatched_lengths():
    with pytest.raises(ValueError):
        stability_segments(np.arange(3.0), np.arange(2.0), np.ones(3, bool))


def test_curves_join_the_runs_of_each_stability_with_breaks():
    x = np.arange(7.0)
    curves = stability_curves(x, 10 * x, np.array([1, 1, 0, 0, 1, 0, 0], bool))
    assert [flag for _, _, flag in curves] == [True, False]  # in the order they first appear
    (xs_stable, ys_stable, _), (xs_unstable, _, _) = curves
    # the runs of stability_segments, each ending on the next run's first point, NaN between
    np.testing.assert_array_equal(xs_stable, [0, 1, 2, np.nan, 4, 5])
    np.testing.assert_array_equal(ys_stable, [0, 10, 20, np.nan, 40, 50])
    np.testing.assert_array_equal(xs_unstable, [2, 3, 4, np.nan, 5, 6])


def test_curves_of_one_stability_are_the_segment_itself():
    x, y = np.linspace(0, 1, 4), np.linspace(2, 3, 4)
    ((xs, ys, flag),) = stability_curves(x, y, np.zeros(4, bool))
    np.testing.assert_array_equal(xs, x)
    np.testing.assert_array_equal(ys, y)
    assert flag is False
    assert stability_curves(np.array([]), np.array([]), np.array([], bool)) == []


def test_a_neutral_line_of_equilibria_is_one_neutral_line():
    """A line of equilibria at one parameter value (a linear model at its branch point: a
    zero eigenvalue at every point), whose stability flag flips from point to point, is drawn
    as one line in the neutral style, holding every point, with its legend entry; a branch
    whose stability flips while its parameter moves is drawn as two lines, one per style."""
    n = 301
    flicker = make_branch("secondary_1a", BranchKind.EQUILIBRIUM, np.full(n, 0.039),
                          np.linspace(-1.5, 1.5, n), np.arange(n) % 2 == 0)
    ax = bifurcation_diagram(ContinuationResult("k1", "one-parameter", (flicker,), ())).axes[0]
    (line,) = branch_lines(ax)
    assert line_style(line) == ("grey", "-.")
    np.testing.assert_allclose(line.get_ydata(), np.degrees(np.linspace(-1.5, 1.5, n)))
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "neutral equilibria (zero eigenvalue)"]
    moving = make_branch("secondary_1a", BranchKind.EQUILIBRIUM, np.linspace(0.03, 0.04, n),
                         np.linspace(-1.5, 1.5, n), np.arange(n) % 2 == 0)
    ax = bifurcation_diagram(ContinuationResult("k1", "one-parameter", (moving,), ())).axes[0]
    lines = branch_lines(ax)
    assert sorted(line_style(line) for line in lines) == [("green", "-"), ("magenta", "--")]
    drawn = np.concatenate([line.get_ydata() for line in lines])
    np.testing.assert_allclose(np.unique(drawn[np.isfinite(drawn)]),
                               np.degrees(np.linspace(-1.5, 1.5, n)))


# -- the layout ----------------------------------------------------------------------------------

def test_layout_rounds_axes_positions_and_keeps_managing_them():
    figure = new_figure()
    ax = figure.add_subplot()
    ax.plot([0.0, 1.0], [0.0, 123456.0])
    ax.set_title("a title")
    figure.canvas.draw()
    first = ax.get_position().bounds  # (x0, y0, width, height): x1 = x0 + width is stored
    np.testing.assert_allclose(first, np.round(first, 9), rtol=0, atol=1e-15)
    assert ax.get_in_layout()
    figure.set_size_inches(9.0, 3.0)  # still laid out: a new position, rounded too
    figure.canvas.draw()
    second = ax.get_position().bounds
    assert second != first
    np.testing.assert_allclose(second, np.round(second, 9), rtol=0, atol=1e-15)


def test_positions_a_few_ulps_apart_round_to_the_same():
    """kiwisolver's layout varied by 8e-16 between two drawings of thesis figure 3.21 (its
    variables are ordered by memory address), enough to move an axes edge by a pixel."""
    bounds = (0.1362022084780088, 0.5086851851851851, 0.19539487485532367, 0.4279758078703704)
    rounded = []
    for noise in (0.0, 7.8e-16, -7.8e-16):
        figure = new_figure()
        ax = figure.add_subplot()
        ax.set_position([v + noise for v in bounds], which="both")
        ax.set_in_layout(True)
        _round_positions(figure)
        rounded.append(ax.get_position(original=True).bounds)
    assert rounded[0] == rounded[1] == rounded[2]
    np.testing.assert_allclose(rounded[0], bounds, atol=POSITION_STEP)


@pytest.mark.parametrize("draw", [bifurcation_diagram, period_plot, projections_figure])
def test_png_is_what_savefig_writes(continuation, draw):
    """files._png draws a figure once (its layout in that draw) and writes the pixels: the
    bytes savefig writes after its own layout pass, PNG text chunks included."""
    ours = files._png(draw(continuation), 150, {"whirl-figure-key": "abc"})
    buffer = io.BytesIO()
    draw(continuation).savefig(buffer, format="png", dpi=150,
                               metadata={"whirl-figure-key": "abc"})
    assert ours == buffer.getvalue()


# -- bifurcation_diagram -------------------------------------------------------------------------

def test_branch_styles_follow_kind_and_stability(continuation):
    ax = bifurcation_diagram(continuation).axes[0]
    styles = [line_style(line) for line in branch_lines(ax)]
    expected = {("green", "-"), ("magenta", "--"), ("blue", "-"), ("red", ":")}
    assert set(styles) == expected
    # equilibrium: stable [0.5..0.3], unstable [0.3..0.1]; periodic max: unstable, then stable
    lines = branch_lines(ax)
    assert len(lines) == 4
    by_style = {line_style(line): line for line in lines}
    np.testing.assert_allclose(by_style["green", "-"].get_xdata(), [0.5, 0.4, 0.3])
    np.testing.assert_allclose(by_style["magenta", "--"].get_xdata(), [0.3, 0.2, 0.1])
    np.testing.assert_allclose(by_style["red", ":"].get_xdata(), [0.3, 0.35, 0.4, 0.35])
    np.testing.assert_allclose(by_style["blue", "-"].get_xdata(), [0.35, 0.3])


def test_y_data_are_degrees(continuation):
    ax = bifurcation_diagram(continuation).axes[0]
    periodic = [line for line in branch_lines(ax) if line_style(line)[0] in ("red", "blue")]
    ys = np.concatenate([line.get_ydata() for line in periodic])
    np.testing.assert_allclose(np.sort(np.unique(ys)), np.degrees([0.0, 0.1, 0.2, 0.3, 0.4]))
    assert ax.get_ylabel() == "$\\theta$ (max) [deg]"
    assert ax.get_xlabel() == "K1 [N m/rad]"
    assert ax.get_title() == "hopf_K1"


def test_radians_when_degrees_false(continuation):
    ax = bifurcation_diagram(continuation, degrees=False).axes[0]
    ys = np.concatenate([line.get_ydata() for line in branch_lines(ax)])
    assert np.max(ys) == pytest.approx(0.4)
    assert ax.get_ylabel() == "$\\theta$ (max) [rad]"


def test_rate_state_in_deg_per_second(continuation):
    ax = bifurcation_diagram(continuation, state="dtheta").axes[0]
    ys = np.concatenate([line.get_ydata() for line in branch_lines(ax)])
    assert np.max(ys) == pytest.approx(np.degrees(0.04))
    assert ax.get_ylabel() == "dtheta (max) [deg/s]"


def renamed(continuation: ContinuationResult, names: tuple[str, ...]) -> ContinuationResult:
    """``continuation`` with the states named ``names`` (a model other than the classical)."""
    return replace(continuation, branches=tuple(
        replace(b, state_names=names, state_units=("m", "m", "m/s", "m/s"))
        for b in continuation.branches))


def test_first_state_by_default_any_names(continuation):
    """No pitch/yaw names assumed: the default is the first state (the model's first dof);
    the study names another with plot_state (files.save_study_plots' ``state``)."""
    other = renamed(continuation, ("x", "y", "dx", "dy"))
    ax = bifurcation_diagram(other).axes[0]
    assert ax.get_ylabel() == "x (max) [m]"
    np.testing.assert_allclose(np.max(np.concatenate(
        [line.get_ydata() for line in branch_lines(ax)])), 0.4)
    assert bifurcation_diagram(other, state="dy").axes[0].get_ylabel() == "dy (max) [m/s]"
    with pytest.raises(WhirlError, match="state 'theta' not on branch"):
        bifurcation_diagram(other, state="theta")


def test_min_drawn_for_periodic_only(continuation):
    ax = bifurcation_diagram(continuation, which=("max", "min")).axes[0]
    periodic = [line for line in branch_lines(ax) if line_style(line)[0] in ("red", "blue")]
    equilibrium = [line for line in branch_lines(ax) if line_style(line)[0] in ("green", "magenta")]
    assert len(periodic) == 4 and len(equilibrium) == 2
    ys = np.concatenate([line.get_ydata() for line in periodic])
    assert np.min(ys) == pytest.approx(np.degrees(-0.4))
    assert ax.get_ylabel() == "$\\theta$ (max, min) [deg]"


def test_special_point_markers(continuation):
    ax = bifurcation_diagram(continuation).axes[0]
    markers = {line.get_marker(): line for line in marker_lines(ax)}
    assert set(markers) == {"s", "*", "o"}  # HB, BP, LPC; no marker for EP
    hopf, branch_point, fold = markers["s"], markers["*"], markers["o"]
    assert hopf.get_markerfacecolor() == "none"
    assert same_color(hopf.get_markeredgecolor(), "black")
    assert same_color(branch_point.get_markerfacecolor(), "black")
    assert same_color(fold.get_markerfacecolor(), "black")
    np.testing.assert_allclose(np.c_[hopf.get_xdata(), hopf.get_ydata()], [[0.3, 0.0]])
    np.testing.assert_allclose(np.c_[branch_point.get_xdata(), branch_point.get_ydata()],
                               [[0.2, 0.0]])
    np.testing.assert_allclose(np.c_[fold.get_xdata(), fold.get_ydata()],
                               [[0.4, np.degrees(0.2)]])
    for line in markers.values():
        assert line.get_linestyle() == "None"


def test_legend_lists_only_present_styles(continuation):
    ax = bifurcation_diagram(continuation).axes[0]
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert labels == ["stable equilibrium", "unstable equilibrium", "stable periodic",
                      "unstable periodic", "Hopf (HB)", "branch point (BP, BPC)",
                      "fold (LP, LPC)"]


def test_legend_without_periodic_or_points():
    equilibrium = make_branch("main", BranchKind.EQUILIBRIUM, [0.1, 0.2], [0.0, 0.0], [1, 1])
    result = ContinuationResult("eq", "one-parameter", (equilibrium,), ())
    ax = bifurcation_diagram(result).axes[0]
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["stable equilibrium"]
    assert ax.get_ylabel() == "$\\theta$ [deg]"


def test_all_markers_of_the_key():
    equilibrium = make_branch("main", BranchKind.EQUILIBRIUM, [0.1, 0.2], [0.0, 0.0], [0, 0])
    types = [PointType.HB, PointType.BP, PointType.BPC, PointType.LP, PointType.LPC,
             PointType.HOMOCLINIC, PointType.HETEROCLINIC, PointType.TR, PointType.PD,
             PointType.REGULAR, PointType.RG, PointType.UZ, PointType.EP, PointType.MX]
    points = tuple(make_point("main", t, 0.1 + 0.01 * i, 0.0) for i, t in enumerate(types))
    ax = bifurcation_diagram(ContinuationResult("all", "one-parameter", (equilibrium,),
                                                points)).axes[0]
    found = {(line.get_marker(), line.get_markerfacecolor() == "none"): len(line.get_xdata())
             for line in marker_lines(ax)}
    assert found == {("s", True): 1, ("*", False): 2, ("o", False): 2, ("^", False): 1,
                     ("^", True): 1, ("o", True): 1, ("D", False): 1}


def test_draws_on_given_axes(continuation):
    figure = new_figure()
    ax = figure.add_subplot()
    assert bifurcation_diagram(continuation, ax=ax) is figure
    assert len(figure.axes) == 1 and ax.lines


def test_loci_are_skipped(continuation):
    locus = make_branch("hopf_locus", BranchKind.HOPF_LOCUS, [0.1, 0.2], [0.0, 0.0], [0, 0])
    extended = ContinuationResult(continuation.name, continuation.kind,
                                  continuation.branches + (locus,), continuation.special_points)
    plain = bifurcation_diagram(continuation).axes[0]
    with_locus = bifurcation_diagram(extended).axes[0]
    assert len(with_locus.lines) == len(plain.lines)


@pytest.mark.parametrize("kwargs", [{"state": "phi"}, {"which": ("mean",)}, {"which": ()}])
def test_bad_arguments_raise(continuation, kwargs):
    with pytest.raises(WhirlError):
        bifurcation_diagram(continuation, **kwargs)


# -- linear_sweep_plot ---------------------------------------------------------------------------

def test_linear_sweep_plot_modes():
    sweep = make_sweep()
    figure = linear_sweep_plot(sweep)
    ax_freq, ax_damp = figure.axes
    modes = {line.get_label(): line for line in ax_freq.lines + ax_damp.lines
             if not line.get_label().startswith("_")}
    assert [line.get_label() for line in ax_freq.lines if line.get_label() in modes] == [
        "BW", "FW"]
    np.testing.assert_allclose(ax_freq.lines[0].get_ydata(), 10 - np.arange(5))
    (fw,) = [line for line in ax_damp.lines if line.get_label() == "FW"]
    np.testing.assert_allclose(fw.get_ydata(), sweep.damping_ratio[:, 2])
    zero = [line for line in ax_damp.lines if np.all(np.asarray(line.get_ydata()) == 0)]
    assert zero, "zero line in the damping panel"
    assert ax_freq.get_ylabel() == "frequency [rad/s]"
    assert ax_damp.get_ylabel() == "damping ratio [-]"
    assert ax_damp.get_xlabel() == "K1 [N m/rad]"


# -- save_study_plots ----------------------------------------------------------------------------

def test_save_study_plots_writes_pngs_only(tmp_path, continuation):
    two_parameter = ContinuationResult("hopf_locus", "two-parameter", (), ())
    result = StudyResult("study", "classical", (continuation, two_parameter), (make_sweep(),), ())
    paths = save_study_plots(result, ("bifurcation", "linear"), tmp_path, "run")
    assert paths == sorted([tmp_path / "run_hopf_K1_bifurcation.png",
                            tmp_path / "run_linear_K1.png"])
    assert sorted(tmp_path.iterdir()) == paths  # no temporary files left behind
    for path in paths:
        assert path.read_bytes()[:8] == PNG_MAGIC


def test_save_study_plots_selected_kind_and_overwrite(tmp_path, continuation):
    result = StudyResult("study", "classical", (continuation,), (make_sweep(),), ())
    (tmp_path / "run_linear_K1.png").write_bytes(PNG_MAGIC + b"old")  # an older plot
    paths = save_study_plots(result, ("linear",), tmp_path, "run")
    assert paths == [tmp_path / "run_linear_K1.png"]
    assert paths[0].read_bytes()[:8] == PNG_MAGIC
    assert [p.name for p in tmp_path.iterdir()] == ["run_linear_K1.png"]


def test_plots_drawn_in_worker_processes_are_the_same_files(continuation):
    """``jobs`` forks workers to draw: the same names and PNG bytes, in the same order."""
    from whirl_cli.plots.files import render_study_plots

    result = StudyResult("study", "classical", (continuation,), (make_sweep(),), ())
    kinds = ("bifurcation", "linear", "root_locus", "projections")
    serial = render_study_plots(result, kinds, "run", jobs=1)
    assert len(serial) == 4
    assert render_study_plots(result, kinds, "run", jobs=2) == serial


def test_save_study_plots_rejects_unknown_kind(tmp_path, continuation):
    result = StudyResult("study", "classical", (continuation,), (), ())
    with pytest.raises(WhirlError):
        save_study_plots(result, ("contour",), tmp_path, "run")
    assert list(tmp_path.iterdir()) == []


def test_plot_kinds():
    assert PLOT_KINDS == ("bifurcation", "linear", "root_locus", "damping_multiples",
                          "projections", "period", "phase", "boundary", "amplitude",
                          "time_history", "hub_path", "law", "poincare", "spectrum",
                          "orbit_diagram")


# -- projections_figure --------------------------------------------------------------------------

def test_projections_one_axes_per_state(continuation):
    figure = projections_figure(continuation)
    axes = figure.axes
    assert len(axes) == 4
    assert [ax.get_ylabel() for ax in axes] == ["$\\theta$ (max) [deg]", "$\\psi$ (max) [deg]",
                                                "dtheta (max) [deg/s]", "dpsi (max) [deg/s]"]
    # theta max reaches 0.4 rad, the other states 0.1 * theta (rad or rad/s)
    for ax, top in zip(axes, [0.4, 0.04, 0.04, 0.04], strict=True):
        ys = np.concatenate([line.get_ydata() for line in branch_lines(ax)])
        assert np.max(ys) == pytest.approx(np.degrees(top))
        assert len(branch_lines(ax)) == 4 and len(marker_lines(ax)) == 3
    assert all(axes[0].get_shared_x_axes().joined(axes[0], ax) for ax in axes)
    assert [ax.get_legend() is not None for ax in axes] == [True, False, False, False]
    assert [ax.get_xlabel() for ax in axes] == ["", "", "K1 [N m/rad]", "K1 [N m/rad]"]
    assert figure.get_suptitle() == "hopf_K1"


def test_projections_odd_state_count_in_radians(continuation):
    def three(branch):
        return replace(branch, state_names=STATES[:3], state_units=UNITS[:3],
                       state_max=branch.state_max[:, :3], state_min=branch.state_min[:, :3],
                       eigenvalues=branch.eigenvalues[:, :3])

    cut = replace(continuation, branches=tuple(three(b) for b in continuation.branches),
                  special_points=tuple(replace(p, state=p.state[:3])
                                       for p in continuation.special_points))
    axes = projections_figure(cut, which=("max", "min"), degrees=False).axes
    assert [ax.get_ylabel() for ax in axes] == ["$\\theta$ (max, min) [rad]",
                                                "$\\psi$ (max, min) [rad]",
                                                "dtheta (max, min) [rad/s]"]
    assert [ax.get_xlabel() for ax in axes] == ["", "K1 [N m/rad]", "K1 [N m/rad]"]
    ys = np.concatenate([line.get_ydata() for line in branch_lines(axes[0])])
    assert np.min(ys) == pytest.approx(-0.4) and np.max(ys) == pytest.approx(0.4)


def test_projections_without_branches():
    figure = projections_figure(ContinuationResult("empty", "one-parameter", (), ()))
    assert len(figure.axes) == 1 and not figure.axes[0].lines


# -- period_plot ---------------------------------------------------------------------------------

def with_period(branch: Branch, period) -> Branch:
    return replace(branch, period=np.asarray(period, dtype=float))


def period_continuation(period, points=()) -> ContinuationResult:
    equilibrium = make_branch("main_down", BranchKind.EQUILIBRIUM,
                              [0.5, 0.4, 0.3, 0.2, 0.1], [0.0] * 5, [1, 1, 0, 0, 0])
    periodic = make_branch("periodic_1", BranchKind.PERIODIC, [0.3, 0.35, 0.4, 0.35, 0.3],
                           [0.0, 0.1, 0.2, 0.3, 0.4], [0, 0, 0, 1, 1])
    return ContinuationResult("hopf_K1", "one-parameter",
                              (equilibrium, with_period(periodic, period)), tuple(points))


def test_period_plot_segments_styles_and_markers():
    hopf = replace(make_point("main_down", PointType.HB, 0.3, 0.0), index=2, period=0.2)
    fold = replace(make_point("periodic_1", PointType.LPC, 0.4, 0.2), index=2)  # period NaN
    end = make_point("periodic_1", PointType.EP, 0.3, 0.4)
    bp_on_equilibrium = make_point("main_down", PointType.BP, 0.2, 0.0)
    result = period_continuation([0.2, 0.25, 0.3, 0.35, 0.4],
                                 [hopf, fold, end, bp_on_equilibrium])
    ax = period_plot(result).axes[0]
    lines = branch_lines(ax)
    assert sorted(line_style(line) for line in lines) == [("blue", "-"), ("red", ":")]
    by_style = {line_style(line): line for line in lines}
    np.testing.assert_allclose(by_style["red", ":"].get_xdata(), [0.3, 0.35, 0.4, 0.35])
    np.testing.assert_allclose(by_style["red", ":"].get_ydata(), [0.2, 0.25, 0.3, 0.35])
    np.testing.assert_allclose(by_style["blue", "-"].get_xdata(), [0.35, 0.3])
    np.testing.assert_allclose(by_style["blue", "-"].get_ydata(), [0.35, 0.4])
    markers = {line.get_marker(): line for line in marker_lines(ax)}
    assert set(markers) == {"s", "o"}  # Hopf and LPC; no EP, no BP of the equilibrium
    np.testing.assert_allclose(np.c_[markers["s"].get_xdata(), markers["s"].get_ydata()],
                               [[0.3, 0.2]])
    np.testing.assert_allclose(np.c_[markers["o"].get_xdata(), markers["o"].get_ydata()],
                               [[0.4, 0.3]])  # the branch's period at the LPC's row
    assert ax.get_yscale() == "linear"
    assert ax.get_xlabel() == "K1 [N m/rad]" and ax.get_ylabel() == "period [s]"
    assert not ax.containers
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "stable periodic", "unstable periodic", "Hopf (HB)", "fold (LP, LPC)"]


@pytest.mark.parametrize(("last", "scale"), [(3.9, "linear"), (4.0, "linear"), (4.2, "log")])
def test_period_plot_log_scale_only_above_factor_20(last, scale):
    ax = period_plot(period_continuation([0.2, 0.5, 1.0, 2.0, last])).axes[0]
    assert ax.get_yscale() == scale


def test_period_plot_brackets_bracketed_homoclinic():
    homoclinic = SpecialPoint(
        branch="periodic_1", index=4, point_type=int(PointType.HOMOCLINIC),
        parameter_names=("K1", "V"), parameters=np.array([0.29]),
        state=np.zeros(4), period=9.0, stable=False, status="bracketed",
        bracket=np.array([0.3, 0.28]), residual=0.01)
    heteroclinic = replace(homoclinic, point_type=int(PointType.HETEROCLINIC),
                           parameters=np.array([0.295]), status="located",
                           bracket=np.full(2, np.nan))
    result = period_continuation([0.2, 0.5, 1.0, 12.0, 8.0], [homoclinic, heteroclinic])
    ax = period_plot(result).axes[0]
    found = {(line.get_marker(), line.get_markerfacecolor() == "none"): line
             for line in marker_lines(ax) if line.get_marker() == "^"}
    # both at the period of the branch's last point, x = their parameter estimate
    np.testing.assert_allclose(np.c_[found["^", False].get_xdata(),
                                     found["^", False].get_ydata()], [[0.29, 8.0]])
    np.testing.assert_allclose(np.c_[found["^", True].get_xdata(),
                                     found["^", True].get_ydata()], [[0.295, 8.0]])
    (container,) = ax.containers  # only the bracketed point gets a bracket
    assert isinstance(container, ErrorbarContainer)
    (bar,) = container.lines[2]
    np.testing.assert_allclose(bar.get_segments()[0], [[0.28, 12.0], [0.3, 12.0]])
    assert ax.get_yscale() == "log"  # 12 / 0.2 > 20
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[-3:] == ["homoclinic", "heteroclinic", "bracket (global bifurcation)"]


def test_period_plot_without_periodic_branch():
    equilibrium = make_branch("main", BranchKind.EQUILIBRIUM, [0.1, 0.2], [0.0, 0.0], [1, 1])
    points = (make_point("main", PointType.HB, 0.1, 0.0),)  # no period: no marker
    ax = period_plot(ContinuationResult("eq", "one-parameter", (equilibrium,),
                                        points)).axes[0]
    assert not ax.lines and ax.get_legend() is None


# -- phase_plane ---------------------------------------------------------------------------------

def make_orbit(label: int, index: int, k1: float, radius: float, closed: bool) -> Orbit:
    """A circle of ``radius`` rad in (theta, psi), 20 samples, endpoint repeated if ``closed``."""
    period = 0.2
    time = np.linspace(0.0, period, 21 if closed else 20, endpoint=closed)
    phase = 2 * np.pi * time / period
    theta, psi = radius * np.cos(phase), radius * np.sin(phase)
    states = np.column_stack([theta, psi, -theta * 31.4, psi * 31.4])
    if closed:
        states[-1] = states[0]
    return Orbit(label=label, point_type=0, index=index, parameters=np.array([k1, 6.7]),
                 period=period, time=time, states=states)


@pytest.fixture
def orbit_branch() -> Branch:
    branch = make_branch("periodic_1", BranchKind.PERIODIC, [0.3, 0.35, 0.4, 0.35, 0.3],
                         [0.0, 0.1, 0.2, 0.3, 0.4], [0, 0, 0, 1, 1])
    orbits = (make_orbit(3, 1, 0.35, 0.1, closed=False),
              make_orbit(5, 4, 0.1234, 0.4, closed=True))
    return replace(branch, orbits=orbits)


def test_phase_plane_closed_curves_in_degrees(orbit_branch):
    ax = phase_plane(orbit_branch).axes[0]
    assert len(ax.lines) == 2
    by_parameter = orbit_branch.orbits[::-1]  # K1 = 0.1234, then 0.35
    for line, orbit in zip(ax.lines, by_parameter, strict=True):
        xs, ys = line.get_xdata(), line.get_ydata()
        assert (xs[0], ys[0]) == (xs[-1], ys[-1])
        np.testing.assert_allclose(xs[:20], np.degrees(orbit.states[:20, 0]))
        np.testing.assert_allclose(ys[:20], np.degrees(orbit.states[:20, 1]))
    assert [len(line.get_xdata()) for line in ax.lines] == [21, 21]  # one closed, one as is
    assert [line.get_linestyle() for line in ax.lines] == ["-", ":"]
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "K1 = 0.1234 (stable)", "K1 = 0.35 (unstable)"]
    assert ax.get_xlabel() == "$\\theta$ [deg]" and ax.get_ylabel() == "$\\psi$ [deg]"
    assert ax.get_aspect() == 1.0
    assert ax.get_title() == "periodic_1"


def test_phase_plane_selected_labels_states_and_radians(orbit_branch):
    ax = phase_plane(orbit_branch, labels=[5], x="theta", y="dtheta",
                     degrees=False).axes[0]
    (line,) = ax.lines
    assert np.max(line.get_ydata()) == pytest.approx(0.4 * 31.4)
    assert ax.get_ylabel() == "dtheta [rad/s]"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["K1 = 0.1234 (stable)"]


def test_phase_plane_legend_sorted_by_parameter_whatever_the_order_asked(orbit_branch):
    orbits = tuple(make_orbit(label, label, k1, 0.1, closed=True)
                   for label, k1 in ((1, 0.3), (2, -0.2), (3, 0.05), (4, 0.1)))
    branch = replace(orbit_branch, orbits=orbits)
    for labels in (None, [4, 1, 3, 2], [1, 4]):
        ax = phase_plane(branch, labels=labels).axes[0]
        shown = [float(t.get_text().split(" = ")[1].split()[0])
                 for t in ax.get_legend().get_texts()]
        assert shown == sorted(shown) and len(shown) == (4 if labels is None else len(labels))


def test_phase_plane_draws_on_given_axes(orbit_branch):
    figure = new_figure()
    ax = figure.add_subplot()
    assert phase_plane(orbit_branch, ax=ax) is figure and len(ax.lines) == 2


@pytest.mark.parametrize("kwargs", [{"labels": [4]}, {"x": "phi"}, {"y": "chi"}])
def test_phase_plane_bad_arguments_raise(orbit_branch, kwargs):
    with pytest.raises(WhirlError):
        phase_plane(orbit_branch, **kwargs)


def test_phase_plane_rejects_equilibrium_branch():
    equilibrium = make_branch("main", BranchKind.EQUILIBRIUM, [0.1, 0.2], [0.0, 0.0], [1, 1])
    with pytest.raises(WhirlError):
        phase_plane(equilibrium)


def test_phase_plane_of_the_first_two_states_any_names(orbit_branch):
    other = replace(orbit_branch, state_names=("x", "y", "dx", "dy"),
                    state_units=("m", "m", "m/s", "m/s"))
    ax = phase_plane(other).axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x [m]", "y [m]")
    np.testing.assert_allclose(ax.lines[0].get_ydata()[:20], other.orbits[1].states[:20, 1])


def test_phase_labels_at_most_twelve_user_points_first(orbit_branch):
    """A study's phase plane draws every orbit of a short family; of a long one 12: its user
    points (orbits_at, UZ) and the others spread along the branch, first and last included."""
    small = replace(orbit_branch, orbits=tuple(
        replace(o, states=o.states * 0.5) for o in orbit_branch.orbits))  # within 20 deg
    assert files.phase_labels(small) == [3, 5]
    orbits = tuple(replace(orbit_branch.orbits[0], label=k + 1, index=k,
                           point_type=int(PointType.UZ) if k in (7, 8) else 0)
                   for k in range(30))
    long = replace(orbit_branch, orbits=orbits)
    labels = files.phase_labels(long)
    assert len(labels) == files.PHASE_ORBITS == 12
    assert {8, 9} <= set(labels) and labels[0] == 1 and labels[-1] == 30
    assert labels == sorted(labels)


# -- save_study_plots: new kinds -----------------------------------------------------------------

def test_save_study_plots_new_kinds(tmp_path, continuation, orbit_branch):
    without_orbits = replace(orbit_branch, name="periodic_2", orbits=())
    rich = replace(continuation, name="hopf K1",  # space made file-safe
                   branches=(continuation.branches[0], orbit_branch, without_orbits))
    equilibria = ContinuationResult("eq", "one-parameter", (continuation.branches[0],), ())
    locus = ContinuationResult("hopf_locus", "two-parameter", (), ())
    result = StudyResult("study", "classical", (rich, equilibria, locus), (make_sweep(),), ())
    paths = save_study_plots(result, ("projections", "period", "phase"), tmp_path, "run")
    assert [p.name for p in paths] == sorted([
        "run_hopf_K1_projections.png", "run_eq_projections.png", "run_hopf_K1_period.png",
        "run_hopf_K1_periodic_1_phase.png"])
    assert sorted(tmp_path.iterdir()) == paths  # no temporary files left behind
    for path in paths:
        assert path.read_bytes()[:8] == PNG_MAGIC


# -- boundary_plot -------------------------------------------------------------------------------

PAIR = ("K1", "K_psi")
PAIR_UNITS = ("N m/rad", "N m/rad")
CASES = (0.4, 0.3, 0.2, 0.05, 0.037)
FLUTTER_LINE = np.array([[0.0, 0.3], [0.1, 0.2]])
DIVERGENCE_LINE = np.array([[0.1, 0.2], [0.3, 0.0]])
HOPF = np.array([[0.3, 0.0], [0.2, 0.1], [0.0, 0.3]])
LPC = np.array([[0.45, 0.0], [0.15, 0.3]])
PITCHFORK = np.array([[0.5, 0.0], [0.6, 0.5]])
FOLD = np.array([[0.7, 0.0], [0.8, 0.5]])
POLYGON = np.array([[0.3, 0.0], [0.45, 0.0], [0.15, 0.3], [0.0, 0.3], [0.3, 0.0]])


def make_grid(max_real=None) -> LinearGrid:
    """K1 in [0, 1] x K_psi in [0, 0.5]; unstable (max_real > 0) where K1 + K_psi < 0.3."""
    x, y = np.linspace(0.0, 1.0, 21), np.linspace(0.0, 0.5, 11)
    xx, yy = np.meshgrid(x, y)
    max_real = 0.3 - xx - yy if max_real is None else max_real
    return LinearGrid("K1", "K_psi", "N m/rad", "N m/rad", x, y, max_real, xx < 0.1,
                      (FLUTTER_LINE,), (DIVERGENCE_LINE,))


def make_boundary(loci=None, polygons=(POLYGON,)) -> Boundary:
    if loci is None:
        loci = {"hopf_1": ("hopf", HOPF), "bp_1": ("branch_point", PITCHFORK),
                "lp_1": ("fold", FOLD), "lpc_1": ("fold_of_cycles", LPC)}
    intervals = (UnsafeInterval(0.2, 0.1, 0.25, "flutter"),
                 UnsafeInterval(0.2, 0.32, 0.35, "divergence"),
                 UnsafeInterval(0.3, 0.0, 0.15, "flutter"),
                 UnsafeInterval(0.2 + 1e-9, 0.6, 0.7, "flutter"))  # another slice
    return Boundary("kk", PAIR, PAIR_UNITS, "loci", loci, intervals, polygons, CASES)


def legend_labels(ax) -> list[str]:
    legend = ax.get_legend()
    return [] if legend is None else [text.get_text() for text in legend.get_texts()]


def contour_sets(ax) -> list[QuadContourSet]:
    return [c for c in ax.collections if isinstance(c, QuadContourSet)]


def polyline(ax, points) -> object:
    """The single line of ``ax`` through exactly ``points`` (K, 2)."""
    found = [line for line in ax.lines if np.shape(line.get_xydata()) == np.shape(points)
             and np.allclose(line.get_xydata(), points)]
    assert len(found) == 1, f"{len(found)} lines through {points.tolist()}"
    return found[0]


@pytest.mark.parametrize("with_loci", [False, True])
def test_boundary_plot_shades_linearly_unstable_region(with_loci):
    """Grey under a boundary's loci; hatched over the max Re lambda surface of a grid alone."""
    grid = make_grid()
    boundary = make_boundary(polygons=()) if with_loci else None
    ax = boundary_plot(boundary, grid).axes[0]
    (contours,) = contour_sets(ax)
    np.testing.assert_array_equal(contours.levels, [0.0, np.inf])
    if with_loci:
        assert same_color(contours.get_facecolor()[0], "lightgrey")
    else:
        assert contours.hatches == ["//"]
    paths = contours.get_paths()
    xx, yy = np.meshgrid(grid.x, grid.y)
    inside = np.array([any(path.contains_point(xy) for path in paths)
                       for xy in np.column_stack([xx.ravel(), yy.ravel()])])
    interior = ((xx > grid.x[0]) & (xx < grid.x[-1]) & (yy > grid.y[0]) & (yy < grid.y[-1]))
    clear = (np.abs(grid.max_real) > 0.02).ravel() & interior.ravel()  # off path edges
    assert (grid.max_real.ravel()[clear] > 0).sum() >= 3
    np.testing.assert_array_equal(inside[clear], grid.max_real.ravel()[clear] > 0)


def test_boundary_plot_without_unstable_points_has_no_shading():
    ax = boundary_plot(None, make_grid(np.full((11, 21), -1.0))).axes[0]
    assert contour_sets(ax) == []
    assert legend_labels(ax) == ["linear boundary (flutter)", "linear boundary (divergence)"]


def test_boundary_plot_linear_contour_styles():
    ax = boundary_plot(None, make_grid()).axes[0]
    flutter, divergence = polyline(ax, FLUTTER_LINE), polyline(ax, DIVERGENCE_LINE)
    assert line_style(flutter) == ("black", "-") and flutter.get_linewidth() < 1.0
    assert line_style(divergence) == ("black", "--") and divergence.get_linewidth() < 1.0


def test_boundary_plot_grid_only_labels_limits_and_legend():
    ax = boundary_plot(None, make_grid()).axes[0]
    assert ax.get_xlabel() == "K1 [N m/rad]" and ax.get_ylabel() == "$K_{\\psi}$ [N m/rad]"
    assert ax.get_xlim() == (0.0, 1.0) and ax.get_ylim() == (0.0, 0.5)
    assert legend_labels(ax) == ["linearly unstable", "linear boundary (flutter)",
                                 "linear boundary (divergence)"]
    assert len(ax.patches) == 0 and ax.get_title() == "linear stability"


def test_boundary_plot_loci_styles_per_kind():
    ax = boundary_plot(make_boundary(), None).axes[0]
    assert same_color(polyline(ax, HOPF).get_color(), "darkblue")
    assert polyline(ax, HOPF).get_linestyle() == "-"
    assert line_style(polyline(ax, PITCHFORK)) == ("black", "--")
    assert same_color(polyline(ax, FOLD).get_color(), "grey")
    assert polyline(ax, FOLD).get_linestyle() == "-."
    assert same_color(polyline(ax, LPC).get_color(), "orange")
    assert polyline(ax, LPC).get_linestyle() == "-"


def test_boundary_plot_unsafe_polygons():
    second = POLYGON + [0.0, 0.1]
    ax = boundary_plot(make_boundary(polygons=(POLYGON, second)), None).axes[0]
    polygons = [patch for patch in ax.patches if isinstance(patch, Polygon)]
    assert len(polygons) == 2
    for patch, expected in zip(polygons, (POLYGON, second), strict=True):
        np.testing.assert_allclose(patch.get_xy(), expected)
        assert same_color(patch.get_facecolor()[:3], "red")
        assert patch.get_alpha() == pytest.approx(0.5)


def test_boundary_plot_case_lines_and_labels():
    ax = boundary_plot(make_boundary(), make_grid(), cases=CASES).axes[0]
    dotted = [line for line in ax.lines if line.get_linestyle() == ":"]
    assert [tuple(line.get_ydata()) for line in dotted] == [(v, v) for v in CASES]
    assert all(line_style(line)[0] == "black" for line in dotted)
    labels = {text.get_text(): text for text in ax.texts}
    assert sorted(labels) == [f"case {k}" for k in range(1, 6)]
    ax.figure.canvas.draw()
    boxes = [labels[f"case {k}"].get_window_extent() for k in range(1, 6)]
    centres = [(box.y0 + box.y1) / 2 for box in boxes]
    at_case = ax.transData.transform([(0.0, v) for v in CASES[:3]])[:, 1]
    assert centres[:3] == pytest.approx(at_case, abs=0.5)  # 0.4, 0.3, 0.2 at their lines
    assert all(box.x0 > ax.get_window_extent().x1 for box in boxes)  # right of the axes
    assert all(low.y1 <= high.y0 for low, high in zip(boxes[1:], boxes, strict=False))
    assert "case" not in " ".join(legend_labels(ax))


def test_close_case_labels_stay_apart_on_a_short_panel():
    """On a short sheet panel the labels of cases 4 and 5 (0.05 and 0.037) do not overlap."""
    from whirl_cli.plots.key import new_figure

    ax = new_figure(figsize=(6.0, 2.2)).add_subplot()
    boundary_plot(make_boundary(), make_grid(), cases=CASES, ax=ax)
    ax.figure.canvas.draw()
    boxes = sorted((text.get_window_extent() for text in ax.texts), key=lambda box: box.y0)
    assert len(boxes) == 5
    assert all(low.y1 <= high.y0 for low, high in zip(boxes, boxes[1:], strict=False))


def test_boundary_plot_cases_outside_limits_are_not_labelled():
    ax = boundary_plot(None, make_grid(), cases=(0.2, 0.9)).axes[0]
    assert [text.get_text() for text in ax.texts] == ["case 1"]


def test_boundary_plot_both_legend_and_title():
    ax = boundary_plot(make_boundary(), make_grid(), cases=CASES).axes[0]
    assert legend_labels(ax) == [
        "linearly unstable", "linear boundary (flutter)", "linear boundary (divergence)",
        "Hopf locus (flutter)", "branch point locus (divergence)", "fold locus (LP)",
        "fold of cycles locus (LPC)", "unsafe (overhang)"]
    assert ax.get_title() == "kk"
    assert ax.get_xlim() == (0.0, 1.0) and ax.get_ylim() == (0.0, 0.5)  # the grid's extent


def test_boundary_plot_boundary_only_legend_and_limits():
    loci = {"hopf_1": ("hopf", HOPF), "hopf_2": ("hopf", HOPF + 0.05),
            "lpc_1": ("fold_of_cycles", LPC),
            "other": ("period_doubling", np.array([[5.0, 5.0]] * 2))}  # a kind not drawn
    ax = boundary_plot(make_boundary(loci=loci, polygons=()), None).axes[0]
    assert legend_labels(ax) == ["Hopf locus (flutter)", "fold of cycles locus (LPC)"]
    assert len(ax.lines) == 3 and contour_sets(ax) == []
    # extent of the loci (x 0..0.45, y 0..0.35) with a 2 % margin
    np.testing.assert_allclose(ax.get_xlim(), [-0.009, 0.459])
    np.testing.assert_allclose(ax.get_ylim(), [-0.007, 0.357])
    assert ax.get_xlabel() == "K1 [N m/rad]" and ax.get_ylabel() == "$K_{\\psi}$ [N m/rad]"


def test_boundary_plot_transposes_a_swapped_grid():
    grid = make_grid()
    swapped = LinearGrid("K_psi", "K1", "N m/rad", "N m/rad", grid.y, grid.x,
                         grid.max_real.T, grid.oscillatory.T, (FLUTTER_LINE[:, ::-1],),
                         (DIVERGENCE_LINE[:, ::-1],))
    ax = boundary_plot(make_boundary(), swapped).axes[0]
    assert ax.get_xlim() == (0.0, 1.0) and ax.get_ylim() == (0.0, 0.5)
    polyline(ax, FLUTTER_LINE)
    (contours,) = contour_sets(ax)
    assert any(path.contains_point((0.05, 0.05)) for path in contours.get_paths())


def test_boundary_plot_rejects_bad_input():
    with pytest.raises(WhirlError):
        boundary_plot(None, None)
    other = replace(make_grid(), x_parameter="V")
    with pytest.raises(WhirlError):
        boundary_plot(make_boundary(), other)


def test_boundary_plot_draws_on_given_axes():
    figure = new_figure()
    ax = figure.add_subplot()
    assert boundary_plot(make_boundary(), None, ax=ax) is figure
    assert len(figure.axes) == 1 and ax.lines


# -- overhang_diagram ----------------------------------------------------------------------------

def two_parameter_continuation(continuation: ContinuationResult) -> ContinuationResult:
    """Slices 0..4 (CASES) each holding ``continuation``'s branches; points on slice 2 only."""
    branches = tuple(replace(branch, name=f"slice_{k}.{branch.name}")
                     for k in range(len(CASES)) for branch in continuation.branches)
    points = tuple(replace(point, branch=f"slice_2.{point.branch}", parameter_names=PAIR,
                           parameters=np.array([point.parameters[0], 0.2]))
                   for point in continuation.special_points)
    locus = make_branch("hopf_locus_1", BranchKind.HOPF_LOCUS, [0.1, 0.2], [0.0, 0.0], [0, 0])
    return ContinuationResult("kk", "two-parameter", branches + (locus,), points)


def bands(ax) -> list[tuple[float, float]]:
    return [(patch.get_x(), patch.get_x() + patch.get_width()) for patch in ax.patches]


def test_slice_continuation(continuation):
    sliced = slice_continuation(two_parameter_continuation(continuation), 2)
    assert sliced.kind == "one-parameter" and sliced.name == "kk.slice_2"
    assert [b.name for b in sliced.branches] == ["main_down", "periodic_1"]
    assert [p.branch for p in sliced.special_points] == [
        "main_down", "main_down", "periodic_1", "periodic_1"]
    assert slice_continuation(two_parameter_continuation(continuation), 1
                              ).special_points == ()


def test_overhang_diagram_bands_at_interval_edges(continuation):
    two = two_parameter_continuation(continuation)
    ax = overhang_diagram(two, make_boundary(), 0.2).axes[0]
    assert bands(ax) == [pytest.approx((0.1, 0.25)), pytest.approx((0.32, 0.35))]
    for patch in ax.patches:
        assert same_color(patch.get_facecolor()[:3], "red")
        assert patch.get_alpha() == pytest.approx(0.25)
    assert legend_labels(ax) == [
        "stable equilibrium", "unstable equilibrium", "stable periodic", "unstable periodic",
        "Hopf (HB)", "branch point (BP, BPC)", "fold (LP, LPC)", "unsafe (overhang)"]
    assert ax.get_title() == "kk: K_psi = 0.2"
    assert ax.get_xlabel() == "K1 [N m/rad]" and ax.get_ylabel() == "$\\theta$ (max) [deg]"
    # the slice's branches only, as in a plain bifurcation diagram
    plain = bifurcation_diagram(continuation).axes[0]
    assert len(ax.lines) == len(plain.lines)
    for mine, theirs in zip(ax.lines, plain.lines, strict=True):
        np.testing.assert_allclose(mine.get_xydata(), theirs.get_xydata())


def test_overhang_diagram_other_slice_and_no_interval(continuation):
    two = two_parameter_continuation(continuation)
    ax = overhang_diagram(two, make_boundary(), 0.3).axes[0]
    assert bands(ax) == [pytest.approx((0.0, 0.15))]
    assert len(marker_lines(ax)) == 0  # special points are on slice 2 only
    ax = overhang_diagram(two, make_boundary(), 0.05).axes[0]
    assert len(ax.patches) == 0 and "unsafe (overhang)" not in legend_labels(ax)


def test_overhang_diagram_one_parameter(continuation):
    ax = overhang_diagram(continuation, make_boundary(), 0.2, which=("max", "min"),
                          degrees=False).axes[0]
    assert bands(ax) == [pytest.approx((0.1, 0.25)), pytest.approx((0.32, 0.35))]
    assert ax.get_ylabel() == "$\\theta$ (max, min) [rad]"
    assert legend_labels(ax)[-1] == "unsafe (overhang)"
    ax = overhang_diagram(continuation, None, 0.2).axes[0]
    assert len(ax.patches) == 0 and ax.get_title() == "hopf_K1"


def test_overhang_diagram_rejects_bad_input(continuation):
    two = two_parameter_continuation(continuation)
    with pytest.raises(WhirlError):
        overhang_diagram(two, None, 0.2)
    with pytest.raises(WhirlError):
        overhang_diagram(two, make_boundary(), 0.25)  # not a slice
    with pytest.raises(WhirlError):
        overhang_diagram(two, make_boundary(), 0.2, state="phi")


# -- save_study_plots: boundary ------------------------------------------------------------------

def test_save_study_plots_boundary(tmp_path, continuation):
    two = two_parameter_continuation(continuation)
    other = replace(make_boundary(), name="no continuation", slices=(0.2,))
    two_slices = replace(make_boundary(), slices=(0.2, 0.3))
    result = StudyResult("study", "classical", (continuation, two), (), (),
                         boundaries=(two_slices, other), linear_grid=make_grid())
    paths = save_study_plots(result, ("boundary",), tmp_path, "run", dpi=40)
    assert [p.name for p in paths] == sorted([
        "run_kk_boundary.png", "run_kk_slice_0_overhang.png", "run_kk_slice_1_overhang.png",
        "run_no_continuation_boundary.png", "run_no_continuation_slice_0_overhang.png"])
    assert sorted(tmp_path.iterdir()) == paths  # no temporary files left behind
    for path in paths:
        assert path.read_bytes()[:8] == PNG_MAGIC


def test_save_study_plots_boundary_grid_only_or_nothing(tmp_path, continuation):
    result = StudyResult("study", "classical", (continuation,), (), (), linear_grid=make_grid())
    paths = save_study_plots(result, ("boundary", "linear"), tmp_path, "run", dpi=40)
    assert [p.name for p in paths] == ["run_linear_grid.png"]
    assert paths[0].read_bytes()[:8] == PNG_MAGIC
    empty = StudyResult("study", "classical", (continuation,), (), ())
    assert save_study_plots(empty, ("boundary",), tmp_path / "none", "run") == []


def test_save_study_plots_boundary_ignores_grid_of_other_parameters(tmp_path, monkeypatch):
    seen = []

    def fake(boundary, grid, cases=(), ax=None, **view):
        seen.append((boundary, grid, tuple(cases)))
        return new_figure()

    monkeypatch.setattr(maps, "boundary_plot", fake)
    boundary = replace(make_boundary(), slices=())
    grid = replace(make_grid(), y_parameter="V")
    result = StudyResult("study", "classical", (), (), (), boundaries=(boundary,),
                         linear_grid=grid)
    paths = save_study_plots(result, ("boundary",), tmp_path, "run", dpi=40)
    assert [p.name for p in paths] == ["run_kk_boundary.png"]
    assert seen == [(boundary, None, ())]


def test_boundary_plot_torus_locus_carries_the_thesis_torus_mark():
    """A torus locus: dotted green, strung with the thesis key's torus mark (hollow circle)."""
    torus = np.array([[0.5, 0.0], [0.55, 0.25], [0.6, 0.5]])
    ax = boundary_plot(make_boundary(loci={"hopf_1": ("hopf", HOPF),
                                           "torus_1a": ("torus", torus)}), None).axes[0]
    line = polyline(ax, torus)
    assert line_style(line) == ("green", ":")
    assert line.get_marker() == "o" and line.get_markerfacecolor() == "none"
    assert legend_labels(ax) == ["Hopf locus (flutter)", "torus locus (TR)", "unsafe (overhang)"]


def test_the_overhang_is_shaded_from_the_subcritical_hopf_point_to_the_outermost_fold():
    """Hardening case 2 (the committed reference): the family ending on the subcritical Hopf
    point at K_theta = 0.0807 folds three times below it, where the origin is stable; the
    band runs to the fold farthest from it (0.0586), its edges the stored values (read here
    with h5py), its width written on top."""
    import h5py
    from matplotlib.patches import Rectangle

    from whirl_cli.output import store
    from whirl_cli.plots.diagrams import overhangs

    path = Path(__file__).resolve().parents[1] / "regression" / "references" / "hardening_case2.h5"
    with h5py.File(path) as handle:
        points = handle["continuations/k1/special_points"]
        kinds = [t.decode() for t in points["type_name"][()]]
        values = points["parameters"][:, 0]
        criticality = [c.decode() for c in points["criticality"][()]]
        branches = [b.decode() for b in points["branch"][()]]
    hopf = next(v for k, v, c in zip(kinds, values, criticality, strict=True)
                if k == "HB" and c == "subcritical")
    folds = [v for k, v, b in zip(kinds, values, branches, strict=True)
             if k == "LPC" and b == "periodic_1"]
    outermost = max(folds, key=lambda v: abs(v - hopf))
    continuation = store.read(path).continuations[0]
    assert overhangs(continuation) == [(outermost, hopf)]
    ax = bifurcation_diagram(continuation).axes[0]
    (band,) = [p for p in ax.patches if isinstance(p, Rectangle) and p.get_alpha() == 0.25]
    np.testing.assert_allclose([band.get_x(), band.get_x() + band.get_width()],
                               [outermost, hopf], rtol=1e-12)
    assert f"{hopf - outermost:.3g} N m/rad" in [t.get_text() for t in ax.texts]
    assert "unsafe (overhang)" in [
        t.get_text() for t in ax.get_legend().get_texts()]
