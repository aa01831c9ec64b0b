"""Linear sweeps in multiples of the datum and the ``damping_multiples`` plot kind (issue 17,
item 2; thesis figs. 3.9-3.11), without AUTO: the stored absolute values are multiples x
datum, the datum travels through the HDF5 mapping with its unit, older files still read and
draw, the figure has one line per parameter with the right labels, and bad input is refused
with ``file:line: key: reason``.

Expected damping values are models.md 4's sensitivity table (minimum modal damping ratio at
the datum airspeed, one parameter scaled), not whirl's output.
"""

from __future__ import annotations

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

from whirl_cli.analysis import linear
from whirl_cli.cli import cli
from whirl_cli.models import get_model
from whirl_cli.output import store
from whirl_cli.pipeline import run_study
from whirl_cli.plots.files import missing_data, study_figures
from whirl_cli.plots.linear import damping_multiples_plot, least_damped
from whirl_cli.study import StudyError, validate_text

from ..conftest import ROOT, STUDIES

CLASSICAL = get_model("classical")
MULTIPLES = np.array([0.5, 1.0, 1.5, 2.0, 3.0, 5.0])
#: models.md 4, sensitivity: minimum modal damping ratio at V = 6.7 m/s, one parameter scaled.
SENSITIVITY = {
    "I_y": [.0584, .0230, .0063, -.0039, -.0163, -.0288],
    "C_theta": [.0077, .0230, .0380, .0528, .0819, .1377],
    "a": [.0141, .0230, .0402, .0665, .1500, .4528],
    "I_x": [.0348, .0230, .0106, -.0017, -.0244, -.0582],
    "R": [.0500, .0230, .0578, .2108, .0636, -.1051],
    "Omega": [.0442, .0230, .0138, .0106, .0101, .0111],
}
STUDY = """\
name: multiples
model: classical
linear:
  sweeps:
    - {parameter: I_x, range: [0.5, 5.0], points: 10, multiples: true}
    - {parameter: V, range: [0.0, 10.0], points: 11}
plots: [damping_multiples]
"""


def sensitivity_sweeps():
    return [linear.sweep(CLASSICAL, {}, name, CLASSICAL.parameter(name).default * MULTIPLES)
            for name in SENSITIVITY]


# ------------------------------------------------------------------------------ sweeps
def test_stored_values_are_multiples_times_the_datum(tmp_path):
    study = validate_text(STUDY)
    assert [s.multiples for s in study.linear.sweeps] == [True, False]
    result = run_study(study, tmp_path / "work")
    path = store.write(result, tmp_path / "r.h5")
    multiple, absolute = store.read(path).linear_sweeps
    np.testing.assert_array_equal(multiple.values, np.linspace(0.5, 5.0, 10) * 0.000103)
    assert multiple.datum == 0.000103 and multiple.multiples is True
    np.testing.assert_array_equal(absolute.values, np.linspace(0.0, 10.0, 11))
    assert absolute.datum == 6.7 and absolute.multiples is False
    with h5py.File(path) as handle:
        group = handle["linear/sweeps/I_x"]
        assert group["datum"].attrs["units"] == "kg m^2"
        assert group["values"].attrs["units"] == "kg m^2"
        assert bool(group.attrs["multiples"]) is True
        assert all("units" in group[key].attrs for key in group if key != "whirl")
    # the same eigenvalues as an absolute sweep over those values
    direct = linear.sweep(CLASSICAL, {}, "I_x", np.linspace(0.5, 5.0, 10) * 0.000103)
    np.testing.assert_array_equal(multiple.eigenvalues, direct.eigenvalues)


def test_an_older_file_reads_and_draws_against_its_parameter_set(tmp_path):
    """The reference written before sweeps stored a datum (schema 1, no parameter set): it
    reads with the datum of its stored study's model (V: 6.7 m/s), not multiples, and
    damping_multiples divides by it."""
    reference = ROOT / "tests" / "regression" / "references" / "linear_datum_airspeed.h5"
    result = store.read(reference)
    (sweep,) = result.linear_sweeps
    with store.opened(reference) as handle:
        assert "datum" not in handle["linear/sweeps/V"]
    assert sweep.datum == 6.7 and sweep.multiples is False
    assert missing_data(result, "damping_multiples") == ""
    ((name, figure),) = list(study_figures(result, ("damping_multiples",), "old"))
    assert name == "old_damping_multiples.png"
    (line,) = [x for x in figure.axes[0].get_lines() if not x.get_label().startswith("_")]
    np.testing.assert_allclose(line.get_xdata(), sweep.values / 6.7, rtol=1e-15)
    run = CliRunner().invoke(cli, ["plot", str(reference), "--kind", "damping_multiples",
                                   "-o", str(tmp_path)])
    assert run.exit_code == 0, run.output
    assert [p.name for p in tmp_path.glob("*.png")] == [
        "linear_datum_airspeed_damping_multiples.png"]


def test_a_sweep_without_its_datum_falls_back_on_the_parameter_set(tmp_path):
    """A schema-2 file whose sweep stores no datum: /parameters gives it (I_x: 0.000103)."""
    from dataclasses import replace

    result = run_study(validate_text(STUDY), tmp_path / "work")
    bare = replace(result, linear_sweeps=tuple(replace(s, datum=None)
                                               for s in result.linear_sweeps))
    read = store.read(store.write(bare, tmp_path / "bare.h5"))
    assert [s.datum for s in read.linear_sweeps] == [None, None]
    ((_, figure),) = list(study_figures(read, ("damping_multiples",)))
    lines = [x for x in figure.axes[0].get_lines() if not x.get_label().startswith("_")]
    assert [x.get_label().split(" (")[0] for x in lines] == ["I_x", "V"]
    np.testing.assert_allclose(lines[0].get_xdata(), np.linspace(0.5, 5.0, 10), rtol=1e-14)
    np.testing.assert_allclose(lines[1].get_xdata(), np.linspace(0.0, 10.0, 11) / 6.7,
                               rtol=1e-15)


def test_a_file_without_a_usable_sweep_cannot_draw_it():
    reference = ROOT / "tests" / "regression" / "references" / "hardening_case2.h5"
    assert missing_data(store.read(reference), "damping_multiples") == \
        "no linear sweep (linear.sweeps)"
    sweep = linear.sweep(get_model("gimballed"), {}, "C_beta", np.linspace(0.0, 1e-3, 3))
    assert sweep.datum == 0.0
    from dataclasses import replace

    result = replace(store.read(reference), linear_sweeps=(sweep,))
    assert "non-zero datum" in missing_data(result, "damping_multiples")


# ------------------------------------------------------------------------------ the figure
def test_least_damped_mode_matches_the_sensitivity_table():
    for sweep in sensitivity_sweeps():
        zeta, _, whirl = least_damped(sweep)
        np.testing.assert_allclose(zeta, SENSITIVITY[sweep.parameter], atol=6e-5,
                                   err_msg=sweep.parameter)
        assert set(whirl) <= {"FW", "BW"}


def test_one_line_per_parameter_with_labels_and_axes():
    sweeps = sensitivity_sweeps()
    figure = damping_multiples_plot(sweeps, hz=True)
    ax_damp, ax_freq = figure.axes
    for ax in (ax_damp, ax_freq):
        lines = [x for x in ax.get_lines() if not x.get_label().startswith("_")]
        assert [x.get_label().split(" (")[0] for x in lines] == list(SENSITIVITY)
        for x in lines:
            np.testing.assert_allclose(x.get_xdata(), MULTIPLES, rtol=1e-15)
    assert ax_freq.get_xlabel() == "parameter / datum"
    assert ax_damp.get_ylabel() == "damping ratio [-]"
    assert ax_freq.get_ylabel() == "frequency [Hz]"
    labels = {x.get_label(): x for x in ax_damp.get_lines()}
    assert labels["I_y (BW)"] is not None  # the datum's flutter mode is BW (models.md 4)
    for name, reference in SENSITIVITY.items():
        (line,) = [x for label, x in labels.items() if label.startswith(f"{name} (")]
        np.testing.assert_allclose(line.get_ydata(), reference, atol=6e-5)
    legend = [t.get_text() for t in ax_damp.get_legend().get_texts()]
    assert legend == [x.get_label() for x in ax_damp.get_lines()
                      if not x.get_label().startswith("_")]
    # BW at the datum: 34.38 rad/s (models.md 3), in Hz on every curve at multiple 1
    for x in ax_freq.get_lines():
        if not x.get_label().startswith("_"):
            assert x.get_ydata()[1] == pytest.approx(34.38 / (2 * np.pi), abs=2e-3)


def test_draws_into_given_axes_and_skips_a_zero_datum():
    from matplotlib.figure import Figure

    figure = Figure()
    axes = tuple(figure.subplots(2, 1))
    zero = linear.sweep(get_model("gimballed"), {}, "C_beta", np.linspace(0.0, 1e-3, 3))
    (sweep,) = sensitivity_sweeps()[:1]
    assert damping_multiples_plot([sweep, zero], axes=axes) is figure
    drawn = [x.get_label() for x in axes[0].get_lines() if not x.get_label().startswith("_")]
    assert drawn == ["I_y (BW)"]
    assert axes[1].get_ylabel() == "frequency [rad/s]"


# ------------------------------------------------------------------------------ bad input
@pytest.mark.parametrize(("sweep", "expected"), [
    ("{parameter: C_beta, range: [0.5, 2], multiples: true}",
     "s.yaml:6: linear.sweeps[0].multiples: the datum of C_beta is 0 N m s/rad: it has no "
     "multiples; give the range in C_beta's unit (multiples: false)"),
    ("{parameter: I_x, range: [-1, 2], multiples: true}",
     "s.yaml:6: linear.sweeps[0].range: with multiples: true the range is in multiples of the "
     "datum of I_x (0.000103) and must be > 0, got -1.0"),
    ("{parameter: I_x, range: [0, 2], multiples: true}",
     "s.yaml:6: linear.sweeps[0].range: with multiples: true the range is in multiples of the "
     "datum of I_x (0.000103) and must be > 0, got 0.0"),
    ("{parameter: aero_coupling, range: [0.5, 2], multiples: true}",
     "s.yaml:6: linear.sweeps[0].range: the range reaches 2.0, outside the bounds of "
     "aero_coupling (in [0, 1])"),
    ("{parameter: I_x, range: [0.5, 2], multiples: yes}",
     "s.yaml:6: linear.sweeps[0].multiples: expected true or false, got 'yes'"),
])
def test_bad_multiples_are_refused(sweep, expected):
    text = f"name: s\nmodel: gimballed\nlinear:\n  sweeps:\n    -\n      {sweep}\n"
    with pytest.raises(StudyError) as error:
        validate_text(text, "s.yaml")
    assert error.value.message.splitlines() == [expected]


def test_multiples_on_a_grid_axis_and_a_switch_out_of_bounds_are_refused():
    grid = ("name: s\nmodel: classical\nlinear:\n  grid:\n"
            "    x: {parameter: K_theta, range: [0, 1], multiples: true}\n"
            "    y: {parameter: K_psi, range: [0, 1]}\n")
    with pytest.raises(StudyError) as error:
        validate_text(grid, "g.yaml")
    assert error.value.message.startswith("g.yaml:5: linear.grid.x.multiples: unknown key")
    with pytest.raises(StudyError) as error:
        validate_text("name: s\nmodel: classical\nparameters: {aero_coupling: 2}\n", "p.yaml")
    assert error.value.message == \
        "p.yaml:3: parameters.aero_coupling: aero_coupling must be in [0, 1], got 2"


def test_the_chapter_3_multiples_studies_validate():
    """Figs. 3.9-3.11: the sweeps and the damping_multiples plot, the uncoupled one with the
    switch off."""
    expected = {"inertia": ["I_y", "C_theta", "a"], "rotor": ["I_x", "Omega", "R"],
                "ix_coupled": ["I_x"], "ix_uncoupled": ["I_x"]}
    for name, parameters in expected.items():
        study = validate_text((STUDIES / f"linear_multiples_{name}.yaml").read_text())
        assert [s.parameter for s in study.linear.sweeps] == parameters
        assert all(s.multiples for s in study.linear.sweeps)
        assert study.plots == ("damping_multiples",)
        assert study.parameter_values().get("aero_coupling", 1.0) == (
            0.0 if name == "ix_uncoupled" else 1.0)
