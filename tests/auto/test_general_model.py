"""A general model end to end (issue 14): the 6-state oscillators test model, whose mass matrix
is full, through ``whirl run`` on the real AUTO, against closed forms and time simulation; and
the same continuation with every typical amplitude 100 times smaller.

Closed forms (``models/builtin/oscillators.model.yaml``; datum k = m = gamma = 1, beta = 0.05): mode
j = 1, 2, 3 of M = m [[2, 1, 0], [1, 2, 1], [0, 1, 2]] has the shape phi_j = (sin(i j pi/4))_i,
mu_j = 2 + 2 cos(j pi/4), omega_j^2 = k/(m mu_j), and its Hopf point in alpha lies at
alpha_j = -beta omega_j^2 with the period 2 pi/omega_j. Near it, first-order averaging on mode j
(the modal equation eta'' + (alpha - alpha_j) eta' + omega_j^2 eta + g_j eta^2 eta' = 0,
g_j = gamma sum_i phi_ji^4 / (m phi_j^T M0 phi_j)) gives the limit cycle eta = A cos(omega_j t)
with A^2 = 4 (alpha_j - alpha) / g_j, so q_i reaches A |phi_ji|.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from click.testing import CliRunner

from whirl_cli import models, publish
from whirl_cli.analysis.simulate import integrate
from whirl_cli.auto import toolchain
from whirl_cli.auto.codegen import fortran_source, source_key
from whirl_cli.cli import cli
from whirl_cli.models import BUILTIN
from whirl_cli.output import store
from whirl_cli.pipeline import run_study
from whirl_cli.plots import files
from whirl_cli.plots.diagrams import bifurcation_diagram, phase_plane, projections_figure
from whirl_cli.results import BranchKind, PointType
from whirl_cli.study import validate_text

RANGE = (-0.1, 0.1)
WIDTH = RANGE[1] - RANGE[0]
BETA = 0.05
MASS = np.array([[2.0, 1.0, 0.0], [1.0, 2.0, 1.0], [0.0, 1.0, 2.0]])
STATES = ("q1", "q2", "q3", "dq1", "dq2", "dq3")
DETUNING = 1e-3  # alpha_j - alpha where the family is checked against averaging


def mode(j: int) -> tuple[float, np.ndarray, float]:
    """(alpha_j, phi_j, period_j) of mode j (module doc)."""
    mu = 2.0 + 2.0 * math.cos(j * math.pi / 4)
    return -BETA / mu, np.sin(np.arange(1, 4) * j * math.pi / 4), 2 * math.pi * math.sqrt(mu)


def averaged_amplitude(j: int, alpha: float) -> np.ndarray:
    """(3,) max of q1, q2, q3 over the limit cycle of mode j at ``alpha`` (module doc)."""
    alpha_j, phi, _ = mode(j)
    g = np.sum(phi**4) / (phi @ MASS @ phi)
    return math.sqrt(4 * (alpha_j - alpha) / g) * np.abs(phi)


HOPFS = [mode(j)[0] for j in (1, 2, 3)]  # -0.0146447, -0.025, -0.0853553
ORBITS_AT = [h - DETUNING for h in HOPFS] + [-0.05]

def study_text(model: str = "oscillators") -> str:
    """alpha from 0.1 down to -0.1, periodic families, orbits stored just below every Hopf
    point and at -0.05, every plot kind but linear and boundary, cross-checks."""
    return f"""\
name: oscillators-alpha
model: {model}
continuations:
  - name: alpha
    type: one-parameter
    parameter: alpha
    start: {RANGE[1]}
    range: [{RANGE[0]}, {RANGE[1]}]
    periodic: true
    orbits_at: [{", ".join(f"{v!r}" for v in ORBITS_AT)}]
plots: [bifurcation, projections, period, phase]
plot_state: q2
cross_check: true
auto: {{step_max: 0.02}}
"""


@pytest.fixture(scope="module")
def cli_run(tmp_path_factory):
    """``whirl run`` of the study: (output path, CLI output, what each figure drawn showed:
    file name -> [(title, x label, y label) per axes])."""
    folder = tmp_path_factory.mktemp("cli")
    (folder / "oscillators.yaml").write_text(study_text())
    output = folder / "out" / "oscillators.h5"
    drawn: dict[str, list[tuple[str, str, str]]] = {}
    original = files._png
    names = iter(())

    def recording(figure, dpi):
        drawn[next(names)] = [(ax.get_title(), ax.get_xlabel(), ax.get_ylabel())
                              for ax in figure.axes]
        return original(figure, dpi)

    def render(result, kinds, stem, state=None, *args):
        nonlocal names
        names = iter(files.plot_names(result, kinds, stem, state))
        return rendering(result, kinds, stem, state, *args)

    def in_turn(function, count, jobs):  # drawn here: forked workers would record in their
        return [function(k) for k in range(count)]  # own copy of ``drawn``

    rendering = files.render_tasks
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(files, "_png", recording)
        patch.setattr(files, "render_tasks", render)
        patch.setattr(publish, "forked_map", in_turn)
        done = CliRunner().invoke(cli, ["run", str(folder / "oscillators.yaml"), "-o",
                                        str(output), "--jobs", "2"])
    assert done.exit_code == 0, done.output
    return output, done.output, drawn


@pytest.fixture(scope="module")
def result(cli_run):
    return store.read(cli_run[0])


@pytest.fixture(scope="module")
def continuation(result):
    (found,) = result.continuations
    return found


@pytest.fixture(scope="module")
def again(tmp_path_factory):
    """The same study through run_study (a second, independent run)."""
    return run_study(validate_text(study_text()), tmp_path_factory.mktemp("again"), jobs=2)


def branch(continuation, name: str):
    return next(b for b in continuation.branches if b.name == name)


def test_full_mass_fortran_compiles_and_solves_with_whirl_solve(cli_run):
    model = models.get_model("oscillators")
    executable = toolchain.compile_equations(lambda: fortran_source(model), model.name,
                                             source_key=source_key(model))
    assert not executable.compiled  # the program the run used
    source = (executable.path.parent / f"{model.name}.f90").read_text()
    assert "(M full)" in source and "SUBROUTINE WHIRL_SOLVE" in source
    assert source.count("CALL WHIRL_SOLVE") == 3  # accelerations, DFDU, DFDP


def test_hopf_points_at_the_closed_form(continuation):
    hopfs = sorted((p for p in continuation.special_points if p.point_type == PointType.HB),
                   key=lambda p: -p.parameters[0])
    assert [p.branch for p in hopfs] == ["main_down"] * 3
    for j, point in enumerate(hopfs, 1):
        alpha_j, _, period = mode(j)
        assert abs(point.parameters[0] - alpha_j) < 1e-6 * WIDTH  # measured <= 5e-10
        assert point.period == pytest.approx(period, rel=1e-7)
        assert np.all(point.state == 0.0)


def test_a_supercritical_family_from_every_hopf_point(continuation):
    """gamma > 0: each Hopf point is supercritical (l1 < 0 and the family on the side where the
    mode is unstable, alpha < alpha_j); the softest mode's cycles are stable, the others'
    unstable (the softest mode grows at the origin too). No other special points."""
    hopfs = sorted((p for p in continuation.special_points if p.point_type == PointType.HB),
                   key=lambda p: -p.parameters[0])
    assert len(continuation.special_points) == 3
    for j, point in enumerate(hopfs, 1):
        assert point.criticality == "supercritical" and point.lyapunov < 0 and not point.note
        family = branch(continuation, f"periodic_{j}")
        assert family.kind == BranchKind.PERIODIC and family.status == "ok"
        assert str(family.origin) == f"HB at alpha = {point.parameters[0]:.6g} on main_down"
        assert family.end == "range" and family.parameters[-1, 0] == pytest.approx(RANGE[0])
        assert np.all(family.parameters[1:, 0] < point.parameters[0])
        known = family.stability_known
        assert np.all(family.stable[known]) == (j == 1) and np.any(known)


def test_families_near_their_hopf_points_against_averaging_and_l1(continuation):
    """At alpha_j - 1e-3 (an orbits_at value) every dof's maximum matches first-order
    averaging to 1e-3 relative (measured <= 2.5e-4), and so does the radius that whirl's first
    Lyapunov coefficient gives: with Re lambda = (alpha - alpha_j)/2, |z|^2 = -Re lambda /
    (l1 omega) and q_i's amplitude 2 |z| |v_i| (v the unit critical eigenvector)."""
    model = models.get_model("oscillators")
    hopfs = sorted((p for p in continuation.special_points if p.point_type == PointType.HB),
                   key=lambda p: -p.parameters[0])
    for j, point in enumerate(hopfs, 1):
        family = branch(continuation, f"periodic_{j}")
        alpha = mode(j)[0] - DETUNING
        (row,) = np.flatnonzero(np.abs(family.parameters[:, 0] - alpha) < 1e-9 * WIDTH)
        assert family.point_type[row] == PointType.UZ
        auto = family.state_max[row, :3]
        expected = averaged_amplitude(j, alpha)
        np.testing.assert_allclose(auto, expected, rtol=1e-3, atol=1e-9)
        omega = 2 * math.pi / point.period
        jacobian = model.jacobian_numpy(point.state, model.parameter_vector(
            {"alpha": point.parameters[0]}))
        values, vectors = np.linalg.eig(jacobian)
        vector = vectors[:, np.argmin(np.abs(values - 1j * omega))]
        radius = math.sqrt(DETUNING / 2 / (-point.lyapunov * omega))
        np.testing.assert_allclose(2 * radius * np.abs(vector[:3]) / np.linalg.norm(vector),
                                   expected, rtol=1e-3, atol=1e-9)


@pytest.mark.parametrize("start", ["origin", "outside"])
def test_stable_cycle_is_where_simulation_settles(continuation, start):
    """At alpha = -0.05 the modes 1 and 2 grow at the origin; started there (q1 = 1e-3, which
    excites both) or 20 % outside AUTO's cycle, LSODA settles on AUTO's stable cycle of mode 1:
    the maximum of every dof over the last two periods within 1e-3 (measured <= 1.5e-4)."""
    model = models.get_model("oscillators")
    family = branch(continuation, "periodic_1")
    (orbit,) = [o for o in family.orbits if abs(o.parameters[0] + 0.05) < 1e-6 * WIDTH]
    assert family.stable[orbit.index] and family.stability_known[orbit.index]
    y0, periods = ((np.array([1e-3, 0, 0, 0, 0, 0]), 200) if start == "origin"
                   else (1.2 * orbit.states[0], 30))
    time, states = integrate(model, model.parameter_vector({"alpha": orbit.parameters[0]}), y0,
                             periods * orbit.period, samples=periods * 400)
    last = time >= (periods - 2) * orbit.period
    np.testing.assert_allclose(states[last, :3].max(axis=0), family.state_max[orbit.index, :3],
                               rtol=1e-3)


def test_result_file_reads_back_with_the_model_names(result, continuation):
    assert result.model == "oscillators_poly" and result.study_name == "oscillators-alpha"
    for b in continuation.branches:
        assert b.state_names == STATES
        assert b.state_units == ("m",) * 3 + ("m/s",) * 3
        assert b.parameter_names == ("alpha",) and b.parameter_units == ("1/s",)
        assert b.eigenvalues.shape == (len(b), 6)
    assert [b.name for b in continuation.branches] == [
        "main_down", "periodic_1", "periodic_2", "periodic_3"]


def test_cross_checks_pass(cli_run, continuation):
    checks = continuation.cross_checks
    assert checks and all(c.passed for c in checks)
    assert {c.branch for c in checks if c.kind == "orbit"} == {"periodic_1"}
    assert all(c.state in STATES for c in checks)
    assert f"cross-checks by time simulation: {len(checks)} of {len(checks)} passed" \
        in cli_run[1]


def test_plots_drawn_with_the_model_states(cli_run):
    """The files, and what whirl run drew in them: the bifurcation diagram of the study's
    plot_state q2, six projections q1..dq3, the period, and phase planes q2 vs q1."""
    output, _, drawn = cli_run
    stem = "oscillators_alpha"
    expected = sorted([f"{stem}_bifurcation.png", f"{stem}_projections.png", f"{stem}_period.png",
                       *(f"{stem}_periodic_{j}_phase.png" for j in (1, 2, 3))])
    assert sorted(drawn) == sorted(p.name for p in output.parent.glob("*.png")) == expected
    # titled by the study (it fixes no parameter), not by the continuation (issue 17, item 3)
    title = "oscillators-alpha"
    assert drawn[f"{stem}_bifurcation.png"] == [(title, r"$\alpha$ [1/s]", "q2 (max) [m]")]
    panels = drawn[f"{stem}_projections.png"]
    assert [y for _, _, y in panels] == [f"{s} (max) [{'m' if len(s) == 2 else 'm/s'}]"
                                         for s in STATES]
    assert drawn[f"{stem}_period.png"] == [(title, r"$\alpha$ [1/s]", "period [s]")]
    for j in (1, 2, 3):
        assert drawn[f"{stem}_periodic_{j}_phase.png"] == [(f"{title}\nperiodic_{j}",
                                                            "q1 [m]", "q2 [m]")]
    for path in output.parent.glob("*.png"):
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_bifurcation_diagram_of_the_first_dof_by_default(continuation):
    ax = bifurcation_diagram(continuation).axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("$\\alpha$ [1/s]", "q1 (max) [m]")
    hopf = next(line for line in ax.lines if line.get_marker() == "s")
    np.testing.assert_allclose(sorted(hopf.get_xdata()), sorted(HOPFS), atol=1e-6 * WIDTH)
    np.testing.assert_array_equal(hopf.get_ydata(), 0.0)
    stable = [line for line in ax.lines if line.get_color() == "blue"]
    family = branch(continuation, "periodic_1")
    assert len(stable) == 1
    np.testing.assert_allclose(stable[0].get_ydata().max(), family.state_max[:, 0].max())
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["stable equilibrium", "unstable equilibrium", "stable periodic",
                      "unstable periodic", "Hopf (HB)"]
    axes = projections_figure(continuation).axes
    assert [a.get_ylabel().split(" ")[0] for a in axes] == list(STATES)
    plane = phase_plane(family).axes[0]
    assert (plane.get_xlabel(), plane.get_ylabel()) == ("q1 [m]", "q2 [m]")
    assert len(plane.lines) == len(family.orbits) > files.PHASE_ORBITS
    assert len(files.phase_labels(family)) == files.PHASE_ORBITS


def test_compare_two_runs_agree(cli_run, again, tmp_path):
    second = store.write(again, tmp_path / "again.h5")
    done = CliRunner().invoke(cli, ["compare", str(cli_run[0]), str(second)])
    assert done.exit_code == 0, done.output


def test_typical_amplitudes_scale_nothing_physical(again, tmp_path):
    """The same family declared with every typical amplitude 100 times smaller (AUTO's state
    is q / amplitude, so AUTO sees states 100 times larger): every special point is the same
    (type, alpha to 1e-6 of the range, state, period, l1, criticality). Amplitude thresholds
    are in typical amplitudes, so the families now stop at auto.max_amplitude (1.5) typical
    amplitudes, 1.5 cm instead of the range end; up to there they match averaging as before."""
    text = (BUILTIN / "oscillators.model.yaml").read_text()
    text = text.replace("name: oscillators", "name: oscillators_small")
    for k in (1, 2, 3):
        text = text.replace(f"stiffness: k{k}}}", f"stiffness: k{k}, amplitude: 0.01}}")
    assert text.count("amplitude: 0.01") == 3
    (tmp_path / "small.model.yaml").write_text(text)
    small = run_study(validate_text(study_text(str(tmp_path / "small.model.yaml"))), tmp_path,
                      jobs=2)
    assert small.model == "oscillators_small_poly"
    ours, theirs = again.continuations[0], small.continuations[0]
    assert len(ours.special_points) == len(theirs.special_points) == 3
    for a, b in zip(ours.special_points, theirs.special_points, strict=True):
        assert (a.branch, a.type_name, a.criticality, a.status) == \
            (b.branch, b.type_name, b.criticality, b.status)
        assert abs(a.parameters[0] - b.parameters[0]) < 1e-6 * WIDTH
        np.testing.assert_allclose(a.state, b.state, atol=1e-12)
        assert a.period == pytest.approx(b.period, rel=1e-9)
        assert a.lyapunov == pytest.approx(b.lyapunov, rel=1e-9)
    for j in (1, 2, 3):
        grown = branch(theirs, f"periodic_{j}")
        assert grown.end == "amplitude bound" and grown.status == "ok"
        reach = np.abs(grown.state_max[-1, :3]).max() / 1e-2
        assert reach == pytest.approx(1.5, rel=1e-3)
        # from 2 mm on: 2e-7 below the Hopf point, where its error (1e-10) is 5e-4 of the
        # detuning (the amplitude goes with its square root)
        for row in np.flatnonzero(grown.state_max[:, :3].max(axis=1) > 2e-3):
            np.testing.assert_allclose(grown.state_max[row, :3], averaged_amplitude(
                j, grown.parameters[row, 0]), rtol=2e-3, atol=1e-9)
        assert branch(ours, f"periodic_{j}").end == "range"


def test_whirl_plot_draws_the_stored_plot_state_or_the_one_asked(cli_run, tmp_path, monkeypatch):
    ylabels: list[str] = []
    original = files._png

    def recording(figure, dpi):
        ylabels.append(figure.axes[0].get_ylabel())
        return original(figure, dpi)

    monkeypatch.setattr(files, "_png", recording)
    runner, output = CliRunner(), str(cli_run[0])
    for extra, label in (((), "q2 (max) [m]"), (("--state", "dq1"), "dq1 (max) [m/s]")):
        done = runner.invoke(cli, ["plot", output, "--kind", "bifurcation", "-o",
                                   str(tmp_path), *extra])
        assert done.exit_code == 0, done.output
        assert ylabels.pop() == label
    done = runner.invoke(cli, ["plot", output, "--state", "theta", "-o", str(tmp_path)])
    assert done.exit_code == 1
    assert "--state theta: not a state of oscillators.h5 (states: dq1, dq2, dq3, q1, q2, q3)" \
        in done.output


def test_whirl_models_lists_every_family():
    """Not only the shipped variants: a study may name any family (the states plot_state takes
    and the typical amplitudes max_amplitude counts in are read off this list)."""
    done = CliRunner().invoke(cli, ["models"])
    assert done.exit_code == 0, done.output
    assert done.output.index("classical_poly:") < done.output.index("oscillators_poly:")
    assert "q1 [m] (typical amplitude 1 m, stiffness k1)" in done.output
    assert "states: q1 [m], q2 [m], q3 [m], dq1 [m/s], dq2 [m/s], dq3 [m/s]" in done.output
