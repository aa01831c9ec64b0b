"""Sheets (whirl_cli.figures): reading and checking sheet files, drawing any kind onto a given
Axes, overlays labelled by what differs, a sheet's layout, the index page."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from matplotlib.colors import to_hex

from tests.unit.plot_data import STATES, STUDY, branch_lines, make_sweep, result_with
from whirl_cli.errors import StudyError, WhirlError
from whirl_cli.figures.draw import draw_sheet
from whirl_cli.figures.index import Entry, index_html
from whirl_cli.figures.sheet import load_sheet
from whirl_cli.plots.key import new_figure
from whirl_cli.plots.panels import PANEL_KINDS, PanelChoice, differing_labels, draw, draw_overlay


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text)
    return path


# -- sheet files ---------------------------------------------------------------------------------

def test_sheet_reads_and_resolves_study_paths(tmp_path):
    (tmp_path / "studies").mkdir()
    write(tmp_path / "studies", "a.yaml", STUDY)
    (tmp_path / "sheets").mkdir()
    path = write(tmp_path / "sheets", "f.yaml",
                 'figure: "3.14"\ncaption: c\nlayout: [1, 2]\npanels:\n'
                 "  - {kind: bifurcation, study: ../studies/a.yaml}\n"
                 "  - kind: bifurcation\n    overlay:\n      - {study: ../studies/a.yaml}\n")
    sheet = load_sheet(path)
    assert sheet.stem == "fig3_14"
    assert sheet.shape == (1, 2)
    assert sheet.studies() == [tmp_path / "studies" / "a.yaml"]


@pytest.mark.parametrize("body, expected", [
    ("panels:\n  - {kind: bifurcation, study: nowhere.yaml}\n",
     "f.yaml:4: panels[0].study: no study file"),
    ("panels:\n  - {kind: bifurcation, study: a.yaml, colour: red}\n",
     "f.yaml:4: panels[0].colour: unknown key"),
    ("panels:\n  - {kind: bifurcation}\n",
     "f.yaml:4: panels[0]: give exactly one of `study` and `overlay`"),
    ("panels:\n  - {kind: period, overlay: [{study: a.yaml}]}\n",
     "f.yaml:4: panels[0]: only bifurcation, damping_multiples and law panels can be overlaid"),
    ("panels:\n  - {kind: contour, study: a.yaml}\n",
     "f.yaml:4: panels[0].kind: expected one of bifurcation"),
    ("layout: [1, 1]\npanels:\n  - {kind: bifurcation, study: a.yaml}\n"
     "  - {kind: period, study: a.yaml}\n",
     "f.yaml:3: layout: 2 panels do not fit a 1 x 1 layout"),
    ("panels: []\n", "f.yaml:3: panels: "),
])
def test_bad_sheets_name_file_line_key_and_reason(tmp_path, body, expected):
    write(tmp_path, "a.yaml", STUDY)
    path = write(tmp_path, "f.yaml", 'figure: "3.1"\ncaption: c\n' + body)
    with pytest.raises(StudyError) as caught:
        load_sheet(path)
    assert expected in str(caught.value)


PANEL = "panels:\n  - {kind: bifurcation, study: a.yaml}\n"


@pytest.mark.parametrize("body, expected", [
    ("size: [1200, 560]\n" + PANEL,
     ["f.yaml:3: size[0]: expected inches, 1 to 40, got 1200 (the size is in inches, not "
      "pixels)", "f.yaml:3: size[1]: expected inches, 1 to 40, got 560 (the size is in "
      "inches, not pixels)"]),
    ("size: [.nan, 5]\n" + PANEL, ["f.yaml:3: size[0]: expected a finite number, got .nan"]),
    ("size: [.inf, 5]\n" + PANEL, ["f.yaml:3: size[0]: expected a finite number, got .inf"]),
    ("size: ['6', 5]\n" + PANEL, ["f.yaml:3: size[0]: expected a number, got '6'"]),
    ("size: [0.2, 5]\n" + PANEL, ["f.yaml:3: size[0]: expected inches, 1 to 40, got 0.2"]),
    ("layout: [1, 100000000]\n" + PANEL, ["f.yaml:3: layout[1]: must be <= 64, got 100000000"]),
    ("layout: [8, 8]\n" + PANEL,
     ["f.yaml:3: layout: 8 x 8 panels of 5.2 x 4.2 inches make 41.6 x 33.6 inches, over 40; "
      "give `size`"]),
    ("panels:\n  - {kind: phase, study: a.yaml, orbits: [0, 2]}\n",
     ["f.yaml:4: panels[0].orbits[0]: must be >= 1, got 0"]),
    ("panels:\n  - {kind: bifurcation, study: a.yaml, colour: red}\n",
     ["f.yaml:4: panels[0].colour: unknown key (allowed: kind, study, overlay, continuation, "
      "branch, state, sweep, slice, orbits, simulation, hz, title, cuts)"]),
    ("panels: []\n", ["f.yaml:3: panels: expected 1 to 64 panels, got 0"]),
])
def test_numeric_sheet_keys_are_bounded_and_each_problem_is_said_once(tmp_path, body,
                                                                      expected):
    """Sizes in inches within bounds (pixels drew a 180000-pixel figure: MemoryError), finite
    and of the right type; counts bounded; a bad panel reported alone (it added "panels:
    Tuple should have at least 1 item")."""
    write(tmp_path, "a.yaml", STUDY)
    path = write(tmp_path, "f.yaml", 'figure: "3.1"\ncaption: c\n' + body)
    with pytest.raises(StudyError) as caught:
        load_sheet(path)
    assert caught.value.message.splitlines() == [line.replace("f.yaml", str(path))
                                                 for line in expected]


@pytest.mark.parametrize("text, expected", [
    ("", ": the sheet file is empty"),
    ("- a\n", ":1: a sheet must be a YAML mapping of keys, got a list"),
])
def test_whole_sheet_problems_call_it_a_sheet(tmp_path, text, expected):
    path = write(tmp_path, "f.yaml", text)
    with pytest.raises(StudyError) as caught:
        load_sheet(path)
    assert caught.value.message == f"{path}{expected}"


def test_bad_figure_number(tmp_path):
    path = write(tmp_path, "f.yaml", 'figure: "three"\ncaption: c\npanels: []\n')
    with pytest.raises(StudyError, match=r"f.yaml:1: figure: expected a figure number"):
        load_sheet(path)


# -- panels --------------------------------------------------------------------------------------

def test_every_panel_kind_draws_or_names_what_is_missing(continuation):  # noqa: F811
    result = result_with(continuation, 10.0)
    drawn = {}
    for kind in PANEL_KINDS:
        ax = new_figure().add_subplot()
        try:
            drawn[kind] = draw(result, kind, ax)
        except WhirlError as error:
            drawn[kind] = str(error)
    (bifurcation,) = drawn["bifurcation"]
    assert bifurcation.get_title() == ""  # no stored study text, nothing fixed: no title
    assert len(branch_lines(bifurcation)) >= 2
    freq, damp = drawn["linear"]  # the linear kind splits its panel in two
    assert freq.get_ylabel() == "frequency [rad/s]"
    assert damp.get_ylabel() == "damping ratio [-]"
    assert len(drawn["projections"]) == len(STATES)
    assert drawn["root_locus"][0].get_xlabel() == "Re $\\lambda$ [1/s]"
    assert drawn["period"][0].get_ylabel() == "period [s]"
    assert "no stability boundary" in drawn["boundary"]
    assert "no stability boundary" in drawn["overhang"]
    assert "freeplay amplitudes" in drawn["amplitude"]


def test_panel_choices_are_checked(continuation):  # noqa: F811
    result = result_with(continuation, 10.0)
    ax = new_figure().add_subplot()
    with pytest.raises(WhirlError, match="no one-parameter continuation 'nope'"):
        draw(result, "bifurcation", ax, PanelChoice(continuation="nope"))
    with pytest.raises(WhirlError, match="no linear sweep of 'V'"):
        draw(result, "linear", ax, PanelChoice(sweep="V"))
    with pytest.raises(WhirlError, match="unknown panel kind"):
        draw(result, "contour", ax)


def test_overlay_one_colour_per_result_labelled_by_what_differs(continuation):  # noqa: F811
    results = [result_with(continuation, k2, f"s{k2:g}") for k2 in (5.0, 10.0, 20.0)]
    assert differing_labels(results) == [f"K2_theta = {k:g} N m/rad^3" for k in (5, 10, 20)]
    ax = new_figure().add_subplot()
    draw_overlay(results, "bifurcation", ax, labels=[None, "datum K2"])
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend[:3] == ["K2_theta = 5 N m/rad^3", "datum K2", "K2_theta = 20 N m/rad^3"]
    assert "Hopf (HB)" in legend and "fold (LP, LPC)" in legend
    colours = {to_hex(line.get_color()) for line in branch_lines(ax)}
    assert len(colours) == 3  # one per result; stability by line style
    styles = {line.get_linestyle() for line in branch_lines(ax)}
    assert styles == {"-", ":"}
    assert ax.get_title() == "$K_{\\psi}$ = 0.3 N m/rad"  # the parameter they share, not K2
    with pytest.raises(WhirlError, match="cannot be overlaid"):
        draw_overlay(results, "period", ax)


def test_differing_labels_fall_back_to_study_names(continuation):  # noqa: F811
    same = [result_with(continuation, 10.0, "a"), result_with(continuation, 10.0, "b")]
    assert differing_labels(same) == ["a", "b"]
    old = [replace(same[0], parameters=()), same[1]]
    assert differing_labels(old) == ["a", "b"]


def test_sheet_layout_title_and_first_legend_only(tmp_path, continuation):  # noqa: F811
    write(tmp_path, "a.yaml", STUDY)
    path = write(tmp_path, "f.yaml",
                 'figure: "3.22"\ncaption: grid\nlayout: [2, 2]\nlegends: first\npanels:\n'
                 + "  - {kind: bifurcation, study: a.yaml}\n" * 3)
    sheet = load_sheet(path)
    figure = draw_sheet(sheet, {tmp_path / "a.yaml": result_with(continuation, 10.0)})
    assert len(figure.axes) == 3
    assert figure.get_suptitle().startswith("Figure 3.22: grid")
    assert [ax.get_legend() is not None for ax in figure.axes] == [True, False, False]
    positions = sorted((round(ax.get_position().x0, 2), -round(ax.get_position().y0, 2))
                       for ax in figure.axes)
    assert len({x for x, _ in positions}) == 2 and len({y for _, y in positions}) == 2


def test_sheet_panel_errors_name_sheet_and_panel(tmp_path, continuation):  # noqa: F811
    write(tmp_path, "a.yaml", STUDY)
    path = write(tmp_path, "f.yaml", 'figure: "3.1"\ncaption: c\npanels:\n'
                 "  - {kind: boundary, study: a.yaml}\n")
    with pytest.raises(WhirlError, match=r"f.yaml: panels\[0\] \(boundary\): .*no stability"):
        draw_sheet(load_sheet(path), {tmp_path / "a.yaml": result_with(continuation, 1.0)})


# -- index ---------------------------------------------------------------------------------------

def test_index_lists_figures_in_number_order_escaped():
    entries = [Entry("3.12", "roots <b>", "", "fig3_12.png", ("s.yaml",), "s.yaml"),
               Entry("3.3", "damping", "a note", None, ("t.yaml",), "t.yaml",
                     "study failed")]
    page = index_html(entries, "whirl figures")
    assert page.index("Figure 3.3") < page.index("Figure 3.12")
    assert "roots &lt;b&gt;" in page and "<b>" not in page
    assert '<img src="fig3_12.png"' in page
    assert "not drawn: study failed" in page and "a note" in page
    assert np.char.count(page, "<section").item() == 2


def test_figure_numbers_sort_by_number_then_letter():
    from whirl_cli.figures.index import figure_order

    numbers = ["3.12a", "3.3", "3.12", "4.1", "3.22"]
    assert sorted(numbers, key=figure_order) == ["3.3", "3.12", "3.12a", "3.22", "4.1"]


def test_damping_multiples_overlay_style_per_result_colour_per_parameter(continuation):  # noqa: F811
    sweep = replace(make_sweep(), datum=0.25)
    results = [replace(result_with(continuation, k2), linear_sweeps=(sweep,))
               for k2 in (5.0, 10.0)]
    ax = new_figure().add_subplot()
    damping, frequency = draw_overlay(results, "damping_multiples", ax, ["on", "off"])
    for panel in (damping, frequency):
        lines = [line for line in panel.lines if not line.get_label().startswith("_")]
        assert [line.get_label() for line in lines] == ["on: K1 (BW)", "off: K1 (BW)"]
        assert [line.get_linestyle() for line in lines] == ["-", "--"]
        assert to_hex(lines[0].get_color()) == to_hex(lines[1].get_color())
        np.testing.assert_allclose(lines[0].get_xdata(), sweep.values / 0.25)
    assert frequency.get_xlabel() == "parameter / datum"


def test_simulation_panels_one_axes_per_dof_and_a_hub_path(continuation):  # noqa: F811
    from whirl_cli.results import Simulation

    time = np.linspace(0.0, 2.0, 201)
    states = np.column_stack([0.01 * np.cos(5 * time), 0.01 * np.sin(5 * time),
                              -0.05 * np.sin(5 * time), 0.05 * np.cos(5 * time)])
    simulation = Simulation("kick", "smoothed", (), (), np.array([]), STATES,
                            ("rad", "rad", "rad/s", "rad/s"), states[0], time, states,
                            -states[:, [1, 0]], "rad", 0, "ok")
    result = replace(result_with(continuation, 10.0), simulations=(simulation,))
    history = draw(result, "time_history", new_figure().add_subplot(),
                   PanelChoice(simulation="kick"))
    assert [ax.get_ylabel() for ax in history] == ["$\\theta$ [deg]", "$\\psi$ [deg]"]
    np.testing.assert_allclose(history[0].lines[0].get_ydata(), np.degrees(states[:, 0]))
    (hub,) = draw(result, "hub_path", new_figure().add_subplot())
    assert hub.get_xlabel() == "hub y [deg]"
    with pytest.raises(WhirlError, match="no simulation 'other' \\(simulations: kick\\)"):
        draw(result, "hub_path", new_figure().add_subplot(), PanelChoice(simulation="other"))


@pytest.mark.parametrize("size, font", [(7.2, 8.0), (12.0, 10.0)])
def test_figure_legend_takes_as_many_columns_as_its_labels_fit(size, font):
    """The columns of the figure legend come from its labels' measured width at the text size
    drawn: more than one where they fit, the legend within the figure."""
    from matplotlib import rc_context

    from whirl_cli.figures.draw import figure_legend

    labels = ["stable equilibrium", "neutral equilibria (zero eigenvalue)",
              "damping ratio 0 ($K_\\theta$ = 0.08071 N m/rad)", "Hopf (HB)", "BW", "FW"]
    with rc_context({"font.size": font}):
        figure = new_figure(figsize=(size, 4.0))
        for k, ax in enumerate(figure.subplots(1, 2)):
            for label in labels[3 * k:3 * k + 3]:
                ax.plot([0, 1], [0, k], label=label)
            ax.legend()
        figure_legend(figure)
        (legend,) = figure.legends
        figure.canvas.draw()
        box = legend.get_window_extent()
    assert legend._ncols >= 2  # one column (the count at 10 pt) made 3.14's legend as tall
    assert 0 <= box.x0 and box.x1 <= figure.bbox.width  # as its panels at 7.2 in
