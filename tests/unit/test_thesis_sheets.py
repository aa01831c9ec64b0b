"""Shipped sheets of the linear model's figures (3.7, 3.8, 3.12, 3.13), drawn from their own
studies (numpy and scipy only, no AUTO) and checked from the figure's own artists against the
model written out apart from whirl (tests.classical_exact)."""

from __future__ import annotations

from dataclasses import replace
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from matplotlib.collections import QuadMesh

from tests.classical_exact import linear_matrix
from tests.unit.plot_data import make_branch, make_point
from whirl_cli.analysis import linear
from whirl_cli.api import run
from whirl_cli.figures.draw import draw_sheet
from whirl_cli.figures.sheet import load_sheet
from whirl_cli.models import get_model
from whirl_cli.plots.blowup import blowup_plot, fit_blowup
from whirl_cli.plots.cuts import phase_cut
from whirl_cli.plots.files import rendered_formats
from whirl_cli.plots.key import new_figure
from whirl_cli.plots.linear import root_locus_plot
from whirl_cli.results import BranchKind, ContinuationResult, PointType

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


@pytest.mark.parametrize("number", ["3.7", "3.8", "3.12", "3.13"])
def test_linear_sheets_are_pixel_identical_run_to_run(number):
    first = rendered_formats(drawn(number), ("png",), 80)["png"]
    assert rendered_formats(drawn(number), ("png",), 80)["png"] == first


def _bisect(f, low: float, high: float) -> float:
    """The root of ``f`` in [low, high] (a sign change or a change of value at the ends)."""
    a = f(low)
    same = (lambda u: u == a) if isinstance(a, int) else (lambda u: u * a > 0)
    for _ in range(60):
        middle = 0.5 * (low + high)
        if same(f(middle)):
            low = middle
        else:
            high = middle
    return 0.5 * (low + high)


def _roots(k_theta: float) -> np.ndarray:
    return np.linalg.eigvals(linear_matrix({"K_theta": k_theta, "K_psi": 0.3}))


def _lowest_pair(k_theta: float) -> complex:
    """The complex root of smallest positive Im (the backward whirl pair's upper root)."""
    roots = _roots(k_theta)
    upper = roots[roots.imag > 1e-6]
    return upper[np.argmin(upper.imag)]


def _real_count(k_theta: float) -> int:
    return int(np.sum(np.abs(_roots(k_theta).imag) <= 1e-9))


def _changes(f, low: float, high: float) -> list[float]:
    """Every point of [low, high] where ``f`` changes sign (or value, integer ``f``)."""
    ks = np.linspace(low, high, 401)
    found = []
    for a, b in zip(ks[:-1], ks[1:], strict=True):
        fa, fb = f(a), f(b)
        if (fa != fb) if isinstance(fa, int) else fa * fb < 0:
            found.append(_bisect(f, a, b))
    return found


def _marked(ax, marker: str) -> np.ndarray:
    lines = [line for line in ax.get_lines() if line.get_marker() == marker]
    assert len(lines) == 1
    return np.asarray(lines[0].get_xydata(), dtype=float)


def test_3_12_zooms_on_the_backward_pair_crossings_and_marks_them():
    figure = drawn("3.12")
    ax = figure.axes[0]
    (zoom,) = ax.child_axes
    # where the backward pair crosses the imaginary axis and the real roots coalesce, from
    # numpy's eigenvalues of the model written out apart from whirl
    has_pair = [k for k in np.linspace(-0.3, 0.5, 801) if _real_count(k) < 2]
    crossings = [(k, _lowest_pair(k).imag) for k in
                 _changes(lambda k: float(_lowest_pair(k).real), min(has_pair), 0.5)]
    assert len(crossings) == 2
    (coalescence,) = _changes(_real_count, -0.3, 0.5)
    meeting = _lowest_pair(coalescence + 1e-9).real
    for axes in (ax, zoom):
        squares = _marked(axes, "s")
        assert len(squares) == len(crossings)
        for (x, y), (_, im) in zip(sorted(squares.tolist(), key=lambda p: p[1]),
                                   sorted(crossings, key=lambda c: c[1]), strict=True):
            assert x == 0.0 and y == pytest.approx(im, abs=0.05)
        ((x, y),) = _marked(axes, "D")
        assert y == 0.0 and x == pytest.approx(meeting, abs=0.1)
    (left, right), (bottom, top) = zoom.get_xlim(), zoom.get_ylim()
    assert left < 0.0 < right and left > -2.0 and right < 2.0  # a zoom on the axis
    for _, im in crossings:
        assert bottom < im < top
    assert left < meeting < right and bottom < 0.0 < top


def test_3_12_arrows_point_the_way_k_theta_increases_and_the_axes_lie_under_the_roots():
    figure = drawn("3.12")
    ax = figure.axes[0]
    for axes in (ax, *ax.child_axes):
        arrows = [t for t in axes.texts if getattr(t, "arrow_patch", None) is not None]
        assert arrows
        for arrow in arrows:
            tail, head = np.asarray(arrow.xyann), np.asarray(arrow.xy)
            ks = np.linspace(-0.3, 0.5, 321)
            nearest = [ks[np.argmin([np.min(np.abs(_roots(k) - complex(*p))) for k in ks])]
                       for p in (tail, head)]
            assert nearest[1] > nearest[0]
        lines = [line for line in axes.get_lines() if line.get_label().endswith("axis")]
        assert len(lines) == 2
        assert max(line.get_zorder() for line in lines) < min(
            c.get_zorder() for c in axes.collections)
    assert any("increasing" in t.get_text() for t in ax.texts)


def test_3_12_arrows_keep_clear_of_the_crossing_and_coalescence_markers():
    """No arrow of 3.12 (main axes or zoom) passes within a marker's size (8 pt) plus a bit
    of a crossing square or the coalescence diamond, measured on the figure as drawn."""
    figure = drawn("3.12")
    figure.canvas.draw()
    reach = 10.0 * figure.dpi / 72.0  # pixels
    ax = figure.axes[0]
    for axes in (ax, *ax.child_axes):
        marks = np.concatenate([_marked(axes, "s"), _marked(axes, "D")])
        centres = axes.transData.transform(marks)
        for arrow in (t for t in axes.texts if getattr(t, "arrow_patch", None) is not None):
            tail, head = axes.transData.transform([arrow.xyann, arrow.xy])
            along = head - tail
            t = np.clip((centres - tail) @ along / max(float(along @ along), 1e-300), 0, 1)
            gaps = np.hypot(*(centres - (tail + t[:, None] * along)).T)
            assert gaps.min() >= reach


def _mode_sense(values: dict, highest: bool) -> int:
    """+1 (counterclockwise) or -1: the sense in which the hub, (y, z) = (-psi, -theta),
    turns in the plane drawn y right, z up, for the lower (or ``highest``) oscillatory mode
    of the model written out, from its eigenvector over one period."""
    roots, vectors = np.linalg.eig(linear_matrix(values))
    upper = np.flatnonzero(roots.imag > 1e-6)
    k = upper[np.argmax(roots[upper].imag)] if highest else upper[np.argmin(roots[upper].imag)]
    t = np.linspace(0.0, 2 * np.pi / roots[k].imag, 400, endpoint=False)
    wave = np.exp(1j * roots[k].imag * t)
    y, z = np.real(-vectors[1, k] * wave), np.real(-vectors[0, k] * wave)
    return int(np.sign(np.sum(y * np.roll(z, -1) - np.roll(y, -1) * z)))


def _spin_sense() -> int:
    """The sense of the mode whose frequency rises with the spin Omega (forward whirl turns
    with the spin)."""
    def frequencies(omega):
        roots = np.linalg.eigvals(linear_matrix({"V": 7.8, "Omega": omega}))
        return np.sort(roots.imag[roots.imag > 1e-6])
    low, high = frequencies(40.0), frequencies(44.0)
    rising_is_highest = high[-1] > low[-1]
    return _mode_sense({"V": 7.8}, highest=rising_is_highest)


def _arrow_sense(arrow) -> int:
    (ay, az), (by, bz) = arrow._posA_posB  # tail, head in data coordinates (hub plane)
    return int(np.sign(ay * bz - az * by))


def _arrows(ax) -> dict:
    return {p.get_gid(): p for p in ax.patches if p.get_gid() in ("whirl", "spin")}


def test_3_8_hub_paths_carry_whirl_and_spin_arrows():
    figure = drawn("3.8")
    panels = [ax for ax in figure.axes if ax.get_xlabel().startswith("hub y")]
    assert len(panels) == 2
    spin = _spin_sense()
    growing = _mode_sense({"V": 7.8}, highest=False)  # the backward mode flutters here
    assert growing == -spin
    for ax in panels:
        arrows = _arrows(ax)
        assert set(arrows) == {"whirl", "spin"}
        assert _arrow_sense(arrows["spin"]) == spin
        assert _arrow_sense(arrows["whirl"]) == growing
        assert any(t.get_text() == "whirl (BW)" for t in ax.texts)


def test_3_7_is_snapshots_of_one_whirl_cycle_and_envelopes():
    figure = drawn("3.7")
    (whirl,) = [ax for ax in figure.axes if ax.get_xlabel().startswith("hub y")]
    dots = [line for line in whirl.get_lines() if line.get_gid() == "snapshot"]
    assert len(dots) == 8
    angles = np.unwrap([np.arctan2(*line.get_xydata()[0][::-1]) for line in dots])
    steps = np.degrees(np.diff(angles))
    sense = _mode_sense({"V": 7.8}, highest=False)
    np.testing.assert_allclose(steps, sense * 45.0, atol=8.0)  # one cycle, eight steps
    assert _arrow_sense(_arrows(whirl)["whirl"]) == sense
    assert _arrow_sense(_arrows(whirl)["spin"]) == _spin_sense()
    histories = [ax for ax in figure.axes if ax.get_xlabel() == "t [s]" or ax.get_ylabel()
                 in ("$\\theta$ [deg]", "$\\psi$ [deg]")]
    assert len(histories) == 2
    for ax in histories:  # the 60 s history as its envelope, not a band of 300 cycles
        lines = [line for line in ax.get_lines() if len(line.get_xdata()) > 2]
        assert len(lines) == 2 and all(len(line.get_xdata()) < 1000 for line in lines)
        upper = max(lines, key=lambda line: np.mean(line.get_ydata()))
        growth = np.interp([30.0, 59.0], upper.get_xdata(), upper.get_ydata())
        assert growth[1] / growth[0] == pytest.approx(np.exp(29.0 * _growth_rate()), rel=0.05)


def _growth_rate() -> float:
    """Re lambda of the backward mode at V = 7.8 m/s [1/s]."""
    roots = np.linalg.eigvals(linear_matrix({"V": 7.8}))
    upper = roots[roots.imag > 1e-6]
    return float(upper[np.argmin(upper.imag)].real)


ASYMPTOTE = -0.08


def blowup_continuation(global_type: PointType = PointType.HOMOCLINIC) -> ContinuationResult:
    """A family from p = 0.3 turning at a fold (p = -0.04, back to -0.03), then approaching
    p = -0.08 as T = 0.3 + 0.02 / (p + 0.08) over 1e-4 to 0.05 from it: the approach is a
    small part of the family's span."""
    run = ASYMPTOTE + np.geomspace(0.05, 1e-4, 40)
    parameter = np.concatenate([np.linspace(0.3, -0.04, 40), np.linspace(-0.04, -0.03, 6)[1:],
                                run])
    period = np.concatenate([0.26 + 0.001 * np.arange(40), 0.30 + 0.01 * np.arange(1, 6),
                             0.3 + 0.02 / (run - ASYMPTOTE)])
    family = replace(make_branch("periodic_1", BranchKind.PERIODIC, parameter,
                                 0.1 + 0 * parameter, np.arange(len(parameter)) < 60),
                     period=period)
    return ContinuationResult("k1", "one-parameter", (family,),
                              (make_point("periodic_1", global_type, -0.0801, 0.0),))


def test_a_narrow_blowup_approach_gets_a_zoom_holding_the_fit_and_its_asymptote():
    continuation = blowup_continuation()
    (family,) = continuation.branches
    parameter = family.parameters[:, 0]
    fit = fit_blowup(parameter, family.period)
    ax = blowup_plot(continuation).axes[0]
    (zoom,) = ax.child_axes
    left, right = zoom.get_xlim()
    main = abs(np.diff(ax.get_xlim())[0])
    assert right - left < 0.2 * main  # a zoom, not the same view
    for value in (ASYMPTOTE, parameter[fit.start], parameter[fit.stop], -0.0801):
        assert left < value < right
    assert [line.get_label() for line in zoom.lines if line.get_label() == "_fit"]


def test_a_heteroclinic_marker_stays_visible_on_a_blowup_plot():
    ax = blowup_plot(blowup_continuation(PointType.HETEROCLINIC)).axes[0]
    (marker,) = [line for line in ax.lines if line.get_marker() == "^"]
    assert marker.get_markerfacecolor() == "none"
    assert marker.get_markeredgecolor() not in ("white", "w", (1, 1, 1, 1))


def test_saddles_at_a_cut_are_marked_apart_from_other_unstable_equilibria():
    """Three equilibria at K1 = 0.1: one stable, one with a real root > 0 beside stable
    ones (a saddle), one unstable through a complex pair only (not a saddle)."""
    k1 = np.linspace(0.0, 0.2, 5)
    roots = {"stable": [-1 + 5j, -1 - 5j, -2, -3], "saddle": [2.0, -3, -1 + 5j, -1 - 5j],
             "focus": [0.5 + 3j, 0.5 - 3j, -1, -2]}
    branches = tuple(
        replace(make_branch(name, BranchKind.EQUILIBRIUM, k1, theta + 0 * k1,
                            [name == "stable"] * 5),
                eigenvalues=np.tile(np.asarray(roots[name], complex), (5, 1)))
        for name, theta in (("stable", 0.0), ("saddle", 0.1), ("focus", -0.1)))
    ax = new_figure().add_subplot()
    phase_cut(ContinuationResult("k1", "one-parameter", branches, ()), 0.1, ax)
    marks = {line.get_label().split()[0]: np.asarray(line.get_xydata()) for line in ax.lines}
    theta_deg = np.degrees(0.1)
    np.testing.assert_allclose(marks["saddle"], [[0.1 * theta_deg, theta_deg]])  # psi, theta
    np.testing.assert_allclose(marks["unstable"], [[-0.1 * theta_deg, -theta_deg]])
    np.testing.assert_allclose(marks["stable"], [[0.0, 0.0]])
    assert {line.get_marker() for line in ax.lines} == {"x", "X"}


@pytest.mark.parametrize("sweep_of", ["3.12", "airspeed"])
def test_a_root_locus_zoom_never_hides_roots(sweep_of):
    if sweep_of == "3.12":
        figure = drawn("3.12")
        roots = np.concatenate([_roots(k) for k in np.linspace(-0.3, 0.5, 161)])
    else:  # one crossing, roots in every corner: no room for a zoom
        sweep = linear.sweep(get_model("classical"), {}, "V", np.linspace(0.0, 10.0, 201))
        figure = root_locus_plot(sweep)
        roots = np.asarray(sweep.eigenvalues).reshape(-1)
    ax = figure.axes[0]
    figure.canvas.draw()
    shown = ax.transData.transform(np.column_stack([roots.real, roots.imag]))
    for zoom in ax.child_axes:
        assert zoom.get_window_extent().count_contains(shown) <= 0.01 * len(roots)
    assert len(ax.child_axes) == (1 if sweep_of == "3.12" else 0)
