"""Phase planes at the cuts of a diagram (thesis figures 3.16, 3.24, 3.26), one legend per
sheet, line colours not reused, mathtext names: each checked from the figure's own artists."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.colors import to_hex
from matplotlib.text import Text

from whirl_cli.figures.draw import figure_legend, share_limits
from whirl_cli.plots.cuts import mark_cuts, phase_cuts, solutions_at
from whirl_cli.plots.diagrams import bifurcation_diagram
from whirl_cli.plots.key import new_figure, symbol
from whirl_cli.results import (
    Branch,
    BranchKind,
    ContinuationResult,
    Orbit,
    Origin,
    PointType,
    SpecialPoint,
)

STATES = ("theta", "psi", "theta_dot", "psi_dot")
UNITS = ("rad", "rad", "rad/s", "rad/s")


TEST = Origin("test")


def branch(name, kind, k1, theta, stable, orbits=(), period=None, origin=TEST) -> Branch:
    """A branch on K1 whose theta is given (rad) and psi is half of it."""
    k1 = np.asarray(k1, dtype=float)
    n = len(k1)
    theta = np.asarray(theta, dtype=float)
    states = np.column_stack([theta, 0.5 * theta, 0 * theta, 0 * theta])
    periodic = kind == BranchKind.PERIODIC
    return Branch(name=name, kind=kind, origin=origin, parameter_names=("K1",),
                  parameter_units=("N m/rad",), state_names=STATES, state_units=UNITS,
                  parameters=k1[:, None], state_max=states, state_min=-states if periodic
                  else states, l2_norm=np.abs(theta),
                  period=np.asarray(period, float) if period is not None
                  else np.full(n, 0.2 if periodic else np.nan),
                  stable=np.asarray(stable, dtype=bool), point_type=np.zeros(n, int),
                  label=np.zeros(n, int), eigenvalues=np.full((n, 4), np.nan, complex),
                  orbits=tuple(orbits))


def circle(label, index, k1, radius, centre=0.0, period=0.2) -> Orbit:
    t = np.linspace(0.0, 2 * np.pi, 41)
    states = np.column_stack([centre + radius * np.sin(t), radius * np.cos(t), 0 * t, 0 * t])
    return Orbit(label=label, point_type=0, index=index, parameters=np.array([k1]),
                 period=period, time=t, states=states)


def point(name, kind, k1) -> SpecialPoint:
    return SpecialPoint(branch=name, index=0, point_type=int(kind), parameter_names=("K1",),
                        parameters=np.array([k1]), state=np.zeros(4), period=np.nan,
                        stable=False)


@pytest.fixture
def cut_continuation() -> ContinuationResult:
    """The origin (stable above K1 = 0.1), two secondary equilibria below K1 = 0 (stable),
    a cycle family from K1 = 0.1 to 0.3 that folds back (two cycles stored at K1 = 0.2), and
    secondary cycles ending in a homoclinic at K1 = -0.1 (the longest stored near it)."""
    k1 = np.linspace(0.5, -0.3, 81)
    main = branch("main_down", BranchKind.EQUILIBRIUM, k1, 0 * k1, k1 > 0.1)
    low = np.linspace(0.0, -0.3, 31)
    up = branch("secondary_1a", BranchKind.EQUILIBRIUM, low, 0.1 + 0 * low, low < -0.05)
    down = branch("secondary_1b", BranchKind.EQUILIBRIUM, low, -0.1 + 0 * low, low < -0.05)
    fold = np.array([0.1, 0.2, 0.3, 0.2, 0.15])
    lco = branch("periodic_1", BranchKind.PERIODIC, fold, [0.01, 0.05, 0.1, 0.15, 0.2],
                 [0, 0, 1, 1, 1], orbits=(circle(7, 1, 0.2, 0.05), circle(8, 3, 0.2, 0.15)),
                 origin=Origin(point=PointType.HB, parameter="K1", value=0.1,
                               branch="main_down"))
    tail = np.array([-0.05, -0.09, -0.0999, -0.09999])
    secondary = branch("periodic_2", BranchKind.PERIODIC, tail, [0.12] * 4, [1] * 4,
                       period=[0.2, 0.5, 2.0, 9.0],
                       origin=Origin(point=PointType.HB, parameter="K1", value=-0.05,
                                     branch="secondary_1a"),
                       orbits=(circle(3, 1, -0.09, 0.03, 0.1, 0.5),
                               circle(4, 3, -0.09999, 0.08, 0.1, 9.0)))
    return ContinuationResult(
        name="k1", kind="one-parameter", branches=(main, up, down, lco, secondary),
        special_points=(point("main_down", PointType.HB, 0.1),
                        point("periodic_2", PointType.HOMOCLINIC, -0.1)))


def drawn_cuts(continuation, values):
    figure = new_figure(figsize=(12, 5))
    grid = figure.add_gridspec(1, 2)
    diagram = figure.add_subplot(grid[0, 0])
    bifurcation_diagram(continuation, ax=diagram)
    mark_cuts(diagram, values)
    planes = phase_cuts(continuation, values, grid[0, 1])
    return figure, diagram, planes


def cycles(ax) -> list:
    return [line for line in ax.lines if line.get_linestyle() not in ("None", "none", "")]


def crosses(ax) -> int:
    return sum(len(line.get_xdata()) for line in ax.lines if line.get_marker() == "x")


def test_every_solution_at_each_cut_is_drawn(cut_continuation):
    """At K1 = -0.2 the three equilibria and no cycle; at 0.2 the origin and both cycles the
    folded family stores there; at 0.4 the origin alone; at the homoclinic (-0.1) the
    secondary family's longest orbit."""
    values = [-0.2, 0.2, 0.4, -0.1]
    _, _, planes = drawn_cuts(cut_continuation, values)
    assert [len(cycles(ax)) for ax in planes] == [0, 2, 0, 1]
    assert [crosses(ax) for ax in planes] == [3, 1, 1, 3]
    (longest,) = cycles(planes[3])
    assert max(longest.get_ydata()) == pytest.approx(np.degrees(0.18), rel=1e-6)
    # psi horizontal, theta vertical, in degrees, equal aspect
    plane = planes[1]
    assert plane.get_xlabel() == "$\\psi$ [deg]" and plane.get_ylabel() == "$\\theta$ [deg]"
    assert plane.get_aspect() == 1.0
    assert "at the homoclinic" in planes[3].get_title()


def test_solutions_at_interpolate_the_equilibria(cut_continuation):
    found = solutions_at(cut_continuation, -0.2)
    assert sorted(round(float(s.states[0, 0]), 12) for s in found) == [-0.1, 0.0, 0.1]
    assert all(s.stable for s in found if s.family != "main_down")


def test_cuts_are_lines_on_the_diagram(cut_continuation):
    values = [-0.2, 0.2, 0.4]
    _, diagram, _ = drawn_cuts(cut_continuation, values)
    verticals = [line.get_xdata()[0] for line in diagram.lines
                 if line.get_label() == "_cut"]
    assert verticals == values
    assert [t.get_text() for t in diagram.texts if t.get_text().startswith("(")] == \
        ["(a)", "(b)", "(c)"]


def test_no_two_labelled_lines_share_colour_and_style(cut_continuation):
    figure, _, _ = drawn_cuts(cut_continuation, [-0.2, 0.2, -0.1])
    styles = [(to_hex(line.get_color()), line.get_linestyle()) for ax in figure.axes
              for line in ax.lines if not line.get_label().startswith("_")
              and line.get_linestyle() not in ("None", "none", "")]
    assert len(styles) == 3
    assert len(set(styles)) == len(styles)


def visible_styles(figure) -> set:
    """(colour, line style, marker) of every visible line of the figure's axes."""
    return {(to_hex(line.get_color()), line.get_linestyle(), line.get_marker())
            for ax in figure.axes for line in ax.lines if line.get_visible()}


def test_one_figure_legend_whose_entries_match_visible_artists(cut_continuation):
    figure, diagram, planes = drawn_cuts(cut_continuation, [-0.2, 0.2, -0.1])
    labels = [t.get_text() for ax in figure.axes if ax.get_legend()
              for t in ax.get_legend().get_texts()]
    figure_legend(figure)
    assert all(ax.get_legend() is None for ax in figure.axes)
    (legend,) = figure.legends
    texts = [t.get_text() for t in legend.get_texts()]
    assert sorted(texts) == sorted(set(labels))  # every entry once
    drawn = visible_styles(figure)
    for handle in legend.legend_handles:
        if hasattr(handle, "get_linestyle") and hasattr(handle, "get_marker"):
            assert (to_hex(handle.get_color()), handle.get_linestyle(),
                    handle.get_marker()) in drawn


def test_no_text_outside_the_canvas(cut_continuation):
    figure, _, _ = drawn_cuts(cut_continuation, [-0.2, 0.2, 0.4, -0.1])
    figure_legend(figure)
    figure.suptitle("Figure 3.16: a caption long enough to need the whole width of the sheet")
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    box = figure.bbox
    for text in figure.findobj(Text):
        if text.get_visible() and text.get_text():
            extent = text.get_window_extent(renderer)
            assert box.x0 - 1 <= extent.x0 and extent.x1 <= box.x1 + 1, text.get_text()
            assert box.y0 - 1 <= extent.y0 and extent.y1 <= box.y1 + 1, text.get_text()


def test_shared_limits_join_axes_of_one_quantity():
    figure = new_figure()
    left, right, other = figure.subplots(1, 3)
    left.plot([0, 1], [0, 1])
    right.plot([0, 5], [-2, 1])
    other.plot([0, 100], [0, 100])
    for ax in (left, right):
        ax.set_xlabel("t [s]")
        ax.set_ylabel("$\\theta$ [deg]")
    other.set_xlabel("V [m/s]")
    share_limits(figure.axes, "both")
    assert left.get_xlim() == right.get_xlim() and left.get_ylim() == right.get_ylim()
    assert other.get_xlim()[1] > 50  # another quantity keeps its own


@pytest.mark.parametrize("name, expected", [
    ("theta", "$\\theta$"), ("K_psi", "$K_{\\psi}$"), ("theta_dot", "$\\dot{\\theta}$"),
    ("Omega", "$\\Omega$"), ("zeta", "$\\zeta$"), ("beta_1", "$\\beta_{1}$"),
    ("K1", "K1"), ("V", "V"), ("hub y", "hub y"), ("max_real", "max_real"),
])
def test_greek_names_are_mathtext(name, expected):
    assert symbol(name) == expected


def test_index_lists_thumbnails_linked_and_what_made_the_figures():
    from whirl_cli.figures.index import Entry, index_html

    page = index_html([Entry("3.16", "cuts", "one orbit per cut", "fig3_16.png", ("s.yaml",),
                             "s.yaml")], "whirl figures",
                      {"whirl": "0.1.0", "commit": "abc123", "engine": "0.9.2"})
    assert '<a href="#fig3.16"><img src="fig3_16.png"' in page  # the contents' thumbnail
    assert '<a href="fig3_16.png"><img src="fig3_16.png"' in page  # full size
    assert "Differs from the thesis: one orbit per cut" in page
    for value in ("0.1.0", "abc123", "0.9.2"):
        assert f"<code>{value}</code>" in page
