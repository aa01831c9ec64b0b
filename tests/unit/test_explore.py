"""A continuation's ``explore:``: the settled motion classified by simulation at listed values
(whirl_cli.continuation.recipes.explorations), stored, compared and drawn.

The classification is checked against AUTO's own answer for hardening case 2 (classical
model): at K1 = 0.24 AUTO continues a stable limit cycle (its period from the regression
reference file), at K1 = 0.45 the trivial equilibrium is stable and no cycle exists (the fold
of cycles is below 0.38)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import h5py
import numpy as np
import pytest

from whirl_cli.analysis import motion
from whirl_cli.continuation import recipes
from whirl_cli.errors import StudyError, WhirlError
from whirl_cli.output import compare, store
from whirl_cli.plots.files import PLOT_KINDS, missing_data, plot_names, study_figures
from whirl_cli.plots.motion import KIND_COLOURS, orbit_diagram, poincare_plot, spectrum_plot
from whirl_cli.results import ContinuationResult, Exploration, MotionKind, StudyResult
from whirl_cli.study import validate_text

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "tests" / "regression" / "references" / "hardening_case2.h5"
STATES = ("theta", "psi", "dtheta", "dpsi")
UNITS = ("rad", "rad", "rad/s", "rad/s")


def hardening_study(explore: str = "[0.24, 0.45]", extra: str = ""):
    """studies/thesis_ch3/hardening_case2.yaml with ``explore`` (and ``extra`` keys)."""
    text = (ROOT / "studies" / "thesis_ch3" / "hardening_case2.yaml").read_text()
    return text.replace("    branch_points: true\n",
                        f"    branch_points: true\n    explore: {explore}\n{extra}")


def auto_stable_period(k1: float) -> float:
    """AUTO's period (s) of the stable orbit of its first periodic branch at ``k1``,
    interpolated between the stable points around it."""
    with h5py.File(REFERENCE) as f:
        branch = f["continuations/k1/branches/periodic_1"]
        parameters, period = branch["parameters"][:, 0], branch["period"][:]
        stable = branch["stable"][:]
    rows = np.nonzero(stable & (np.abs(parameters - k1) < 0.02))[0]
    order = np.argsort(parameters[rows])
    return float(np.interp(k1, parameters[rows][order], period[rows][order]))


@pytest.fixture(scope="module")
def explored():
    study = validate_text(hardening_study(), "h.yaml")
    spec = study.continuations[0]
    return recipes.explorations(study.variant(), study.parameter_values(), spec)


# ----------------------------------------------------------------------------- the class
def test_at_autos_stable_cycle_the_motion_is_periodic_at_its_frequency(explored):
    found = explored[0]
    assert (found.value, found.parameter, found.unit) == (0.24, "K_theta", "N m/rad")
    assert found.kind == "periodic", found.evidence
    assert found.multiplicity == 1
    assert found.frequencies[0] == pytest.approx(1.0 / auto_stable_period(0.24), rel=1e-2)
    # the default section: the first dof's rate crossing its mean (0) upwards, at pitch minima
    assert np.all(np.abs(found.section[:, 2]) < 0.05)  # rad/s: 0 within its mean's drift
    assert np.all(found.section[:, 0] < 0)


def test_far_from_cycles_at_a_linearly_stable_value_the_motion_is_an_equilibrium(explored):
    found = explored[1]
    assert found.kind == "equilibrium", found.evidence
    assert found.lyapunov < 0
    assert len(found.frequencies) == 0


def test_explorations_are_the_same_bits_for_any_jobs(explored):
    """Two values side by side in forked processes: every field as one after another."""
    study = validate_text(hardening_study(), "h.yaml")
    forked = recipes.explorations(study.variant(), study.parameter_values(),
                                   study.continuations[0], jobs=2)
    for a, b in zip(explored, forked, strict=True):
        for name in Exploration.__dataclass_fields__:
            x, y = getattr(a, name), getattr(b, name)
            assert (np.array_equal(x, y, equal_nan=x.dtype.kind == "f")
                    if isinstance(x, np.ndarray) else x == y or (x != x and y != y)), name


def test_the_initial_state_is_the_first_dof_at_2_degrees_unless_given():
    study = validate_text(hardening_study("[0.45]"), "h.yaml")
    spec = study.continuations[0]
    assert spec.explore_initial is None
    (found,) = recipes.explorations(study.variant(), study.parameter_values(), spec)
    assert found.initial == pytest.approx([np.radians(2.0), 0.0, 0.0, 0.0])
    study = validate_text(hardening_study("[0.45]", "    explore_initial: {psi: 1, dtheta: 10}\n"),
                          "h.yaml")
    (found,) = recipes.explorations(study.variant(), study.parameter_values(),
                                     study.continuations[0])
    assert found.initial == pytest.approx([0.0, np.radians(1.0), np.radians(10.0), 0.0])


def test_a_failed_classification_is_reported_never_raised(monkeypatch):
    def broken(*_args, **_kwargs):
        raise FloatingPointError("overflow in the field")

    monkeypatch.setattr(motion, "classify_model", broken)
    study = validate_text(hardening_study("[0.3]"), "h.yaml")
    (found,) = recipes.explorations(study.variant(), study.parameter_values(),
                                     study.continuations[0])
    assert found.kind == "diverged"
    assert "overflow in the field" in found.evidence
    assert found.section.shape == (0, 4)


# ----------------------------------------------------------------------------- bad input
def problems(text: str) -> list[str]:
    with pytest.raises(StudyError) as caught:
        validate_text(text, "h.yaml")
    return caught.value.message.splitlines()


def test_an_explored_value_outside_the_range_is_refused():
    assert problems(hardening_study("[0.24, 0.6]")) == [
        "h.yaml:18: continuations[0].explore[1]: 0.6 is outside the range [-0.3, 0.5]"]


def test_an_unknown_state_in_explore_initial_or_explore_section_is_refused():
    found = problems(hardening_study("[0.24]", "    explore_initial: {theta: 2, phi: 1}\n"
                                               "    explore_section: beta\n"))
    assert len(found) == 2
    assert found[0].startswith("h.yaml:19: continuations[0].explore_initial.phi: expected one "
                               "of theta, psi, dtheta, dpsi")
    assert found[1].startswith("h.yaml:20: continuations[0].explore_section: expected one of")


def test_explore_must_be_numbers_and_its_transient_positive():
    assert "explore" in problems(hardening_study("[fast]"))[0]
    assert "explore_transient" in problems(hardening_study("[0.2]",
                                                           "    explore_transient: 0\n"))[0]


# ----------------------------------------------------------------------------- HDF5
def exploration(value: float, kind: str, section: np.ndarray, frequencies=(4.4,)) -> Exploration:
    return Exploration(value, "K_theta", "N m/rad", STATES, UNITS,
                       np.array([0.035, 0, 0, 0]), kind, 0.002, 0.001,
                       np.asarray(frequencies, float), section, 1.1,
                       1 if kind == "periodic" else 0, np.array([4.4, 8.8]), 1e-3,
                       f"{kind}: made up")


def sample_explorations() -> tuple[Exploration, ...]:
    cycle = np.tile([[-0.1, 0.02, 0.0, 0.5]], (5, 1))
    return (exploration(0.24, MotionKind.PERIODIC, cycle),
            exploration(0.45, MotionKind.EQUILIBRIUM, np.zeros((0, 4)), ()),
            exploration(0.3, MotionKind.CHAOTIC,
                        np.random.default_rng(1).normal(size=(30, 4)) * 0.05, (4.0, 2.1, 6.0)))


def result_of(explorations, branches=()) -> StudyResult:
    return StudyResult("s", "classical", (ContinuationResult(
        "k1", "one-parameter", branches, (), explorations=explorations),), (), ())


def test_explorations_round_trip_through_the_file_with_units(tmp_path):
    path = store.write(result_of(sample_explorations()), tmp_path / "x.h5")
    back = store.read(path).continuations[0].explorations
    assert len(back) == 3
    for a, b in zip(sample_explorations(), back, strict=True):
        for name in Exploration.__dataclass_fields__:
            x, y = getattr(a, name), getattr(b, name)
            if isinstance(x, np.ndarray):
                assert np.array_equal(x, y) and np.shape(x) == np.shape(y), name
            else:
                assert x == y and type(x) is type(y), name
    with h5py.File(path) as f:
        group = f["continuations/k1/explorations/0"]
        assert group["lyapunov"].attrs["units"] == "1/s"
        assert group["lyapunov_error"].attrs["units"] == "1/s"
        assert group["frequencies"].attrs["units"] == "Hz"
        assert group["peaks"].attrs["units"] == "Hz"
        assert group["value"].attrs["units"] == "N m/rad"
        assert list(group["section"].attrs["units"]) == list(UNITS)
        assert list(group["section"].attrs["names"]) == list(STATES)
        assert group.attrs["kind"] == "periodic"


def test_a_file_without_explorations_still_reads(tmp_path):
    path = store.write(result_of(()), tmp_path / "old.h5")
    with h5py.File(path) as f:
        assert "explorations" not in f["continuations/k1"]
    assert store.read(path).continuations[0].explorations == ()


def test_compare_takes_classes_exactly_and_frequencies_to_a_tolerance():
    a = result_of(sample_explorations())
    assert compare.compare_results(a, a) == []
    first = sample_explorations()[0]
    close = replace(first, frequencies=first.frequencies * (1 + 1e-5))
    assert compare.compare_results(a, result_of((close,) + sample_explorations()[1:])) == []
    changed = (replace(first, kind="quasi-periodic"),) + sample_explorations()[1:]
    (difference,) = compare.compare_results(a, result_of(changed))
    assert difference.path == "/continuations/k1/explorations/0/@kind"
    drifted = (replace(first, frequencies=first.frequencies * 1.01),) + sample_explorations()[1:]
    (difference,) = compare.compare_results(a, result_of(drifted))
    assert difference.path == "/continuations/k1/explorations/0/frequencies"
    assert compare.compare_results(a, result_of(sample_explorations()[:2]))


# ----------------------------------------------------------------------------- plots
def test_poincare_plot_draws_every_value_in_degrees_with_its_class():
    figure = poincare_plot(ContinuationResult("k1", "one-parameter", (), (),
                                              explorations=sample_explorations()))
    (ax,) = figure.axes
    assert len(ax.collections) == 3  # one scatter per value, the equilibrium's empty
    assert np.allclose(ax.collections[0].get_offsets(),
                       np.degrees(np.tile([[-0.1, 0.02]], (5, 1))))
    assert len(ax.collections[1].get_offsets()) == 0
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "K_theta = 0.24: periodic", "K_theta = 0.45: equilibrium", "K_theta = 0.3: chaotic"]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("$\\theta$ [deg]", "$\\psi$ [deg]")


def test_orbit_diagram_draws_section_values_over_the_branches(continuation):  # noqa: F811
    drawn = replace(continuation, explorations=sample_explorations())
    figure = orbit_diagram(drawn)
    (ax,) = figure.axes
    dots = {line.get_color(): line for line in ax.lines if line.get_marker() == "o"
            and line.get_linestyle() in ("None", "none")}
    periodic = dots[KIND_COLOURS["periodic"]]
    assert periodic.get_xdata() == pytest.approx([0.24] * 5)
    assert periodic.get_ydata() == pytest.approx([np.degrees(-0.1)] * 5)
    chaotic = dots[KIND_COLOURS["chaotic"]]
    assert len(chaotic.get_xdata()) == 30
    # the equilibrium has no section points: a triangle on the parameter axis
    (triangle,) = [line for line in ax.lines if line.get_marker() == "^"]
    assert list(triangle.get_xdata()) == [0.45]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "stable equilibrium" in labels  # the bifurcation diagram under it
    assert {"periodic (simulation)", "equilibrium (simulation)",
            "chaotic (simulation)"} <= set(labels)
    assert ax.get_xlabel() == "$K_{\\theta}$ [N m/rad]"
    alone = orbit_diagram(drawn, branches=False).axes[0]
    assert "stable equilibrium" not in [t.get_text() for t in alone.get_legend().get_texts()]


def test_spectrum_plot_draws_the_frequencies_found_per_value():
    figure = spectrum_plot(ContinuationResult("k1", "one-parameter", (), (),
                                              explorations=sample_explorations()))
    (ax,) = figure.axes
    lines = {line.get_label(): line for line in ax.lines}
    assert lines["periodic"].get_xdata() == pytest.approx([0.24])
    assert lines["periodic"].get_ydata() == pytest.approx([4.4])
    assert lines["chaotic"].get_ydata() == pytest.approx([4.0, 2.1, 6.0])
    assert len(lines["spectral peaks"].get_xdata()) == 6
    assert ax.get_ylabel() == "frequency [Hz]"


def test_the_study_plot_kinds_draw_files_or_say_what_is_missing(continuation):  # noqa: F811
    assert {"poincare", "spectrum", "orbit_diagram"} <= set(PLOT_KINDS)
    without = StudyResult("s", "classical", (continuation,), (), ())
    assert "explore" in missing_data(without, "orbit_diagram")
    result = result_of(sample_explorations(), continuation.branches)
    assert missing_data(result, "poincare") == ""
    kinds = ("poincare", "spectrum", "orbit_diagram")
    assert plot_names(result, kinds, "run") == [
        "run_k1_poincare.png", "run_k1_spectrum.png", "run_k1_orbit_diagram.png"]
    for _, figure in study_figures(result, kinds, "run"):
        assert figure.axes[0].get_title().startswith("s")


def test_a_continuation_without_explorations_is_a_clear_error(continuation):  # noqa: F811
    with pytest.raises(WhirlError, match="no explorations"):
        poincare_plot(continuation)


def test_the_new_study_explores_values_inside_its_range():
    from whirl_cli.study import load_study

    study = load_study(ROOT / "studies" / "gimballed" / "explore_combined_case2_soft.yaml")
    (spec,) = study.continuations
    assert spec.explore and all(spec.range[0] <= v <= spec.range[1] for v in spec.explore)
    assert {"orbit_diagram", "poincare"} <= set(study.plots)
