"""The root locus plot kind (issue 17, item 2): eigenvalues of a linear sweep in the complex
plane, coloured by the parameter, FW/BW told apart, checked on the figure object."""

from __future__ import annotations

import numpy as np
from click.testing import CliRunner

from whirl_cli.analysis import linear
from whirl_cli.cli import cli
from whirl_cli.models import get_model
from whirl_cli.plots.linear import root_locus_plot

from ..conftest import ROOT


def test_the_root_locus_crosses_the_imaginary_axis_at_the_hopf_point():
    """Read off the drawn markers (positions and colour values), the root crossing Re = 0
    does so, by linear interpolation between sweep points 1e-4 m/s apart, at the Hopf point
    Brent's method finds on the eigenvalues (1e-6 m/s)."""
    model = get_model("classical")
    (hopf,) = [p.value for p in linear.critical_points(model, {}, "V", 7.0, 8.5)
               if p.kind == "hopf"]
    sweep = linear.sweep(model, {}, "V", np.linspace(hopf - 0.05, hopf + 0.05, 1001))
    figure = root_locus_plot(sweep)
    ax = figure.axes[0]
    crossings = []
    for collection in ax.collections:
        xy, values = collection.get_offsets(), collection.get_array()
        for branch in (xy[:, 1] > 0, xy[:, 1] < 0):
            re, v = xy[branch, 0], np.asarray(values)[branch]
            order = np.argsort(v)
            re, v = re[order], v[order]
            # a crossing once, also where a sweep point lies on Re = 0 (the sweep's middle
            # point is the Hopf point itself: its real part may round to exactly 0)
            for k in np.flatnonzero((re[:-1] < 0) != (re[1:] < 0)):
                crossings.append(v[k] - re[k] * (v[k + 1] - v[k]) / (re[k + 1] - re[k]))
    assert len(crossings) == 2  # the conjugate pair
    np.testing.assert_allclose(crossings, hopf, atol=1e-6)
    labels = {t.get_text() for t in ax.get_legend().get_texts()}
    assert labels <= {"FW", "BW", "real root", "crossing Re $\\lambda$ = 0 (Hopf)",
                      "real roots coalesce"} and labels & {"FW", "BW"}
    (square,) = [line for line in ax.get_lines() if line.get_marker() == "s"]
    np.testing.assert_array_equal(square.get_xdata(), [0.0])  # the crossing marked
    assert ax.get_xlabel() == "Re $\\lambda$ [1/s]"
    assert ax.get_ylabel() == "Im $\\lambda$ [rad/s]"
    assert figure.axes[1].get_ylabel() == "V [m/s]"  # the colour bar names the parameter


def test_whirl_plot_draws_it_from_a_file_with_a_sweep(tmp_path):
    reference = ROOT / "tests" / "regression" / "references" / "linear_datum_airspeed.h5"
    run = CliRunner().invoke(cli, ["plot", str(reference), "--kind", "root_locus", "-o",
                                   str(tmp_path)])
    assert run.exit_code == 0, run.output
    assert [p.name for p in tmp_path.glob("*.png")] == ["linear_datum_airspeed_root_locus_V.png"]
    other = ROOT / "tests" / "regression" / "references" / "hardening_case2.h5"
    run = CliRunner().invoke(cli, ["plot", str(other), "--kind", "root_locus", "-o",
                                   str(tmp_path)])
    assert run.exit_code == 1 and "no linear sweep" in run.output
