"""The study plots checked from their own artists, after a draw: no text outside the canvas,
legends clear of the data, special-point markers on a drawn branch and above the others,
legend entries matching visible artists."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from matplotlib.colors import to_hex

from whirl_cli.plots.diagrams import phase_plane
from whirl_cli.plots.files import SMALL_ANGLE, phase_labels
from whirl_cli.results import BranchKind, Orbit, PointType

from .plot_data import make_branch


def _orbit(label: int, index: int, value: float, radius: float) -> Orbit:
    """An ellipse of ``radius`` rad in theta (half that in psi), 40 samples."""
    phase = np.linspace(0.0, 2 * np.pi, 40, endpoint=False)
    theta, psi = radius * np.cos(phase), 0.5 * radius * np.sin(phase)
    return Orbit(label=label, point_type=0, index=index, parameters=np.array([value, 6.7]),
                 period=0.2, time=phase / (2 * np.pi) * 0.2,
                 states=np.column_stack([theta, psi, 10 * psi, 10 * theta]))


def _family(radii) -> object:
    """A periodic family with one stored orbit per radius (rad), the parameter rising."""
    n = len(radii)
    branch = make_branch("periodic_1", BranchKind.PERIODIC, np.linspace(0.3, 0.5, n),
                         radii, np.ones(n))
    return replace(branch, orbits=tuple(_orbit(k + 1, k, 0.3 + 0.2 * k / max(n - 1, 1), r)
                                        for k, r in enumerate(radii)))


def _display_points(ax) -> np.ndarray:
    """Every vertex of ``ax``'s lines, in display coordinates."""
    points = [line.get_xydata() for line in ax.lines if len(line.get_xdata())]
    xy = np.concatenate(points)
    return ax.transData.transform(xy[np.isfinite(xy).all(axis=1)])


def _inside(points: np.ndarray, box) -> np.ndarray:
    return ((points[:, 0] > box.x0) & (points[:, 0] < box.x1)
            & (points[:, 1] > box.y0) & (points[:, 1] < box.y1))


def test_phase_plane_legend_lies_clear_of_every_orbit():
    figure = phase_plane(_family(np.linspace(0.02, 0.3, 12)))
    figure.canvas.draw()
    ax = figure.axes[0]
    box = ax.get_legend().get_window_extent()
    assert not _inside(_display_points(ax), box).any()
    canvas = figure.bbox
    assert canvas.x0 <= box.x0 and box.x1 <= canvas.x1


def test_phase_plane_gives_each_orbit_its_own_colour():
    ax = phase_plane(_family(np.linspace(0.02, 0.3, 12))).axes[0]
    colours = [to_hex(line.get_color()) for line in ax.lines]
    assert len(colours) == 12 and len(set(colours)) == 12


def test_study_phase_plane_leaves_out_orbits_beyond_the_small_angle_range():
    radii = [0.05, 0.2, 0.3, 0.6, 1.2]  # rad: 0.6 and 1.2 beyond 20 deg
    family = _family(radii)
    assert SMALL_ANGLE < 0.6
    assert phase_labels(family) == [1, 2, 3]
    asked = replace(family, orbits=tuple(
        replace(o, point_type=int(PointType.UZ)) if o.label == 5 else o
        for o in family.orbits))
    assert phase_labels(asked) == [1, 2, 3, 5]  # an orbit orbits_at asked for stays


def test_study_phase_plane_keeps_its_orbits_when_none_is_small():
    assert phase_labels(_family([0.6, 0.9, 1.2])) == [1, 2, 3]


def _texts_outside(figure) -> list[str]:
    """The visible non-empty texts of ``figure`` that reach beyond its canvas, after a draw."""
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    canvas = figure.bbox
    hidden = {id(tick.label1) for ax in figure.axes for axis in (ax.xaxis, ax.yaxis)
              for tick in axis.get_major_ticks() + axis.get_minor_ticks()
              if not _in_view(tick.get_loc(), axis.get_view_interval())}
    out = []
    for text in figure.findobj(lambda a: hasattr(a, "get_text") and hasattr(a, "get_wrap")):
        if not text.get_visible() or not text.get_text().strip() or id(text) in hidden:
            continue
        box = text.get_window_extent(renderer)
        if (box.x0 < canvas.x0 - 0.5 or box.x1 > canvas.x1 + 0.5
                or box.y0 < canvas.y0 - 0.5 or box.y1 > canvas.y1 + 0.5):
            out.append(text.get_text())
    return out


def _in_view(value, interval) -> bool:
    """Whether a tick at ``value`` is drawn (within the axis's view ``interval``)."""
    low, high = sorted(interval)
    return low - 1e-9 * abs(high - low) <= value <= high + 1e-9 * abs(high - low)


def test_freeplay_law_title_stays_on_the_canvas():
    from whirl_cli.models import get_model
    from whirl_cli.output.provenance import law_curve
    from whirl_cli.plots.laws import law_plot

    model = get_model("classical", ("freeplay", "polynomial"))
    values = {"K_theta": 0.4, "delta_theta": 0.017453292519943295,
              "epsilon_theta": 0.00017453292519943295, "K_in_theta": 0.0}
    figure = law_plot(law_curve(model, values, "theta"))
    assert _texts_outside(figure) == []


def test_a_study_figure_wraps_a_long_title_onto_the_canvas():
    from whirl_cli.plots.files import View, _viewed

    long = "freeplay-pitch-airspeed: " + ", ".join(f"$K_{{{k}}}$ = 0.{k} N m/rad"
                                                   for k in range(1, 9))
    figure = _viewed(phase_plane(_family([0.05, 0.1]), title=long), View())
    assert _texts_outside(figure) == []


def _homoclinic_ending(saddle_theta: float):
    """A periodic family ending at a homoclinic point (stored with the saddle's theta, off the
    family's max there) beside a fold of cycles and a torus point at the same place."""
    from whirl_cli.results import ContinuationResult, PointType, SpecialPoint

    family = make_branch("periodic_1", BranchKind.PERIODIC, [0.3, 0.35, 0.4, 0.42, 0.43],
                         [0.1, 0.15, 0.2, 0.25, 0.3], [1, 1, 1, 1, 1])

    def point(kind, row, theta):
        return SpecialPoint(branch="periodic_1", index=row, point_type=int(kind),
                            parameter_names=("K1", "V"),
                            parameters=family.parameters[row].copy(),
                            state=np.array([theta, 0.0, 0.0, 0.0]), period=0.2, stable=True)

    points = (point(PointType.HOMOCLINIC, 4, saddle_theta), point(PointType.LPC, 4, 0.3),
              point(PointType.TR, 2, 0.2), point(PointType.LPC, 2, 0.2))
    return ContinuationResult("k1", "one-parameter", (family,), points)


def test_a_homoclinic_marker_lies_on_the_family_it_ends():
    from whirl_cli.plots.diagrams import bifurcation_diagram

    ax = bifurcation_diagram(_homoclinic_ending(saddle_theta=0.12)).axes[0]
    (marker,) = [line for line in ax.lines if line.get_marker() == "^"]
    curves = np.concatenate([line.get_xydata() for line in ax.lines
                             if line.get_marker() in ("None", "", None)])
    for xy in marker.get_xydata():
        assert np.isclose(curves, xy, rtol=1e-9, atol=1e-12).all(axis=1).any()


def test_torus_and_global_markers_lie_above_a_fold_at_the_same_place():
    from whirl_cli.plots.diagrams import bifurcation_diagram

    ax = bifurcation_diagram(_homoclinic_ending(saddle_theta=0.12)).axes[0]
    (homoclinic,) = [line for line in ax.lines if line.get_marker() == "^"]
    (torus,) = [line for line in ax.lines if line.get_marker() == "o"
                and line.get_markerfacecolor() == "none"]
    folds = [line for line in ax.lines if line.get_marker() == "o" and line is not torus]
    assert folds  # the fold under the homoclinic marker is set beside it, in a line of its own
    for fold in folds:
        assert torus.get_zorder() > fold.get_zorder()
        assert homoclinic.get_zorder() > fold.get_zorder()
        assert torus.get_markersize() > fold.get_markersize()  # a ring around the fold


def _unseen_entries(ax) -> list[str]:
    """The entries of ``ax``'s legend whose artist shows nothing inside the axes after a draw:
    a line or marker with no vertex in the axes' box, an error bar narrower than a marker."""
    from matplotlib.container import ErrorbarContainer
    from matplotlib.lines import Line2D

    ax.figure.canvas.draw()
    box = ax.get_window_extent()
    marker_px = 8.0 * ax.figure.dpi / 72.0
    legend = ax.get_legend()
    unseen = []
    for handle, text in zip(legend.legend_handles, legend.get_texts(), strict=True):
        artist = next((a for a in [*ax.lines, *ax.containers]
                       if a is handle or a.get_label() in (text.get_text(),
                                                             "_" + text.get_text())), handle)
        if isinstance(artist, ErrorbarContainer):
            (bars,) = artist.lines[2]
            xy = ax.transData.transform(np.concatenate(bars.get_segments()))
            if np.ptp(xy[:, 0]) < marker_px:
                unseen.append(text.get_text())
        elif isinstance(artist, Line2D) and artist.axes is ax:
            xy = artist.get_xydata()
            xy = ax.transData.transform(xy[np.isfinite(xy).all(axis=1)])
            if not _inside(xy, box.expanded(1.001, 1.001)).any():
                unseen.append(text.get_text())
    return unseen


def _bracketed_heteroclinic(width: float):
    """A periodic family whose period blows up at a heteroclinic point bracketed ``width``
    wide."""
    from whirl_cli.results import ContinuationResult, LocateStatus, PointType, SpecialPoint

    family = replace(make_branch("periodic_1", BranchKind.PERIODIC, [0.3, 0.35, 0.4, 0.42,
                                                                     0.43],
                                 [0.1, 0.15, 0.2, 0.25, 0.3], [1, 1, 1, 1, 1]),
                     period=np.array([0.2, 0.3, 0.5, 1.0, 3.0]))
    point = SpecialPoint(branch="periodic_1", index=4, point_type=int(PointType.HETEROCLINIC),
                         parameter_names=("K1", "V"), parameters=np.array([0.43, 6.7]),
                         state=np.zeros(4), period=np.nan, stable=False,
                         status=LocateStatus.BRACKETED,
                         bracket=np.array([0.43, 0.43 + width]), residual=0.01)
    return ContinuationResult("k1", "one-parameter", (family,), (point,))


def test_a_period_plot_lists_no_bracket_too_narrow_to_be_seen():
    from whirl_cli.plots.diagrams import period_plot

    ax = period_plot(_bracketed_heteroclinic(3e-8)).axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "heteroclinic" in labels and not any("bracket" in label for label in labels)
    assert _unseen_entries(ax) == []


def test_every_legend_entry_of_the_study_diagrams_shows_in_its_axes():
    from whirl_cli.plots.diagrams import bifurcation_diagram, period_plot

    wide = period_plot(_bracketed_heteroclinic(0.02)).axes[0]
    assert any("bracket" in t.get_text() for t in wide.get_legend().get_texts())
    for ax in (wide, bifurcation_diagram(_homoclinic_ending(0.12)).axes[0],
               phase_plane(_family([0.05, 0.1, 0.2])).axes[0]):
        assert _unseen_entries(ax) == []


def test_sheet_captions_name_the_parameters_as_the_axes_do():
    """whirl's axes read K_theta; a caption says K_theta too (the thesis's K1 only as such)."""
    import re
    from pathlib import Path

    from whirl_cli.figures.sheet import load_sheet

    sheets = sorted((Path(__file__).resolve().parents[2] / "sheets" / "thesis_ch3").glob(
        "fig3_*.yaml"))
    assert len(sheets) == 28
    bare = {path.name: load_sheet(path).caption for path in sheets
            if re.search(r"(?<!thesis's )\bK1\b", load_sheet(path).caption)}
    assert bare == {}


def test_four_cuts_under_a_diagram_at_journal_width_keep_their_size():
    """At 7.2 in (a double journal column) four phase cuts under a diagram go in one row, each
    at least an inch on a side, instead of a 2 x 2 grid that collapses."""
    from whirl_cli.plots.cuts import phase_cuts
    from whirl_cli.plots.key import new_figure

    from .plot_data import hopf_continuation

    figure = new_figure(figsize=(7.2, 6.6))
    grid = figure.add_gridspec(2, 1)
    figure.add_subplot(grid[0]).plot([0, 1], [0, 1])
    axes = phase_cuts(hopf_continuation(), [0.1, 0.2, 0.3, 0.45], grid[1])
    figure.canvas.draw()
    boxes = [ax.get_window_extent() for ax in axes]
    inch = figure.dpi
    assert len({round(box.y0) for box in boxes}) == 1  # one row
    assert all(box.width >= 0.8 * inch and box.height >= 0.8 * inch for box in boxes)


def test_the_small_panel_sheets_are_set_for_a_double_column():
    from pathlib import Path

    from whirl_cli.figures.sheet import COLUMNS, load_sheet

    folder = Path(__file__).resolve().parents[2] / "sheets" / "thesis_ch3"
    for number in ("16", "21", "24", "26"):
        sheet = load_sheet(folder / f"fig3_{number}.yaml")
        assert sheet.column == "double" and sheet.figure_size[0] == COLUMNS["double"]
        assert sheet.shape[1] == 1  # the diagram above its small panels, not beside them


def test_a_figure_legend_lists_a_marker_drawn_alike_on_two_panels_once():
    """Panel (a) says "heteroclinic", panel (b) "heteroclinic (whirl: ...)" for the same
    hollow triangle: the sheet's legend lists it once, with the fuller label; a different
    marker keeps its own entry."""
    from whirl_cli.figures.draw import figure_legend
    from whirl_cli.plots.key import new_figure

    figure = new_figure()
    left, right = figure.subplots(1, 2)
    style = {"marker": "^", "markerfacecolor": "none", "markeredgecolor": "black",
             "linestyle": "none"}
    left.plot([0.1], [1.0], **style, label="heteroclinic")
    left.plot([0.2], [1.0], marker="^", color="black", linestyle="none", label="homoclinic")
    right.plot([0.1], [1.0], **style, label="heteroclinic (whirl: K = 0.0777)")
    for ax in (left, right):
        ax.legend()
    figure_legend(figure)
    (legend,) = figure.legends
    assert [t.get_text() for t in legend.get_texts()] == [
        "heteroclinic (whirl: K = 0.0777)", "homoclinic"]


def _crowded(axes_count: int):
    """A figure of ``axes_count`` axes, each filled by a dense grid of points and a legend."""
    from whirl_cli.plots.key import new_figure

    figure = new_figure()
    grid = np.linspace(0.0, 1.0, 30)
    xs, ys = np.meshgrid(grid, grid)
    for ax in figure.subplots(1, axes_count, squeeze=False).ravel():
        ax.plot(xs.ravel(), ys.ravel(), ".", label="every point")
        ax.plot(grid, grid, "-", label="a line")
        ax.legend()
    return figure


def test_a_study_figure_moves_a_legend_off_its_data_beside_its_axes():
    from whirl_cli.plots.files import View, _viewed

    figure = _viewed(_crowded(1), View())
    figure.canvas.draw()
    ax = figure.axes[0]
    box = ax.get_legend().get_window_extent()
    assert not _inside(_display_points(ax), box).any()
    assert box.x1 <= figure.bbox.x1 and _texts_outside(figure) == []


def test_a_study_figure_of_several_axes_gathers_covering_legends_below_them():
    from whirl_cli.plots.files import View, _viewed

    figure = _viewed(_crowded(2), View())
    figure.canvas.draw()
    assert all(ax.get_legend() is None for ax in figure.axes)
    (legend,) = figure.legends
    box = legend.get_window_extent()
    assert all(box.y1 <= ax.get_window_extent().y0 for ax in figure.axes)
    assert _texts_outside(figure) == []


def test_the_letters_of_close_cuts_do_not_overlap_on_a_short_diagram():
    """Three cuts within 2 % of the axis (3.26: 0.075, 0.0777, 0.09 of 0.8) on a 2 in tall
    diagram: their letters' boxes are disjoint."""
    from whirl_cli.plots.cuts import mark_cuts
    from whirl_cli.plots.key import new_figure

    ax = new_figure(figsize=(7.2, 2.0)).add_subplot()
    ax.plot([-0.3, 0.5], [-10.0, 10.0])
    mark_cuts(ax, [0.075, 0.0777, 0.09])
    ax.figure.canvas.draw()
    boxes = [text.get_window_extent() for text in ax.texts]
    assert len(boxes) == 3
    for a in range(3):
        for b in range(a + 1, 3):
            assert not boxes[a].overlaps(boxes[b])


def _figure_eight_cut():
    """At K1 = 0.1: a main cycle (a figure eight through the origin) stored first, and the two
    secondary cycles that are its upper and lower loops, as at a homoclinic."""
    from whirl_cli.results import ContinuationResult

    s = np.linspace(0.0, 2 * np.pi, 60, endpoint=False)
    upper = np.column_stack([0.1 * (1 - np.cos(s)), 0.05 * np.sin(s)])  # theta, psi [rad]
    loops = {"periodic_1": np.vstack([upper, -upper]), "periodic_2": upper,
             "periodic_3": -upper}
    branches = []
    for name, loop in loops.items():
        family = make_branch(name, BranchKind.PERIODIC, [0.05, 0.1, 0.15], [0.2] * 3,
                             [0, 0, 0])
        orbit = Orbit(label=1, point_type=0, index=1, parameters=np.array([0.1, 6.7]),
                      period=1.0, time=np.linspace(0.0, 1.0, len(loop)),
                      states=np.column_stack([loop, 0 * loop]))
        branches.append(replace(family, orbits=(orbit,)))
    return ContinuationResult("k1", "one-parameter", tuple(branches), ())


def test_the_main_cycle_at_a_cut_lies_above_the_secondary_cycles_it_runs_along():
    from whirl_cli.plots.cuts import phase_cut
    from whirl_cli.plots.key import new_figure

    ax = new_figure().add_subplot()
    assert phase_cut(_figure_eight_cut(), 0.1, ax) == 3
    lines = {line.get_label().split()[2]: line for line in ax.lines
             if "limit cycle" in line.get_label()}
    main = lines.pop("periodic_1")
    for secondary in lines.values():
        assert main.get_zorder() > secondary.get_zorder()
        # drawn wider: the secondary shows on both sides of the main cycle above it
        assert secondary.get_linewidth() > 2 * main.get_linewidth()


def _snaking_family(folds: int):
    """A periodic family whose period grows towards K1 = 0.08 while it snakes there: ``folds``
    folds of cycles within 1e-5 of each other, then a homoclinic end."""
    from whirl_cli.results import ContinuationResult, SpecialPoint

    rows = 20 + 4 * folds
    k1 = np.concatenate([np.linspace(0.4, 0.08, 20),
                         0.08 + 1e-5 * np.tile([0.0, 0.5, 1.0, 0.5], folds)])
    period = np.concatenate([np.linspace(0.25, 0.5, 20), np.linspace(0.5, 2.0, 4 * folds)])
    family = replace(make_branch("periodic_1", BranchKind.PERIODIC, k1, 0.1 + 0 * k1,
                                 np.ones(rows)), period=period)

    def point(kind, row):
        return SpecialPoint(branch="periodic_1", index=row, point_type=int(kind),
                            parameter_names=("K1", "V"), parameters=family.parameters[row],
                            state=np.zeros(4), period=period[row], stable=True)

    turns = [point(PointType.LPC, 20 + 4 * k + 2) for k in range(folds)]
    return ContinuationResult("k1", "one-parameter", (family,),
                              (*turns, point(PointType.HOMOCLINIC, rows - 1)))


def _fold_marks(ax) -> np.ndarray:
    """The centres of the filled circles drawn on ``ax`` (fold markers), in data units."""
    lines = [line for line in ax.lines if line.get_marker() == "o"
             and line.get_markerfacecolor() not in ("none", "None")]
    return np.concatenate([line.get_xydata() for line in lines] or [np.zeros((0, 2))])


def test_the_folds_of_a_snaking_family_are_drawn_as_one_cluster():
    from whirl_cli.plots.blowup import blowup_plot
    from whirl_cli.plots.diagrams import period_plot

    continuation = _snaking_family(6)
    for ax in (period_plot(continuation).axes[0], blowup_plot(continuation).axes[0]):
        assert len(_fold_marks(ax)) == 1
        assert [t.get_text() for t in ax.texts if "\u00d7" in t.get_text()] == ["\u00d76"]
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        assert any("snaking" in label for label in labels)
        assert not any(label.startswith("fold (") for label in labels)


def test_two_folds_of_a_family_stay_two_markers():
    from whirl_cli.plots.diagrams import period_plot

    assert len(_fold_marks(period_plot(_snaking_family(2)).axes[0])) == 2


def _hidden_markers(ax) -> list[tuple[str, str]]:
    """Pairs (marker below, marker above) of ``ax``'s special-point markers, after a draw,
    where the centre of the lower lies inside the upper's marker (half its size around its
    centre) and the upper is no larger hollow ring around it."""
    ax.figure.canvas.draw()
    lines = [line for line in ax.lines if line.get_linestyle() in ("None", "none", "")
             and line.get_marker() not in ("None", "", None, "_")]
    per_point = ax.figure.dpi / 72.0
    hidden = []
    for k, low in enumerate(lines):
        for m, high in enumerate(lines):
            above = (high.get_zorder(), m) > (low.get_zorder(), k)
            alike = (low.get_marker(), low.get_markerfacecolor()) == (
                high.get_marker(), high.get_markerfacecolor())
            ring = high.get_markerfacecolor() == "none" and \
                high.get_markersize() > low.get_markersize()
            if not above or alike or ring:
                continue
            a = low.get_transform().transform(low.get_xydata())
            b = high.get_transform().transform(high.get_xydata())
            gaps = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)
            if (gaps < 0.5 * high.get_markersize() * per_point).any():
                hidden.append((str(low.get_marker()), str(high.get_marker())))
    return hidden


def _branch_point_under_homoclinic():
    """A family ending at a homoclinic point, with a branch point of cycles one row before,
    at the same K1 and a period 2 % shorter, and a fold at the homoclinic's own row."""
    from whirl_cli.results import ContinuationResult, SpecialPoint

    k1 = np.array([0.3, 0.2, 0.12, 0.1021, 0.1021, 0.1021])
    period = np.array([0.3, 0.5, 1.4, 1.8, 5.52, 5.63])
    family = replace(make_branch("periodic_1", BranchKind.PERIODIC, k1, 0.1 + 0 * k1,
                                 np.zeros(6)), period=period)

    def point(kind, row):
        return SpecialPoint(branch="periodic_1", index=row, point_type=int(kind),
                            parameter_names=("K1", "V"), parameters=family.parameters[row],
                            state=np.zeros(4), period=period[row], stable=False)

    return ContinuationResult("k1", "one-parameter", (family,), (
        point(PointType.BPC, 4), point(PointType.HOMOCLINIC, 5), point(PointType.LPC, 5)))


def test_markers_at_one_place_are_set_apart_so_both_show():
    from whirl_cli.plots.diagrams import bifurcation_diagram, period_plot

    period = period_plot(_branch_point_under_homoclinic()).axes[0]
    assert _hidden_markers(period) == []
    assert {"*", "^", "o"} <= {str(line.get_marker()) for line in period.lines}
    diagram = bifurcation_diagram(_homoclinic_ending(saddle_theta=0.12)).axes[0]
    assert _hidden_markers(diagram) == []


def test_markers_set_apart_keep_every_point_and_its_place_in_data():
    from whirl_cli.plots.diagrams import period_plot

    ax = period_plot(_branch_point_under_homoclinic()).axes[0]
    stars = np.concatenate([line.get_xydata() for line in ax.lines
                            if line.get_marker() == "*"])
    np.testing.assert_allclose(stars, [[0.1021, 5.52]])


def test_a_blowup_panel_clusters_folds_by_the_axis_it_shows():
    """Three folds 0.0017 apart on the approach: under 1 % of the family's span, but apart on
    the zoomed axis of the blowup panel (3 % of it), so drawn one by one there."""
    from whirl_cli.plots.blowup import blowup_plot

    from .plot_data import blowup_continuation

    continuation = blowup_continuation()
    family = continuation.branches[0]
    folds = tuple(replace(continuation.special_points[1], index=row,
                          parameters=family.parameters[row].copy(), period=family.period[row])
                  for row in (58, 59, 60))
    assert np.ptp([f.parameters[0] for f in folds]) < 0.01 * np.ptp(family.parameters[:, 0])
    ax = blowup_plot(replace(continuation, special_points=(continuation.special_points[0],
                                                           *folds))).axes[0]
    assert len(_fold_marks(ax)) == 3
    assert not [t for t in ax.texts if "\u00d7" in t.get_text()]


def test_every_cluster_of_a_plot_is_set_apart_from_a_marker_over_it():
    """Two snaking families, each with a period-doubling point at its first fold: both
    clusters' fold markers are set beside the diamonds, not only the last cluster drawn."""
    from whirl_cli.plots.diagrams import period_plot

    one = _snaking_family(4)
    two = _snaking_family(4)
    moved = replace(two.branches[0], name="periodic_2",
                    parameters=two.branches[0].parameters + np.array([0.2, 0.0]))
    points = []
    for family, source in (("periodic_1", one), ("periodic_2", two)):
        branch = one.branches[0] if family == "periodic_1" else moved
        for point in source.special_points:
            points.append(replace(point, branch=family,
                                  parameters=branch.parameters[point.index].copy()))
        first_fold = points[-len(source.special_points)]
        points.append(replace(first_fold, point_type=int(PointType.PD)))
    from whirl_cli.results import ContinuationResult

    ax = period_plot(ContinuationResult("k1", "one-parameter", (one.branches[0], moved),
                                        tuple(points))).axes[0]
    assert len(_fold_marks(ax)) == 2
    assert _hidden_markers(ax) == []


def _torus_markers(ax) -> int:
    """Torus (TR) markers drawn on ``ax``: hollow rings."""
    return sum(len(line.get_xdata()) for line in ax.lines
               if line.get_marker() == "o" and line.get_markerfacecolor() == "none")


def test_a_point_whirl_rejected_gets_no_marker_in_a_study_plot_or_a_sheet_panel():
    """A TR that whirl's own check says is no torus bifurcation is listed (summary, HDF5) but
    never drawn as one: a study's bifurcation plot and a sheet's panel draw only the located
    TR beside it."""
    import matplotlib.pyplot as plt

    from whirl_cli.plots.files import study_figures
    from whirl_cli.plots.panels import draw
    from whirl_cli.results import LocateStatus

    from .plot_data import hopf_continuation, make_point, result_with

    base = hopf_continuation()
    located = make_point("periodic_1", PointType.TR, 0.35, 0.1)
    rejected = replace(make_point("periodic_1", PointType.TR, 0.38, 0.3),
                       status=LocateStatus.REJECTED)
    result = result_with(replace(base, special_points=(*base.special_points, located,
                                                       rejected)), 0.0)
    ((_, figure),) = list(study_figures(result, ("bifurcation",)))
    assert [_torus_markers(ax) for ax in figure.axes if ax.lines] == [1]
    plt.close(figure)
    figure, ax = plt.subplots()
    draw(result, "bifurcation", ax)
    assert _torus_markers(ax) == 1
    plt.close(figure)


def _veering_sweep():
    """Two oscillatory modes along V in 0-20 m/s: one stays a damped gimbal FW mode, the other
    starts as a nacelle FW mode, its energy passing to the gimbal from 14 m/s and its whirl
    turning BW from 15.5 m/s; its damping ratio crosses zero at 16 m/s (flutter)."""
    from whirl_cli.results import LinearSweep

    values = np.linspace(0.0, 20.0, 81)
    zeta = np.column_stack([0.05 + 0 * values, 0.1 - 0.1 * values / 16.0])
    freq = np.column_stack([80.0 + 0 * values, 50.0 - 2.0 * values])
    roots = freq * (-zeta + 1j * np.sqrt(1 - zeta ** 2))
    eigenvalues = np.column_stack([roots[:, 1], np.conj(roots[:, 1]),
                                   roots[:, 0], np.conj(roots[:, 0])])
    group = np.where(values < 14.0, "nacelle", "gimbal")
    whirl = np.where(values < 15.5, "FW", "BW")
    groups = np.column_stack([group, group, ["gimbal"] * 81, ["gimbal"] * 81])
    whirls = np.column_stack([whirl, whirl, ["FW"] * 81, ["FW"] * 81])
    return LinearSweep("V", "m/s", values, eigenvalues, -eigenvalues.real / np.abs(eigenvalues),
                       np.abs(eigenvalues.imag), whirls.astype(object), groups.astype(object))


def test_a_linear_sweep_legend_names_the_modes_as_stored_along_them_and_at_the_onset():
    """The mode that flutters was a nacelle mode for most of the sweep but is stored as the
    gimbal BW mode where it goes unstable: the legend names every stored label along its
    line (not the majority alone) and the label stored at the onset."""
    from whirl_cli.plots.linear import linear_sweep_plot

    sweep = _veering_sweep()
    ax_freq, ax_damp = linear_sweep_plot(sweep).axes
    texts = [t.get_text() for t in ax_freq.get_legend().get_texts()]
    (fluttering,) = [line.get_label() for line in ax_freq.lines
                     if line.get_label() in texts and line.get_linewidth() > 1.5]
    for label in ("nacelle", "gimbal", "FW", "BW"):
        assert label in fluttering
    (onset,) = [text for text in texts if text.startswith("damping ratio 0")]
    assert "V = 16 m/s" in onset and onset.endswith("gimbal BW)")
    assert "gimbal FW" in texts  # a mode stored alike all along keeps its one label


def _cluster_bars(ax) -> list[tuple[np.ndarray, float]]:
    """The span bars of fold clusters on ``ax`` as (ends in display coordinates, line width
    [points]): an error bar's vertical segment, or a capped line of two vertices at one x."""
    from matplotlib.container import ErrorbarContainer

    bars = []
    for container in ax.containers:
        if isinstance(container, ErrorbarContainer):
            for segments in container.lines[2]:
                for segment in segments.get_segments():
                    bars.append((ax.transData.transform(segment),
                                 float(segments.get_linewidth()[0])))
    for line in ax.lines:
        xy = line.get_xydata()
        if (len(xy) == 2 and np.ptp(xy[:, 0]) == 0.0 and line.get_marker() == "_"
                and line.get_linestyle() not in ("None", "none", "")):
            bars.append((line.get_transform().transform(xy), line.get_linewidth()))
    return bars


def test_a_cluster_bar_leaves_the_family_curve_beside_it_in_view():
    """A snaking family runs up and down the span of its folds: the cluster's bar is drawn
    beside the curve, clear of it by the half widths of both lines, not over it."""
    from whirl_cli.plots.blowup import blowup_plot
    from whirl_cli.plots.diagrams import period_plot

    continuation = _snaking_family(6)
    for ax in (period_plot(continuation).axes[0], blowup_plot(continuation).axes[0]):
        ax.figure.canvas.draw()
        ((ends, width),) = _cluster_bars(ax)
        curves = [line for line in ax.lines if line.get_marker() in ("None", "", None)]
        per_point = ax.figure.dpi / 72.0
        for curve in curves:
            xy = curve.get_transform().transform(curve.get_xydata())
            beside = xy[(xy[:, 1] >= ends[:, 1].min()) & (xy[:, 1] <= ends[:, 1].max())]
            clear = 0.5 * (curve.get_linewidth() + width) * per_point
            assert (np.abs(beside[:, 0] - ends[0, 0]) > clear).all()


def _overhang_under_a_marker():
    """A subcritical Hopf point at K1 = 0.3 whose family folds at 0.38 (the overhang
    0.3-0.38), and a period-doubling point at the top of the data in the band's middle."""
    from whirl_cli.results import ContinuationResult, Criticality

    from .plot_data import make_point

    equilibrium = make_branch("main_down", BranchKind.EQUILIBRIUM,
                              [0.5, 0.4, 0.3, 0.2, 0.1], [0.0] * 5, [1, 1, 0, 0, 0])
    family = make_branch("periodic_1", BranchKind.PERIODIC, [0.3, 0.33, 0.36, 0.38, 0.34],
                         [0.0, 0.1, 0.2, 0.25, 0.3], [0, 0, 0, 1, 1])
    hopf = replace(make_point("main_down", PointType.HB, 0.3, 0.0), index=2,
                   criticality=Criticality.SUBCRITICAL)
    fold = replace(make_point("periodic_1", PointType.LPC, 0.38, 0.25), index=3)
    doubling = replace(make_point("periodic_1", PointType.PD, 0.34, 0.3), index=4)
    return ContinuationResult("k1", "one-parameter", (equilibrium, family),
                              (hopf, fold, doubling))


def _marker_boxes(ax) -> list:
    """Each marker of ``ax``'s lines as a box of its size around its centre (display)."""
    from matplotlib.transforms import Bbox

    per_point = ax.figure.dpi / 72.0
    boxes = []
    for line in ax.lines:
        if line.get_marker() in ("None", "", None, " ") or not line.get_visible():
            continue
        half = 0.5 * line.get_markersize() * per_point
        for x, y in line.get_transform().transform(line.get_xydata()):
            boxes.append(Bbox([[x - half, y - half], [x + half, y + half]]))
    return boxes


def test_an_overhang_width_label_overlaps_no_marker():
    from whirl_cli.plots.diagrams import bifurcation_diagram, overhangs

    continuation = _overhang_under_a_marker()
    assert overhangs(continuation) == [(0.3, 0.38)]
    ax = bifurcation_diagram(continuation).axes[0]
    ax.figure.canvas.draw()
    renderer = ax.figure.canvas.get_renderer()
    (label,) = [t for t in ax.texts if t.get_text() == "0.08 N m/rad"]
    box = label.get_window_extent(renderer)
    assert ax.get_window_extent().contains(box.x0, box.y0)
    assert ax.get_window_extent().contains(box.x1, box.y1)
    assert not [m for m in _marker_boxes(ax) if m.overlaps(box)]


def test_crowd_is_the_largest_group_of_overlapping_markers():
    from whirl_cli.plots.markers import CROWD, crowd

    chain = np.column_stack([np.arange(CROWD) * 7.0, np.zeros(CROWD)])  # each touches the next
    apart = np.array([[200.0, 0.0], [300.0, 0.0], [300.0, 30.0]])
    centres = np.concatenate([apart, chain])
    assert crowd(centres, np.full(len(centres), 4.0)).tolist() == list(range(3, 3 + CROWD))
    assert crowd(centres[:-1], np.full(len(centres) - 1, 4.0)).tolist() == []  # one too few
    assert crowd(centres, np.full(len(centres), 3.0)).tolist() == []  # 7 apart, 6 across


def _crowded_diagram():
    """A Hopf point feeding a family, and six special points of six kinds within 0.004 of
    K1 = 0.15 and 0.3 deg of theta on it: together under one marker's size at full scale."""
    from whirl_cli.results import ContinuationResult

    from .plot_data import hopf_continuation, make_point

    base = hopf_continuation()
    kinds = (PointType.LPC, PointType.BPC, PointType.PD, PointType.TR, PointType.HOMOCLINIC,
             PointType.LP)
    crowd = tuple(make_point("periodic_1", kind, 0.33 + 0.0008 * k, 0.2 + 0.001 * k)
                  for k, kind in enumerate(kinds))
    return ContinuationResult(base.name, base.kind, base.branches,
                              (*base.special_points, *crowd))


def test_a_crowded_bifurcation_diagram_gets_a_zoom_panel_that_sets_its_markers_apart():
    """The study's bifurcation figure of a diagram whose markers crowd has a second panel
    whose limits hold the crowd, where no marker hides another; an uncrowded one stays one
    panel."""
    from whirl_cli.plots.files import study_figures

    from .plot_data import hopf_continuation, result_with

    ((_, figure),) = list(study_figures(result_with(_crowded_diagram(), 0.0),
                                        ("bifurcation",)))
    diagram, zoom = [ax for ax in figure.axes if ax.lines]
    figure.canvas.draw()
    (x0, x1), (y0, y1) = zoom.get_xlim(), zoom.get_ylim()
    assert x0 < 0.33 and 0.334 < x1 and y0 < np.degrees(0.2) and np.degrees(0.205) < y1
    assert x1 - x0 < 0.5 * np.ptp(diagram.get_xlim())
    assert _hidden_markers(zoom) == []
    per_point = figure.dpi / 72.0
    centres = np.concatenate([line.get_transform().transform(line.get_xydata())
                              for line in zoom.lines if line.get_linestyle() == "None"])
    inside = centres[_inside(centres, zoom.get_window_extent())]
    gaps = np.linalg.norm(inside[:, None] - inside[None, :], axis=2)
    assert (gaps[np.triu_indices(len(inside), 1)] >= 8.0 * per_point).all()
    ((_, single),) = list(study_figures(result_with(hopf_continuation(), 0.0),
                                        ("bifurcation",)))
    assert len([ax for ax in single.axes if ax.lines]) == 1


def test_an_overhang_width_label_takes_one_place_in_every_format():
    """The label's place is chosen from its glyphs' outlines, not a renderer's metrics: the
    PNG at two resolutions, the PDF and the SVG put it at the same place."""
    import io

    from whirl_cli.plots.diagrams import bifurcation_diagram

    figure = bifurcation_diagram(_overhang_under_a_marker())
    (label,) = [t for t in figure.axes[0].texts if t.get_text() == "0.08 N m/rad"]
    places = []
    for fmt, dpi in (("png", 100), ("png", 150), ("pdf", 72), ("svg", 72)):
        figure.savefig(io.BytesIO(), format=fmt, dpi=dpi)
        places.append((label.xy, tuple(label.xyann), label.get_ha(), label.get_va()))
    assert places[0] != (((0.3 + 0.38) / 2, 1.0), (0.0, -3.0), "center", "top")
    assert all(place == places[0] for place in places)
