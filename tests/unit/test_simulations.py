"""Simulations from stated initial conditions (issue 17, item 2: thesis figures 3.6-3.8): the
``simulations:`` key, the run (no AUTO), the stored group and the ``time_history`` and
``hub_path`` plot kinds.

The ground truth of the linear model is its closed-form solution y(t) = V e^(Lambda t) V^-1 y0
from the eigen-decomposition of the Jacobian at y = 0, and its growth rate the largest real
part of the eigenvalues; figures are checked on the Figure object."""

from __future__ import annotations

import dataclasses
import shutil

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

from whirl_cli import pipeline
from whirl_cli.analysis import linear, simulate
from whirl_cli.cli import cli
from whirl_cli.errors import StudyError
from whirl_cli.models import get_model
from whirl_cli.output import store
from whirl_cli.plots.captions import Captions, Fixed
from whirl_cli.plots.files import missing_data, plot_names
from whirl_cli.plots.simulations import hub_path, time_history
from whirl_cli.results import Simulation, StudyResult
from whirl_cli.study import validate_text
from whirl_cli.verdict import verdict

from ..conftest import ROOT

DEG = np.degrees(1.0)


@pytest.fixture(scope="module")
def model():
    return get_model("classical")


def closed_form(model, params: np.ndarray, y0: np.ndarray, time: np.ndarray) -> np.ndarray:
    """(K, n): the linear model's solution from ``y0``, by the eigen-decomposition of the
    Jacobian at y = 0 (from analysis.linear)."""
    (jacobian,) = linear.jacobians(model, params[:, None])
    values, vectors = np.linalg.eig(jacobian)
    weights = np.linalg.solve(vectors, y0.astype(complex))
    return (vectors @ (np.exp(np.outer(values, time)) * weights[:, None])).real.T


# ------------------------------------------------------------------------------ the physics
def test_the_linear_simulation_is_the_matrix_exponential(model):
    """Above the onset (V = 7.9 m/s), from 1 deg pitch and 2 deg/s yaw rate: every state
    within 1e-6 of its largest magnitude of the closed form, at every sample."""
    params = model.parameter_vector({"V": 7.9})
    y0 = np.array([1.0, 0.0, 0.0, 2.0]) / DEG
    found = simulate.simulation(model, params, y0, 4.0, 801)
    assert found.status == 0 and found.message
    np.testing.assert_array_equal(found.time, np.linspace(0.0, 4.0, 801))
    expected = closed_form(model, params, y0, found.time)
    error = np.abs(found.states - expected).max(axis=0) / np.abs(expected).max(axis=0)
    assert error.max() < 1e-6, error
    # the hub path is the declared combination: classical (y, z) = (-psi, -theta)
    np.testing.assert_array_equal(found.hub, found.states @ model.hub_matrix.T)
    assert found.hub_unit == "rad"


def test_the_growth_rate_is_the_largest_real_eigenvalue(model):
    """The pitch peaks of the simulation (parabola through the three samples around each
    maximum) grow as e^(sigma t), sigma the largest real part of the eigenvalues, once the
    forward mode (decay ~10/s) has died: fitted slope within 1e-3 relative."""
    params = model.parameter_vector({"V": 8.0})
    (jacobian,) = linear.jacobians(model, params[:, None])
    sigma = float(np.linalg.eigvals(jacobian).real.max())
    assert sigma > 0.1
    found = simulate.simulation(model, params, np.array([1.0, 0, 0, 0]) / DEG, 30.0, 15001)
    t, theta = found.time, found.states[:, 0]
    k = np.flatnonzero((theta[1:-1] > theta[:-2]) & (theta[1:-1] >= theta[2:])) + 1
    k = k[t[k] > 3.0]
    a, b, c = theta[k - 1], theta[k], theta[k + 1]
    shift = 0.5 * (a - c) / (a - 2 * b + c)
    peak = b - 0.25 * (a - c) * shift
    slope = np.polyfit(t[k] + shift * (t[1] - t[0]), np.log(peak), 1)[0]
    assert len(k) > 100
    assert slope == pytest.approx(sigma, rel=1e-3)


def test_a_diverging_simulation_stops_and_says_so(model):
    """A softening spring (K2 = -10) from 40 deg runs away in finite time: the simulation
    stops at the divergence bound (status 1, the message says so), keeping what it had; no
    exception. Its samples stop before the duration."""
    params = model.parameter_vector({"K2_theta": -10.0})
    found = simulate.simulation(model, params, np.array([40.0, 0, 0, 0]) / DEG, 10.0, 1001)
    assert found.status == 1 and "typical amplitudes" in found.message
    assert 1 < len(found.time) < 1001 and found.time[-1] < 10.0
    assert np.abs(found.states[:, 0]).max() <= simulate.DIVERGENCE_LIMIT
    assert verdict(StudyResult("s", "m", (), (), (), simulations=(found,))).problems == ()
    failed = dataclasses.replace(found, status=-1, message="step size too small")
    assert verdict(StudyResult("s", "m", (), (), (), simulations=(failed,))).problems == (
        "simulation  failed: step size too small",)


def test_the_exact_freeplay_law_inside_the_gap_is_the_free_linear_model():
    """Pitch freeplay (delta = 1 deg, K_in = 0): from 0.1 delta for 0.05 s the pitch stays in
    the gap, where the exact law has no pitch spring: the closed form of the linear model
    with K_theta = 0 (to 1e-6), while the smoothed law is not exactly that."""
    study = validate_text(
        "name: s\nmodel: classical\nparameters: {K_psi: 0.3}\n"
        "nonlinearity: {type: freeplay, dof: theta, delta: 0.017453292519943295, K_out: 0.4}\n"
        "simulations:\n  - {initial: {theta: 0.1}, duration: 0.05, samples: 51, law: exact}\n")
    found = pipeline.simulations(study, study.variant())[0]
    assert found.status == 0 and found.law == "exact"
    free = get_model("classical")
    params = free.parameter_vector({"K_psi": 0.3, "K_theta": 0.0})
    expected = closed_form(free, params, found.initial, found.time)
    assert np.abs(expected[:, 0]).max() < np.radians(1.0)
    error = np.abs(found.states - expected).max(axis=0) / np.abs(expected).max(axis=0)
    assert error.max() < 1e-6, error


# ------------------------------------------------------------------------------ the study
SIMULATIONS = """name: sims
model: classical
parameters: {K_psi: 0.3}
simulations:
  - parameters: {V: 7.9}
    initial: {theta: 1.0, dpsi: -2}
    duration: 0.5
    samples: 51
  - name: rest
    initial: {}
    duration: 0.1
plots: [time_history, hub_path]
"""


def test_a_study_of_simulations_alone_runs_without_auto(monkeypatch, tmp_path, model):
    """Names default to sim_<k>; initial states in deg and deg/s become SI; the overrides
    go on top of the study's (K_psi = 0.3 and V = 7.9 give the closed form); no AUTO; with
    two jobs (forked workers) the same results in the same order."""
    def no_auto(*args, **kwargs):
        raise AssertionError("a study without continuations started AUTO")

    monkeypatch.setattr(pipeline, "Engine", no_auto)
    study = validate_text(SIMULATIONS)
    assert [s.name for s in study.simulations] == ["sim_1", "rest"]
    result = pipeline.run_study(study, tmp_path)
    first, rest = result.simulations
    assert result.runs == () and result.continuations == ()
    assert first.parameter_names == ("V",) and first.parameter_units == ("m/s",)
    np.testing.assert_array_equal(first.parameter_values, [7.9])
    np.testing.assert_allclose(first.initial, [np.radians(1.0), 0, 0, np.radians(-2.0)])
    params = model.parameter_vector({"K_psi": 0.3, "V": 7.9})
    expected = closed_form(model, params, first.initial, first.time)
    assert np.abs(first.states - expected).max() < 1e-6 * np.abs(expected).max()
    assert len(rest.time) == 2001 and not rest.states.any()  # the default samples; at rest
    forked = pipeline.run_study(study, tmp_path, jobs=2).simulations  # one process each
    assert [s.name for s in forked] == ["sim_1", "rest"]
    for alone, beside in zip(result.simulations, forked, strict=True):
        np.testing.assert_array_equal(alone.time, beside.time)
        np.testing.assert_array_equal(alone.states, beside.states)
    names = plot_names(result, ("time_history", "hub_path"), "out")
    assert names == ["out_sim_1_time_history.png", "out_rest_time_history.png",
                     "out_sim_1_hub_path.png", "out_rest_hub_path.png"]


@pytest.mark.parametrize(("body", "expected"), [
    ("  - {initial: {phi: 1}, duration: 1}\n",
     ["s.yaml:4: simulations[0].initial.phi: expected one of theta, psi, dtheta, dpsi, got "
      "'phi'"]),
    ("  - {initial: {theta: 1}, duration: 0}\n",
     ["s.yaml:4: simulations[0].duration: must be > 0, got 0"]),
    ("  - {initial: {theta: 1}, duration: -2.5}\n",
     ["s.yaml:4: simulations[0].duration: must be > 0, got -2.5"]),
    ("  - {initial: {theta: 1}, duration: 1, law: exact}\n",
     ["s.yaml:4: simulations[0].law: the exact law needs a piecewise stiffness law (type: "
      "freeplay) on a dof; this study has none (use smoothed)"]),
    ("  - {initial: {theta: 1}, duration: 1, law: fast}\n",
     ["s.yaml:4: simulations[0].law: expected one of smoothed, exact, got 'fast'"]),
    ("  - {initial: [1, 2], duration: 1}\n",
     ["s.yaml:4: simulations[0].initial: expected a mapping state -> number, e.g. {theta: 2}, "
      "got a list"]),
    ("  - {initial: {theta: 1}, duration: 1, samples: 1}\n",
     ["s.yaml:4: simulations[0].samples: must be >= 2, got 1"]),
    ("  - {initial: {theta: 1}, duration: 1, parameters: {V: -1}}\n",
     ["s.yaml:4: simulations[0].parameters.V: V must be >= 0 m/s, got -1"]),
    ("  - {initial: {theta: 1}, duration: 1, parameters: {K2: 3}}\n",
     ["s.yaml:4: simulations[0].parameters.K2: set K2 under nonlinearity (type: polynomial, "
      "dof: theta)"]),
    ("  - {initial: {theta: 1}, duration: 1}\n  - {name: sim_1, initial: {}, duration: 1}\n",
     ["s.yaml:5: simulations[1].name: duplicate simulation name 'sim_1'"]),
    ("  - {initial: {theta: 1}}\n",
     ["s.yaml:4: simulations[0].duration: required key is missing"]),
])
def test_bad_simulations_are_refused_word_for_word(body, expected):
    with pytest.raises(StudyError) as caught:
        validate_text("name: s\nmodel: classical\nsimulations:\n" + body, "s.yaml")
    assert caught.value.message.splitlines() == expected


def test_the_exact_law_is_accepted_with_freeplay():
    study = validate_text(
        "name: s\nmodel: classical\nnonlinearity: {type: freeplay, delta: 0.01}\n"
        "simulations:\n  - {initial: {theta: 1}, duration: 1, law: exact}\n")
    assert study.simulations[0].law == "exact"


# ------------------------------------------------------------------------------ HDF5
def a_simulation(model, overrides: dict[str, float], name: str = "s1") -> Simulation:
    params = model.parameter_vector(overrides)
    return simulate.simulation(model, params, np.array([0.02, -0.01, 0.0, 0.1]), 0.3, 31,
                               name=name, overrides=overrides)


def test_the_simulations_group_round_trips_with_units(tmp_path, model):
    result = StudyResult("s", model.name, (), (), (), simulations=(
        a_simulation(model, {"V": 7.9, "K_psi": 0.3}), a_simulation(model, {}, "plain")))
    path = store.write(result, tmp_path / "r.h5")
    back = store.read(path)
    assert len(back.simulations) == 2
    for written, read in zip(result.simulations, back.simulations, strict=True):
        for field in dataclasses.fields(Simulation):
            x, y = getattr(written, field.name), getattr(read, field.name)
            if isinstance(x, np.ndarray):
                np.testing.assert_array_equal(x, y)
            else:
                assert x == y, field.name
    with h5py.File(path) as handle:
        group = handle["simulations/s1"]
        assert list(handle["simulations"]) == ["s1", "plain"]
        assert group.attrs["law"] == "smoothed" and group.attrs["status"] == 0
        assert list(group["parameters"].attrs["names"]) == ["V", "K_psi"]
        assert list(group["parameters"].attrs["units"]) == ["m/s", "N m/rad"]
        assert group["time"].attrs["units"] == "s"
        for key in ("initial", "states"):
            assert list(group[key].attrs["units"]) == ["rad", "rad", "rad/s", "rad/s"]
            assert list(group[key].attrs["names"]) == ["theta", "psi", "dtheta", "dpsi"]
        assert group["hub"].attrs["units"] == "rad" and group["hub"].shape == (31, 2)


def test_a_file_without_simulations_reads_and_says_what_plot_is_missing(tmp_path):
    legacy = tmp_path / "legacy.h5"
    shutil.copy(ROOT / "tests" / "data" / "legacy_hardening_case2.h5", legacy)
    result = store.read(legacy)
    assert result.simulations == ()
    assert missing_data(result, "time_history") == "no simulation (simulations:)"
    for kind in ("time_history", "hub_path"):
        run = CliRunner().invoke(cli, ["plot", str(legacy), "--kind", kind, "-o",
                                       str(tmp_path / "plots")])
        assert run.exit_code == 1
        assert f"--kind {kind}: legacy.h5 has no simulation (simulations:)" in run.output
    assert not (tmp_path / "plots").exists() or not list((tmp_path / "plots").iterdir())


# ------------------------------------------------------------------------------ figures
def test_time_history_draws_one_panel_per_dof_in_degrees(model):
    found = a_simulation(model, {"V": 7.9})
    figure = time_history(found, title="study: V = 7.9 m/s\ns1")
    axes = figure.axes
    assert len(axes) == 2
    assert [ax.get_ylabel() for ax in axes] == ["$\\theta$ [deg]", "$\\psi$ [deg]"]
    assert axes[-1].get_xlabel() == "t [s]"
    assert axes[0].get_title() == "study: V = 7.9 m/s\ns1"
    for k, ax in enumerate(axes):
        (line,) = [x for x in ax.get_lines() if len(x.get_xdata()) > 2]
        np.testing.assert_array_equal(line.get_xdata(), found.time)
        np.testing.assert_allclose(line.get_ydata(), DEG * found.states[:, k])


def test_time_history_and_hub_path_of_another_model_and_given_axes():
    """No state names assumed: the oscillators model's dofs q1..q3 in m, its hub (q1, q2);
    drawn on axes the caller gives."""
    from whirl_cli.plots.key import new_figure

    model = get_model("oscillators")
    params = model.parameter_vector({})
    found = simulate.simulation(model, params, np.r_[0.1, 0.0, -0.05, np.zeros(3)], 1.0, 101)
    figure = new_figure()
    axes = figure.subplots(3, 1)
    assert time_history(found, axes=list(axes)) is figure
    assert [ax.get_ylabel() for ax in axes] == ["q1 [m]", "q2 [m]", "q3 [m]"]
    assert axes[0].get_title() == found.name
    single = new_figure().add_subplot()
    time_history(found, states=["dq2"], axes=single)
    assert single.get_ylabel() == "dq2 [m/s]"
    ax = new_figure().add_subplot()
    hub_path(found, ax=ax)
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("hub y [m]", "hub z [m]")
    segments = ax.collections[0].get_segments()
    np.testing.assert_allclose(segments[0][0], found.states[0, :2])


def test_hub_path_draws_the_declared_hub_coloured_by_time_with_its_start(model):
    found = a_simulation(model, {"V": 7.9})
    figure = hub_path(found, title="t")
    ax = figure.axes[0]
    (lines,) = ax.collections
    segments = np.array(lines.get_segments())
    assert segments.shape == (30, 2, 2)
    hub = DEG * np.column_stack([-found.states[:, 1], -found.states[:, 0]])  # (-psi, -theta)
    np.testing.assert_allclose(segments[:, 0], hub[:-1])
    np.testing.assert_allclose(segments[:, 1], hub[1:])
    np.testing.assert_allclose(lines.get_array(), 0.5 * (found.time[:-1] + found.time[1:]))
    markers = {x.get_label(): np.array([x.get_xdata()[0], x.get_ydata()[0]])
               for x in ax.get_lines()}
    np.testing.assert_allclose(markers["start"], hub[0])
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("hub y [deg]", "hub z [deg]")
    assert ax.get_aspect() == 1.0 and ax.get_title() == "t"
    assert figure.axes[1].get_ylabel() == "t [s]"  # the colour bar is time


def test_a_stopped_simulation_says_why_in_the_title(model):
    found = dataclasses.replace(a_simulation(model, {}), status=1, message="a dof beyond")
    assert time_history(found, title="x").axes[0].get_title() == "x\nstopped: a dof beyond"


def test_the_title_names_the_study_its_fixed_and_the_simulation_s_parameters(model):
    captions = Captions("study", (Fixed("K_psi", 0.3, "N m/rad"), Fixed("V", 6.7, "m/s")))
    found = a_simulation(model, {"V": 7.9}, name="pitch")
    assert captions.simulation_title(found) == \
        "study: $K_{\\psi}$ = 0.3 N m/rad, V = 7.9 m/s\npitch"
    plain = a_simulation(model, {}, name="p")
    assert Captions("study").simulation_title(plain) == "study\np"
    assert Captions("study").simulation_title(found) == "study: V = 7.9 m/s\npitch"


def test_compare_finds_a_simulation_that_drifted(model):
    from whirl_cli.output.compare import compare_results

    found = a_simulation(model, {"V": 7.9})
    same = StudyResult("s", "m", (), (), (), simulations=(found,))
    assert compare_results(same, same) == []
    moved = found.states.copy()
    moved[17, 1] += 1e-5 * np.abs(found.states[:, 1]).max()
    other = StudyResult("s", "m", (), (), (), simulations=(
        dataclasses.replace(found, states=moved),))
    (difference,) = compare_results(same, other)
    assert difference.path == "/simulations/s1/states[17, 1]"
    gone = StudyResult("s", "m", (), (), ())
    assert [d.path for d in compare_results(same, gone)] == ["/simulations/s1"]
