"""The registry of plot kinds is the only list of them: the command line, the study and sheet
schemas and the drawing code read it, and a kind added as one module appears in all of them."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import get_args

from tests.package_copy import loaded_after
from whirl_cli.plots.kinds import overlay_kinds, panel_kinds, plot_kinds, registry

REFERENCE = Path(__file__).resolve().parents[1] / "regression" / "references" / \
    "hardening_case2.h5"


def test_every_list_of_plot_kinds_is_the_registry():
    from whirl_cli.cli import plot
    from whirl_cli.figures.sheet import PanelKind
    from whirl_cli.plots import files, panels
    from whirl_cli.study.schema import PlotKind

    option = next(p for p in plot.params if p.name == "kinds")
    assert tuple(option.type.choices) == plot_kinds()
    assert get_args(PlotKind) == plot_kinds() == files.PLOT_KINDS
    assert get_args(PanelKind) == panel_kinds() == panels.PANEL_KINDS
    assert overlay_kinds() == panels.OVERLAY_KINDS


def test_every_kind_draws_a_panel_and_a_file_kind_says_what_it_needs():
    for name, kind in registry().items():
        assert kind.name == name and callable(kind.panel)
        assert (kind.missing is None) == (kind.figures is None), name
    assert len({kind.rank for kind in registry().values()}) == len(registry())  # one order
    assert set(plot_kinds()) < set(panel_kinds())
    assert set(overlay_kinds()) <= set(panel_kinds())


def test_the_registry_is_light():
    """Listing the kinds imports no drawing code (the command line lists them at start-up)."""
    assert loaded_after("from whirl_cli.plots.kinds import plot_kinds; plot_kinds()",
                        {"numpy", "matplotlib", "whirl_cli.results"}) == []


TOY = '''
from whirl_cli.plots.kinds import PlotKind


def _missing(result):
    return "" if result.continuations else "no continuation"


def _draw():
    from matplotlib.figure import Figure

    figure = Figure(figsize=(2, 2))
    figure.add_subplot().plot([0, 1], [1, 0])
    return figure


def _figures(figures):
    return [(f"{figures.stem}_toy.png", _draw)]


def _panel(result, ax, choice, caption):
    ax.plot([0, 1], [0, 1])
    return [ax]


TOY = PlotKind("toy", 5, _panel, missing=_missing, figures=_figures)
'''

CHECK = '''
import sys
from pathlib import Path

import whirl_cli.plots.kinds as kinds

kinds.__path__.append(sys.argv[1])  # the toy module lies beside the package's own
from click.testing import CliRunner
from matplotlib.figure import Figure

from whirl_cli.cli import cli
from whirl_cli.output import store
from whirl_cli.plots.panels import draw
from whirl_cli.study import validate_text

print("help", "toy" in CliRunner().invoke(cli, ["plot", "--help"]).output)
print("study", validate_text("name: t\\nmodel: classical\\nplots: [toy]\\n").plots)
out = Path(sys.argv[1]) / "out"
ran = CliRunner().invoke(cli, ["plot", sys.argv[2], "--kind", "toy", "-o", str(out)])
print("plot", ran.exit_code, sorted(p.name for p in out.iterdir()))
print("panel", len(draw(store.read(sys.argv[2]), "toy", Figure().add_subplot())))
'''


def test_a_kind_added_as_one_module_is_in_every_list(tmp_path):
    (tmp_path / "toy.py").write_text(TOY)
    done = subprocess.run([sys.executable, "-c", CHECK, str(tmp_path), str(REFERENCE)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [
        "help True", "study ('toy',)", "plot 0 ['hardening_case2_toy.png']", "panel 1"]
