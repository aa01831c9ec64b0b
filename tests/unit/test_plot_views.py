"""Plots people can show (issue 17, item 3), checked on the figure objects: titles name the
study and its fixed parameters, slices their study labels, phase legends in parameter order,
axis limits, frequencies in Hz; ``whirl plot`` draws every kind a file has and refuses a kind
it lacks the data for."""

from __future__ import annotations

import math

import h5py
import numpy as np
import pytest
import yaml
from click.testing import CliRunner

from whirl_cli.cli import cli
from whirl_cli.output import store
from whirl_cli.output.provenance import study_parts
from whirl_cli.plots.files import PLOT_KINDS, View, study_figures
from whirl_cli.results import Boundary, Provenance, StudyResult, UnsafeInterval
from whirl_cli.study import validate_text

from ..conftest import ROOT, STUDIES

REFERENCES = ROOT / "tests" / "regression" / "references"
HARDENING = REFERENCES / "hardening_case2.h5"
LINEAR = REFERENCES / "linear_datum_airspeed.h5"


@pytest.fixture(scope="module")
def hardening() -> StudyResult:
    return store.read(HARDENING)


def figures(result, kinds, **view):
    return dict(study_figures(result, tuple(kinds), "x", view=View(**view)))


def test_titles_name_the_study_and_its_fixed_parameters(hardening):
    study = yaml.safe_load(hardening.provenance.study_yaml)
    assert study["parameters"] == {"K_psi": 0.3}  # what the title must say, in N m/rad
    want = f"{study['name']}: $K_{{\\psi}}$ = 0.3 N m/rad"
    drawn = figures(hardening, ("bifurcation", "projections", "period", "phase"))
    assert set(drawn) == {"x_k1_bifurcation.png", "x_k1_projections.png", "x_k1_period.png",
                          "x_k1_periodic_1_phase.png", "x_k1_periodic_3_phase.png",
                          "x_k1_periodic_5_phase.png"}
    assert drawn["x_k1_bifurcation.png"].axes[0].get_title() == want
    assert drawn["x_k1_period.png"].axes[0].get_title() == want
    assert drawn["x_k1_projections.png"]._suptitle.get_text() == want
    assert drawn["x_k1_periodic_3_phase.png"].axes[0].get_title() == f"{want}\nperiodic_3"
    for figure in drawn.values():
        titles = [ax.get_title() for ax in figure.axes]
        assert "k1" not in " ".join(titles).split()  # not the continuation's name


def test_axis_labels_carry_units(hardening):
    drawn = figures(hardening, ("bifurcation", "period", "phase"))
    ax = drawn["x_k1_bifurcation.png"].axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("$K_{\\theta}$ [N m/rad]",
                                                  "$\\theta$ (max) [deg]")
    ax = drawn["x_k1_period.png"].axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("$K_{\\theta}$ [N m/rad]", "period [s]")
    ax = drawn["x_k1_periodic_1_phase.png"].axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("$\\theta$ [deg]", "$\\psi$ [deg]")


def test_a_study_at_datum_is_titled_by_its_name_alone():
    result = store.read(LINEAR)
    (figure,) = figures(result, ("linear",)).values()
    assert figure.axes[0].get_title() == "linear-datum-airspeed"


def test_phase_legends_are_sorted_by_parameter(hardening):
    for name, figure in figures(hardening, ("phase",)).items():
        texts = [t.get_text() for t in figure.axes[0].get_legend().get_texts()]
        values = [float(t.split(" = ")[1].split()[0]) for t in texts]
        assert len(values) >= 2 and values == sorted(values), name


def test_axis_limits_apply_to_every_axes_of_every_figure(hardening):
    drawn = figures(hardening, PLOT_KINDS, xlim=(0.0, 0.3), ylim=(-1.0, 20.0))
    axes = [ax for figure in drawn.values() for ax in figure.axes]
    assert len(axes) >= 9
    for ax in axes:
        assert ax.get_xlim() == (0.0, 0.3) and ax.get_ylim() == (-1.0, 20.0)
    without = figures(hardening, ("bifurcation",))["x_k1_bifurcation.png"].axes[0]
    assert without.get_xlim() != (0.0, 0.3)


def test_frequencies_in_hz_on_request():
    result = store.read(LINEAR)
    with h5py.File(LINEAR) as handle:
        frequency = handle["linear/sweeps/V/frequency"][()]  # rad/s
        eigenvalues = handle["linear/sweeps/V/eigenvalues"][()]
    for hz, factor, unit in ((False, 1.0, "rad/s"), (True, 1 / (2 * math.pi), "Hz")):
        (figure,) = figures(result, ("linear",), hz=hz).values()
        top = figure.axes[0]
        assert top.get_ylabel() == f"frequency [{unit}]"
        drawn = [np.asarray(line.get_ydata()) for line in top.get_lines()
                 if not line.get_label().startswith("_")]  # the modes, not the onset marks
        columns = [k for k in range(eigenvalues.shape[1]) if (eigenvalues[:, k].imag > 0).any()]
        assert len(drawn) == len(columns) == 2
        for ys, k in zip(drawn, columns, strict=True):
            upper = eigenvalues[:, k].imag > 0
            np.testing.assert_allclose(ys[upper], frequency[upper, k] * factor, rtol=1e-12)


# -- slices labelled by the study -------------------------------------------------------------
def labelled_boundary_result() -> StudyResult:
    """The linear boundary study with two of its five slices labelled, and a boundary over its
    slices (no loci: only the slices and their labels matter here)."""
    text = (STUDIES / "boundary_linear.yaml").read_text().replace(
        "slices: [0.4, 0.3, 0.2, 0.05, 0.037]",
        "slices: [0.4, {value: 0.3, label: thesis case 2}, 0.2, 0.05,\n"
        "             {value: 0.037, label: near the bubble}]")
    assert "thesis case 2" in text
    boundary = Boundary("boundary", ("K_theta", "K_psi"), ("N m/rad", "N m/rad"), "loci",
                        {"hopf_0a": ("hopf", np.array([[0.1, 0.0], [0.2, 0.5]]))},
                        (UnsafeInterval(0.3, 0.1, 0.2, "flutter"),), (),
                        (0.4, 0.3, 0.2, 0.05, 0.037))
    return StudyResult("boundary-linear", "classical_poly", (), (), (), boundaries=(boundary,),
                       provenance=study_parts(Provenance(study_yaml=text), validate_text(text)))


def test_slices_are_labelled_by_the_study():
    drawn = figures(labelled_boundary_result(), ("boundary",))
    ax = drawn["x_boundary_boundary.png"].axes[0]
    # labels are placed bottom to top: K_psi = 0.037, 0.05, 0.2, 0.3, 0.4
    assert [t.get_text() for t in ax.texts] == ["near the bubble", "case 4", "case 3",
                                                "thesis case 2", "case 1"]
    assert ax.get_title() == "boundary-linear"  # K_psi, its only override, is varied here
    overhang = drawn["x_boundary_slice_1_overhang.png"].axes[0]
    assert overhang.get_title() == "boundary-linear\nthesis case 2: $K_{\\psi}$ = 0.3 N m/rad"
    assert drawn["x_boundary_slice_0_overhang.png"].axes[0].get_title() == \
        "boundary-linear\ncase 1: $K_{\\psi}$ = 0.4 N m/rad"


def test_titles_do_not_depend_on_todays_schema(hardening, tmp_path):
    """A stored study today's schema rejects (a key it no longer knows) changes no title: the
    fixed parameters come from the provenance stored with the result."""
    path = store.write(hardening, tmp_path / "r.h5")
    with h5py.File(path, "r+") as handle:
        handle.attrs["study_yaml"] = hardening.provenance.study_yaml + "retired_key: 1\n"
    stored = store.read(path)
    assert "retired_key" in stored.provenance.study_yaml
    figure = figures(stored, ("bifurcation",))["x_k1_bifurcation.png"]
    assert figure.axes[0].get_title() == "hardening-case2: $K_{\\psi}$ = 0.3 N m/rad"


# -- whirl plot: every kind the file has; a missing kind is an error --------------------------
def test_plot_without_kind_draws_every_kind_the_file_has(tmp_path):
    result = CliRunner().invoke(cli, ["plot", str(HARDENING), "-o", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        f"hardening_case2_{name}" for name in (
            "k1_bifurcation.png", "k1_projections.png", "k1_period.png",
            "k1_periodic_1_phase.png", "k1_periodic_3_phase.png", "k1_periodic_5_phase.png",
            "law_theta.png"))


@pytest.mark.parametrize("kind, missing", [
    ("linear", "no linear sweep"),
    ("boundary", "no stability boundary"),
])
def test_a_kind_without_data_is_an_error_naming_what_is_missing(tmp_path, kind, missing):
    result = CliRunner().invoke(cli, ["plot", str(HARDENING), "-o", str(tmp_path),
                                      "--kind", "bifurcation", "--kind", kind])
    assert result.exit_code == 1
    assert result.stderr.startswith(f"--kind {kind}: hardening_case2.h5 has {missing}")
    assert len(result.stderr.splitlines()) == 1
    assert list(tmp_path.iterdir()) == []  # nothing drawn, not even the kind it has


def test_phase_without_orbits_is_an_error(tmp_path):
    result = CliRunner().invoke(cli, ["plot", str(LINEAR), "-o", str(tmp_path),
                                      "--kind", "phase", "--kind", "period"])
    assert result.exit_code == 1
    lines = result.stderr.splitlines()
    assert lines[0].startswith("--kind phase: linear_datum_airspeed.h5 has no stored orbits")
    assert lines[1].startswith("--kind period: linear_datum_airspeed.h5 has no periodic")


@pytest.mark.parametrize("option", [["--xlim", "1", "1"], ["--ylim", "0", "inf"]])
def test_limits_must_be_two_different_finite_numbers(tmp_path, option):
    result = CliRunner().invoke(cli, ["plot", str(HARDENING), "-o", str(tmp_path), *option])
    assert result.exit_code == 2 and "expected two different finite numbers" in result.output
