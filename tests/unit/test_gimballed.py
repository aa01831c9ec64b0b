"""The gimballed-hub model (issue 16, whirl's derivation of models.md section 8) without AUTO:
its symbolic nacelle rows against the classical model's, its limits (stiff gimbal: the classical
model; free gimbal without air: a free gyroscope on an undamped nacelle), the onset against the
gimbal stiffness, the mode groups, laws on each of its four dofs, the odd symmetry and bad input.

Expected values come from closed forms (models.md 2.2-2.4 and 8) or from the classical model,
never from the gimballed model's own earlier output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from tests.strip_theory import coefficients
from whirl_cli.analysis import linear
from whirl_cli.models import get_model
from whirl_cli.models.symbolic import Symbolic
from whirl_cli.study import StudyError, load_study, validate_text

GIMBALLED = get_model("gimballed")
CLASSICAL = get_model("classical")
RIGID = {"K_beta": 1e6}


def _symbols(names):
    return {n: sp.Symbol(n, real=True) for n in names}


# ------------------------------------------------------------------------------ symbolic
def test_nacelle_rows_carry_the_classical_aerodynamic_terms():
    """From the generated residual R = G - S of the gimballed model: with K and C the
    structural terms removed, the theta and psi rows' aerodynamic stiffness and damping are
    the classical k_d, k_c, c_a (tests/strip_theory.py) exactly, and the only
    cross damping left on the nacelle is the gyroscopic I_x Omega (the +/- a A_2 pairs cancel
    with beta = 0): thesis frame, rows I_y theta'' = k_d theta - k_c psi - c_a theta' + ...,
    I_y psi'' = k_c theta + k_d psi - c_a psi' - ..."""
    sym = Symbolic(GIMBALLED)
    s = _symbols(GIMBALLED.state_names + GIMBALLED.parameter_names)
    k_d, k_c, c_a = coefficients(s)
    r_theta, r_psi = sym.residual[0], sym.residual[1]
    gyro = s["I_x"] * s["Omega"]
    terms = {
        "k_d (theta row)": (sp.diff(r_theta, s["theta"]) + s["K_theta"], k_d),
        "k_d (psi row)": (sp.diff(r_psi, s["psi"]) + s["K_psi"], k_d),
        "k_c (theta row)": (-sp.diff(r_theta, s["psi"]), k_c),
        "k_c (psi row)": (sp.diff(r_psi, s["theta"]), k_c),
        "c_a (theta row)": (-(sp.diff(r_theta, s["dtheta"]) + s["C_theta"]), c_a),
        "c_a (psi row)": (-(sp.diff(r_psi, s["dpsi"]) + s["C_psi"]), c_a),
        "gyroscopic (theta row)": (sp.diff(r_theta, s["dpsi"]), gyro),
        "gyroscopic (psi row)": (sp.diff(r_psi, s["dtheta"]), -gyro),
    }
    datum = {s[p.name]: p.default for p in GIMBALLED.parameters}
    origin = {s[n]: 0 for n in GIMBALLED.state_names}  # linear terms: at y = 0 (laws' K x)
    terms = {name: (generated.subs(origin), expected)
             for name, (generated, expected) in terms.items()}
    for name, (generated, expected) in terms.items():
        assert sp.simplify(generated - expected) == 0, name
        assert float(generated.subs(datum)) == pytest.approx(float(expected.subs(datum)),
                                                             rel=1e-12), name
    # models.md 2.3 at the datum: 0.04657, 0.05179 N m/rad, 0.000883 N m s/rad
    assert float(terms["k_d (theta row)"][0].subs(datum)) == pytest.approx(0.04657, rel=1e-3)
    assert float(terms["k_c (theta row)"][0].subs(datum)) == pytest.approx(0.05179, rel=1e-3)
    assert float(terms["c_a (theta row)"][0].subs(datum)) == pytest.approx(0.000883, rel=1e-3)


def test_with_beta_zero_the_nacelle_rows_are_the_classical_model():
    """R(theta, psi, beta = 0) of the gimballed model's nacelle rows equals the classical R."""
    g, c = Symbolic(GIMBALLED), Symbolic(CLASSICAL)
    zero = {sp.Symbol(n, real=True): 0 for n in ("beta_y", "beta_z", "dbeta_y", "dbeta_z")}
    for row in (0, 1):
        assert sp.simplify(g.residual[row].subs(zero) - c.residual[row]) == 0
    assert g.mass[:2, :2] == c.mass and not g.diagonal_mass


# ------------------------------------------------------------------------------ limits
def _eigenvalues(model, overrides):
    return np.linalg.eigvals(model.jacobian_numpy(np.zeros(model.n_states),
                                                  model.parameter_vector(overrides)))


@pytest.mark.parametrize("speed", [0.0, 4.0, 6.7, 7.764, 9.0])
def test_stiff_gimbal_nacelle_eigenvalues_are_the_classical(speed):
    """K_beta = 1e6: the four slowest eigenvalues are the classical model's (1e-3)."""
    rigid = _eigenvalues(GIMBALLED, {**RIGID, "V": speed})
    slow = rigid[np.argsort(np.abs(rigid))[:4]]
    expected = _eigenvalues(CLASSICAL, {"V": speed})
    np.testing.assert_allclose(np.sort_complex(slow), np.sort_complex(expected), rtol=1e-3)


def test_stiff_gimbal_onset_and_k1_critical_points_are_the_classical():
    """K_beta = 1e6: the onset in V at datum and the Hopf and branch points in K_theta at
    K_psi = 0.3 equal the classical model's (1e-3 relative; models.md 4: 7.764 m/s, 0.0807,
    0.2888, 0.03598)."""
    def points(model, overrides, parameter, lower, upper):
        return [(c.kind, c.value) for c in linear.critical_points(model, overrides, parameter,
                                                                  lower, upper, points=801)]
    for overrides, parameter, bounds in (({}, "V", (0.0, 12.0)),
                                         ({"K_psi": 0.3}, "K_theta", (-0.3, 0.5))):
        rigid = points(GIMBALLED, {**overrides, **RIGID}, parameter, *bounds)
        expected = points(CLASSICAL, overrides, parameter, *bounds)
        assert [k for k, _ in rigid] == [k for k, _ in expected]
        for (_, value), (_, reference) in zip(rigid, expected, strict=True):
            assert value == pytest.approx(reference, rel=1e-3)
    assert points(GIMBALLED, RIGID, "V", 0.0, 12.0)[0][1] == pytest.approx(7.764, rel=1e-3)


def test_free_gimbal_without_air_is_a_gyroscope_on_an_undamped_nacelle():
    """K_beta = C_beta = 0, rho = 0 (and no structural damping): the disc modes sit at
    I_x Omega / I_d = 2 Omega (nutation, forward) and 0 (precession), the nacelle modes at
    sqrt(K_theta / I_n), I_n = I_y - I_d, all undamped; each mode's energy is in its group."""
    free = {"K_beta": 0.0, "C_beta": 0.0, "rho": 0.0, "C_theta": 0.0, "C_psi": 0.0}
    params = GIMBALLED.parameter_vector(free)
    p = dict(zip(GIMBALLED.parameter_names, params, strict=True))
    nacelle = math.sqrt(p["K_theta"] / (p["I_y"] - p["I_d"]))
    assert p["I_x"] * p["Omega"] / p["I_d"] == pytest.approx(2 * p["Omega"])
    sweep = linear.sweep(GIMBALLED, free, "V", np.array([p["V"]]))
    values, whirl, groups = sweep.eigenvalues[0], sweep.whirl[0], sweep.mode_group[0]
    expected = np.array([0, 0, 2j, -2j], complex) * p["Omega"]
    expected = np.concatenate([expected, np.array([1j, -1j, 1j, -1j]) * nacelle])
    scale = 2 * p["Omega"]
    assert np.abs(values.real).max() < 1e-9 * scale  # undamped
    np.testing.assert_allclose(np.sort(np.abs(values.imag)), np.sort(np.abs(expected.imag)),
                               rtol=1e-9, atol=1e-6 * scale)
    at = np.abs(np.abs(values.imag) - nacelle) < 1e-6 * scale
    assert at.sum() == 4 and set(groups[at]) == {"nacelle"}
    assert set(groups[~at]) == {"gimbal"}
    nutation = np.abs(np.abs(values.imag) - 2 * p["Omega"]) < 1e-6 * scale
    assert nutation.sum() == 2 and set(whirl[nutation]) == {"FW"}


def test_onset_decreases_as_the_gimbal_softens(capsys):
    """The flutter onset in V (eigenvalues, datum otherwise) falls monotonically as K_beta
    decreases from effectively rigid to soft; the test prints the table."""
    stiffnesses = [1e6, 1e4, 1e3, 300.0, 100.0, 30.0, 10.0, 5.0, 3.0, 2.0, 1.5, 1.0, 0.7, 0.5]
    onsets = []
    for k_beta in stiffnesses:
        hopfs = [c for c in linear.critical_points(GIMBALLED, {"K_beta": k_beta}, "V", 0.0,
                                                   12.0, points=601) if c.kind == "hopf"]
        onsets.append((hopfs[0].value, hopfs[0].frequency))
    with capsys.disabled():
        print("\n  K_beta [N m/rad]   onset V [m/s]   frequency [rad/s]")
        for k_beta, (onset, frequency) in zip(stiffnesses, onsets, strict=True):
            print(f"  {k_beta:>16g}   {onset:13.5f}   {frequency:17.3f}")
    values = np.array([v for v, _ in onsets])
    assert np.all(np.diff(values) < 0)
    assert values[0] == pytest.approx(7.764, rel=1e-3)


def test_mode_groups_and_whirl_at_a_stiff_gimbal():
    """K_beta = 1e6 at the datum: the two slow pairs are nacelle modes with the classical
    labels (BW 34.38 rad/s, FW 57.53 rad/s, models.md 3), the two fast pairs gimbal modes."""
    sweep = linear.sweep(GIMBALLED, RIGID, "V", np.array([6.7]))
    frequency, whirl, groups = sweep.frequency[0], sweep.whirl[0], sweep.mode_group[0]
    slow = frequency < 100.0
    assert set(groups[slow]) == {"nacelle"} and set(groups[~slow]) == {"gimbal"}
    bw = np.abs(frequency - 34.38) < 0.01
    fw = np.abs(frequency - 57.53) < 0.01
    assert bw.sum() == 2 and set(whirl[bw]) == {"BW"}
    assert fw.sum() == 2 and set(whirl[fw]) == {"FW"}
    assert linear.sweep(CLASSICAL, {}, "V", np.array([6.7])).mode_group is None


# ------------------------------------------------------------------------------ laws, symmetry
@pytest.mark.parametrize("dof", ["theta", "psi", "beta_y", "beta_z"])
def test_a_polynomial_law_on_each_dof(dof):
    """K2 and K3 on one dof add -(K2 x^3 + K3 x^5) to that dof's row of M q'' = R: the change
    of the accelerations is M^-1 e_dof times it (M numeric, from the model)."""
    index = GIMBALLED.family.dof_names.index(dof)
    rng = np.random.default_rng(index)
    y = rng.normal(scale=0.3, size=8)
    base = {"K_psi": 0.3, "K_beta": 2.0}
    params = GIMBALLED.parameter_vector({**base, f"K2_{dof}": -10.0, f"K3_{dof}": 350.0})
    plain = GIMBALLED.parameter_vector(base)
    change = GIMBALLED.rhs_numpy(y, params) - GIMBALLED.rhs_numpy(y, plain)
    x = y[index]
    force = np.zeros(4)
    force[index] = -(-10.0 * x**3 + 350.0 * x**5)
    expected = np.linalg.solve(GIMBALLED.mass_numpy(plain), force)
    np.testing.assert_allclose(change[:4], 0.0, atol=0)
    np.testing.assert_allclose(change[4:], expected, rtol=1e-10, atol=1e-12 * abs(force).max())


def test_a_law_on_a_gimbal_dof_in_a_study():
    """A study's law on beta_z: K1/K2/K3 are that dof's (K_beta, K2_beta_z, K3_beta_z)."""
    study = validate_text("name: s\nmodel: gimballed\nnonlinearity: {type: polynomial, dof: "
                          "beta_z, K2: 5.0, K3: 1.0}\ncontinuations:\n  - {name: k, type: "
                          "one-parameter, parameter: K1, start: 1.0, range: [0.0, 2.0]}\n")
    values = study.parameter_values()
    assert values["K2_beta_z"] == 5.0 and values["K3_beta_z"] == 1.0
    assert study.continuations[0].parameter == "K_beta"


def test_right_hand_side_is_odd():
    """f(-y) = -f(y) with laws on every dof (the declared symmetry y -> -y), and the
    Jacobian even."""
    rng = np.random.default_rng(7)
    laws = {f"K{k}_{d}": rng.normal() * 10 for d in GIMBALLED.family.dof_names for k in (2, 3)}
    params = GIMBALLED.parameter_vector({"K_beta": 3.0, **laws})
    assert GIMBALLED.symmetric
    for _ in range(5):
        y = rng.normal(scale=0.4, size=8)
        np.testing.assert_allclose(GIMBALLED.rhs_numpy(-y, params),
                                   -GIMBALLED.rhs_numpy(y, params), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(GIMBALLED.jacobian_numpy(-y, params),
                                   GIMBALLED.jacobian_numpy(y, params), rtol=1e-12, atol=1e-12)


# ------------------------------------------------------------------------------ declaration
def test_declared_as_provisional_with_units_and_bounds():
    text = GIMBALLED.describe()
    assert "provisional" in text.lower() and GIMBALLED.family.provisional
    assert GIMBALLED.state_names == ("theta", "psi", "beta_y", "beta_z", "dtheta", "dpsi",
                                     "dbeta_y", "dbeta_z")
    p = {q.name: q for q in GIMBALLED.parameters}
    assert p["I_d"].default == pytest.approx(p["I_x"].default / 2)
    assert (p["I_d"].unit, p["K_beta"].unit, p["C_beta"].unit) == ("kg m^2", "N m/rad",
                                                                    "N m s/rad")
    assert p["C_beta"].default == 0.0
    assert not p["K_beta"].bounds.contains(-1e-9) and p["K_beta"].bounds.contains(0.0)
    assert "provisional" in (GIMBALLED.family.description + GIMBALLED.notes).lower()
    from whirl_cli.models import BUILTIN
    assert "PROVISIONAL" in (BUILTIN / "gimballed.model.yaml").read_text()
    from click.testing import CliRunner

    from whirl_cli.cli import cli
    listed = CliRunner().invoke(cli, ["models"]).output
    block = listed[listed.index("gimballed_poly:"):]
    assert "[provisional: whirl's own derivation]" in block.splitlines()[0]
    assert "mode groups: nacelle (theta, psi), gimbal (beta_y, beta_z)" in block


BAD = """\
name: bad
model: gimballed
parameters:
  I_d: {i_d}
  K_beta: {k_beta}
continuations:
  - {{name: v, type: one-parameter, parameter: V, range: [0.0, 10.0]}}
"""


def _problems(tmp_path, text, name="bad.yaml"):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(StudyError) as caught:
        load_study(path)
    return caught.value.message.splitlines()


@pytest.mark.parametrize("i_d", [0.000178, 0.0002])
def test_gimbal_inertia_not_below_the_total_is_refused(tmp_path, i_d):
    assert _problems(tmp_path, BAD.format(i_d=i_d, k_beta=1.0)) == [
        f"bad.yaml:4: parameters.I_d: the nacelle-only inertia I_n = I_y - I_d must be > 0 "
        f"(I_d < I_y), got I_d = {i_d:g}, I_y = 0.000178"]


def test_negative_gimbal_stiffness_is_refused(tmp_path):
    assert _problems(tmp_path, BAD.format(i_d=5e-5, k_beta=-1.0)) == [
        "bad.yaml:5: parameters.K_beta: K_beta must be >= 0 N m/rad, got -1.0"]


def test_both_at_once_and_ranges_crossing_the_constraint(tmp_path):
    assert _problems(tmp_path, BAD.format(i_d=0.001, k_beta=-2.0)) == [
        "bad.yaml:4: parameters.I_d: the nacelle-only inertia I_n = I_y - I_d must be > 0 "
        "(I_d < I_y), got I_d = 0.001, I_y = 0.000178",
        "bad.yaml:5: parameters.K_beta: K_beta must be >= 0 N m/rad, got -1.0".replace(
            "-1.0", "-2.0")]
    text = ("name: bad\nmodel: gimballed\ncontinuations:\n  - {name: i, type: one-parameter, "
            "parameter: I_y, start: 0.0002, range: [0.00001, 0.001]}\n")
    assert _problems(tmp_path, text) == [
        "bad.yaml:4: continuations[0].range: the range reaches 1e-05, where the nacelle-only "
        "inertia I_n = I_y - I_d must be > 0 (I_d < I_y)"]


def test_a_law_on_an_unknown_dof_is_refused(tmp_path):
    text = "name: bad\nmodel: gimballed\nnonlinearity: {type: polynomial, dof: beta_x, K2: 1}\n"
    assert _problems(tmp_path, text) == [
        "bad.yaml:3: nonlinearity.dof: expected one of theta, psi, beta_y, beta_z, got "
        "'beta_x'"]


def test_linear_plot_names_each_mode_by_group_and_whirl():
    """The linear-sweep figure's legend: "<group> <whirl>" for a model with mode groups."""
    from whirl_cli.plots.linear import linear_sweep_plot

    sweep = linear.sweep(GIMBALLED, {}, "K_beta", np.linspace(2.0, 50.0, 25))
    figure = linear_sweep_plot(sweep)
    labels = {line.get_label() for line in figure.axes[0].get_lines()
              if not line.get_label().startswith("_")}
    assert labels == {"nacelle BW", "nacelle FW", "gimbal BW", "gimbal FW"}
