"""The figures the thesis draws and whirl had not: the stiffness laws side by side (3.4), the
linear modes against airspeed with the flutter mode and its onset told apart (3.5), and the
period approaching a global bifurcation with its fitted 1/x asymptote (3.25)."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.colors import to_hex

from tests.unit.plot_data import (
    ASYMPTOTE,
    OFFSET,
    SCALE,
    blowup_continuation,
    blowup_family,
)
from whirl_cli.plots.blowup import approach, blowup_plot, fit_blowup
from whirl_cli.plots.key import new_figure
from whirl_cli.plots.laws import laws_plot
from whirl_cli.plots.linear import (
    STABLE_COLOURS,
    UNSTABLE_COLOURS,
    linear_sweep_plot,
    zero_crossings,
)
from whirl_cli.results import LinearSweep

from ..conftest import ROOT


def test_fit_blowup_recovers_the_asymptote_of_a_1_over_x_approach():
    parameter, period = blowup_family()
    first, last = approach(parameter, period)
    assert first >= 45 and last == len(parameter) - 1  # the approach, not the fold before it
    fit = fit_blowup(parameter, period)
    assert fit.asymptote == pytest.approx(ASYMPTOTE, abs=1e-7)
    assert fit.scale == pytest.approx(SCALE, rel=1e-5)
    assert fit.offset == pytest.approx(OFFSET, abs=1e-5)


def test_fit_needs_a_run_over_which_the_period_grows():
    with pytest.raises(ValueError, match="period grows"):
        approach(np.linspace(0.0, 1.0, 20), np.linspace(1.0, 0.5, 20))


def test_blowup_plot_draws_the_family_its_points_fit_and_asymptote():
    figure = blowup_plot(blowup_continuation())
    (ax,) = figure.axes
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[-2:] == ["fitted 1/x curve", "fitted asymptote K1 = -0.08 N m/rad"]
    assert "homoclinic (whirl: K1 = -0.0801)" in labels
    assert "fold (LP, LPC)" in labels and "stable periodic" in labels
    (asymptote,) = [line for line in ax.lines if line.get_label() == "_asymptote"]
    assert asymptote.get_xdata()[0] == pytest.approx(ASYMPTOTE, abs=1e-7)
    low, high = ax.get_xlim()
    assert low < ASYMPTOTE < high and high > -0.03  # the fold the approach leaves is shown
    (homoclinic,) = [line for line in ax.lines if line.get_marker() == "^"]
    (fold,) = [line for line in ax.lines if line.get_marker() == "o"]
    assert homoclinic.get_zorder() > fold.get_zorder()


def airspeed_sweep() -> LinearSweep:
    """BW damping 0.12 - 0.02 V (zero at V = 6), FW 0.12 + 0.01 V, over V = 0..10."""
    values = np.linspace(0.0, 10.0, 11)
    zeta = {"BW": 0.12 - 0.02 * values, "FW": 0.12 + 0.01 * values}
    omega = {"BW": 37.0 - values, "FW": 60.0 - 0.5 * values}
    columns = []
    for name in ("BW", "FW"):
        root = omega[name] * (-zeta[name] + 1j * np.sqrt(1 - zeta[name] ** 2))
        columns += [root, root.conj()]
    eigenvalues = np.column_stack(columns)
    whirl = np.array([["BW", "BW", "FW", "FW"]] * len(values))
    return LinearSweep("V", "m/s", values, eigenvalues,
                       -eigenvalues.real / np.abs(eigenvalues), np.abs(eigenvalues.imag), whirl)


def test_damping_zero_crossings_are_interpolated():
    found = zero_crossings(airspeed_sweep())
    assert list(found) == [0]  # the BW column only
    ((value, frequency),) = found[0]
    assert value == pytest.approx(6.0)
    assert frequency == pytest.approx(31.0)


def test_linear_plot_tells_the_flutter_mode_apart_and_marks_its_onset():
    figure = linear_sweep_plot(airspeed_sweep())
    ax_freq, ax_damp = figure.axes
    modes = {line.get_label(): to_hex(line.get_color()) for line in ax_damp.lines
             if line.get_label() in ("BW", "FW")}
    assert modes == {"BW": to_hex(UNSTABLE_COLOURS[0]), "FW": to_hex(STABLE_COLOURS[0])}
    onset = [line for line in ax_damp.lines if line.get_marker() == "o"]
    assert [(line.get_xdata()[0], line.get_ydata()[0]) for line in onset] == [
        pytest.approx((6.0, 0.0))]
    labels = [t.get_text() for t in ax_freq.get_legend().get_texts()]
    assert labels == ["BW", "FW", "damping ratio 0 (V = 6 m/s)"]
    verticals = [line for ax in (ax_freq, ax_damp) for line in ax.lines
                 if line.get_label() == "_onset" and line.get_linestyle() == ":"]
    assert len(verticals) == 2 and all(line.get_xdata()[0] == 6.0 for line in verticals)


def test_laws_side_by_side_with_the_linear_spring():
    from whirl_cli.output.provenance import law_curve
    from whirl_cli.study import load_study

    entries = []
    for name in ("hardening_case2", "softening_case2", "combined_case2"):
        study = load_study(ROOT / "studies" / "thesis_ch3" / f"{name}.yaml")
        entries.append((law_curve(study.variant(), study.parameter_values(), "theta"), name))
    ax = new_figure().add_subplot()
    laws_plot(entries, ax=ax)
    lines = {line.get_label(): line for line in ax.lines}
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "linear (K_theta = 0.4)", "hardening_case2", "softening_case2", "combined_case2"]
    x = np.radians(lines["hardening_case2"].get_xdata())
    expected = {"linear (K_theta = 0.4)": 0.4 * x,
                "hardening_case2": 0.4 * x + 10 * x**3,
                "softening_case2": 0.4 * x - 10 * x**3,
                "combined_case2": 0.4 * x - 10 * x**3 + 350 * x**5}
    for label, force in expected.items():
        np.testing.assert_allclose(lines[label].get_ydata(), force, atol=1e-12)
    styles = {(to_hex(line.get_color()), str(line.get_linestyle())) for line in lines.values()
              if not line.get_label().startswith("_")}
    assert len(styles) == 4  # no two laws alike
