"""Model files (no AUTO): safe expressions, every bad file a clean ``file:line: key: reason``,
the content key, and the classical model written as a file giving the built-in's equations."""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from whirl_cli.errors import StudyError
from whirl_cli.models import get_model, load_model_file
from whirl_cli.models.expressions import ExpressionError, evaluate, parse, to_sympy
from whirl_cli.models.file import model_from_text
from whirl_cli.study import load_study

DATA = Path(__file__).resolve().parents[1] / "data"

#: A small valid model: two coupled oscillators with a flutter-like coupling.
GOOD = """\
name: pair
description: two coupled oscillators
dofs:
  - {name: x, unit: m, stiffness: k_x}
  - {name: y, unit: m, stiffness: k_y, amplitude: 0.1}
parameters:
  - {name: k_x, value: 1.0, unit: N/m}
  - {name: k_y, value: 2.0, unit: N/m}
  - {name: m, value: 1.0, unit: kg, bounds: positive}
  - {name: c, value: 0.05, unit: N s/m, bounds: non-negative}
  - {name: g, value: 0.3, unit: N/m}
definitions:
  c2: 2*c
mass: [[m, 0.1*m], [0.1*m, m]]
forces:
  x: -c*dx + g*y
  y: -c2*dy - g*x
"""


def problems(text: str) -> list[str]:
    with pytest.raises(StudyError) as error:
        model_from_text(text, "model.yaml")
    return error.value.message.splitlines()


def edited(old: str, new: str) -> str:
    assert old in GOOD, old
    return GOOD.replace(old, new)


# (change to GOOD, key path reported, part of the reason)
BAD = [
    (("name: pair", "name: classical"), "name", "built-in"),
    (("name: pair", "name: 3pair"), "name", "letters"),
    (("  - {name: x, unit: m, stiffness: k_x}", "  - {name: x, unit: m, stiffness: k_z}"),
     "dofs[0].stiffness", "no parameter 'k_z'"),
    (("  - {name: g, value: 0.3, unit: N/m}", "  - {name: X, value: 0.3, unit: N/m}"),
     "parameters[4].name", "declared twice"),
    (("  - {name: g, value: 0.3, unit: N/m}", "  - {name: g, value: 0.3, unit: N/m}\n"
      "  - {name: g, value: 1}"), "parameters[5].name", "declared twice"),
    (("name: g,", "name: K2_x,"), "parameters[4].name", "law"),
    (("name: g,", "name: K1,"), "parameters[4].name", "reserved"),
    (("name: g,", "name: ndim,"), "parameters[4].name", "reserved"),
    (("name: g,", "name: a_very_long_name_x,"), "parameters[4].name", "at most 13"),
    (("name: g,", "name: sqrt,"), "parameters[4].name", "function"),
    (("{name: m, value: 1.0", "{name: m, value: -1.0"), "parameters[2].value",
     "outside its bounds"),
    (("{name: m, value: 1.0", "{name: m, value: ten"), "parameters[2].value",
     "expected a number"),
    (("bounds: positive}", "bounds: sometimes}"), "parameters[2].bounds", "expected"),
    (("  c2: 2*c", "  c2: 2*c2"), "definitions.c2", "refers to itself"),
    (("  c2: 2*c", "  c2: 2*c3\n  c3: c"), "definitions.c2", "defined below"),
    (("  c2: 2*c", "  c2: 2*q"), "definitions.c2", "unknown name 'q'"),
    (("[[m, 0.1*m], [0.1*m, m]]", "[[m, 0.1*m], [0.2*m, m]]"), "mass[1][0]", "symmetric"),
    (("[[m, 0.1*m], [0.1*m, m]]", "[[m, m], [m, m]]"), "mass", "singular"),
    (("[[m, 0.1*m], [0.1*m, m]]", "[[m, 0], [0, m], [0, m]]"), "mass", "2 x 2"),
    (("[[m, 0.1*m], [0.1*m, m]]", "[[m + x, 0], [0, m]]"), "mass[0][0]",
     "may not depend on the states"),
    (("  y: -c2*dy - g*x\n", ""), "forces", "no force for dof y"),
    (("  y: -c2*dy - g*x\n", "  y: -c2*dy - g*x\n  z: 0\n"), "forces.z", "no dof 'z'"),
    (("  x: -c*dx + g*y", "  x: -c*dx + g*w"), "forces.x", "unknown name 'w'"),
    (("  x: -c*dx + g*y", "  x: -c*dx + g^y"), "forces.x", "'**'"),
    (("  x: -c*dx + g*y", "  x: -c*dx + g.real"), "forces.x", "attribute"),
    (("  x: -c*dx + g*y", "  x: -c*dx + g[0]"), "forces.x", "subscript"),
    (("  x: -c*dx + g*y", "  x: \"__import__('os').system('true')\""), "forces.x",
     "only the named functions"),
    (("  x: -c*dx + g*y", "  x: \"(lambda: 1)()\""), "forces.x", "only the named functions"),
    (("  x: -c*dx + g*y", "  x: \"__import__('os')\""), "forces.x",
     "unknown function '__import__'"),
    (("  x: -c*dx + g*y", "  x: \"'text'\""), "forces.x", "not a number"),
    (("  x: -c*dx + g*y", "  x: -c*dx + eval(y)"), "forces.x", "unknown function 'eval'"),
    (("  x: -c*dx + g*y", "  x: -c*dx + sqrt(y, y)"), "forces.x", "takes 1"),
    (("  x: -c*dx + g*y", "  x: -c*dx + 2**10**10"), "forces.x", "exponent"),
    (("  x: -c*dx + g*y", "  x: -c*dx + log(c - c)"), "forces.x", "cannot be computed"),
    (("  x: -c*dx + g*y", "  x: -c*dx + g*y > 0"), "forces.x", "comparison"),
    (("  x: -c*dx + g*y", "  x: \"-c*dx + (g*y\""), "forces.x", "cannot read"),
    (("description: two coupled oscillators", "colour: blue"), "colour", "unknown key"),
    (("description: two coupled oscillators", "states: [{name: lam}]"), "rates",
     "no rate for state lam"),
    (("description: two coupled oscillators", "states: [{name: lam}]\nrates: {lam: -lam/tau}"),
     "rates.lam", "unknown name 'tau'"),
    (("description: two coupled oscillators", "rates: {mu: -x}"), "rates.mu",
     "no first-order state 'mu'"),
    (("description: two coupled oscillators", "states: [{name: lam_inflow_1}]\n"
      "rates: {lam_inflow_1: -lam_inflow_1}"), "states[0].name", "too long for AUTO"),
    (("description: two coupled oscillators", "states: [{name: dx}]\nrates: {dx: 0}"),
     "states[0].name", "declared twice"),
    (("description: two coupled oscillators", "states: [{name: s}]\nrates: {s: 1/(s - s)}"),
     "rates.s", "cannot be computed"),
    (("mass: [[m, 0.1*m], [0.1*m, m]]", "mass: [[m, 0.1*s], [0.1*s, m]]\nstates: [{name: s}]"
      "\nrates: {s: -s}"), "mass[0][1]", "may not depend on the states"),
    (("mass: [[m, 0.1*m], [0.1*m, m]]", ""), "mass", "missing"),
    (("description: two coupled oscillators", "hub: {y: y*x, z: x}"), "hub.y", "linear"),
    (("description: two coupled oscillators", "hub: {y: m*x, z: x}"), "hub.y", "not a state"),
    (("description: two coupled oscillators",
      "constraints: [{expression: k_x - k_y > 0, reason: x stiffer}]"),
     "constraints[0].expression", "does not hold"),
    (("description: two coupled oscillators", "constraints: [{expression: k_x + k_y}]"),
     "constraints[0].expression", "one comparison"),
]


@pytest.mark.parametrize(("change", "key", "reason"), BAD, ids=[b[1] + ":" + b[2] for b in BAD])
def test_bad_model_file(change, key, reason):
    lines = problems(edited(*change))
    pattern = re.compile(rf"^model\.yaml:\d+: {re.escape(key)}: .*{re.escape(reason)}")
    assert any(pattern.search(line) for line in lines), lines
    assert all(re.match(r"^model\.yaml:\d+: \S+: ", line) for line in lines), lines


def test_at_least_25_bad_files():
    assert len(BAD) >= 25


def test_every_problem_at_once():
    text = edited("  c2: 2*c", "  c2: 2*q").replace("g*y", "g*w")
    lines = problems(text)
    assert any("definitions.c2" in line for line in lines)
    assert any("forces.x" in line for line in lines)


def test_the_good_model_reads():
    family = model_from_text(GOOD, "model.yaml")
    assert family.dof_names == ("x", "y")
    assert family.dofs[1].rate == "dy" and family.dofs[1].amplitude == 0.1
    assert family.symmetric and family.linear  # derived: the forces are odd and linear


def test_no_code_runs_from_an_expression(tmp_path):
    """An expression that would create a file if it were evaluated is refused, and nothing
    is created, through the CLI too (exit 1, nothing written)."""
    marker = tmp_path / "ran"
    model = tmp_path / "evil.yaml"
    model.write_text(edited("  x: -c*dx + g*y",
                            f"  x: \"__import__('pathlib').Path('{marker}').touch() or 0\""))
    study = tmp_path / "study.yaml"
    study.write_text("name: s\nmodel: ./evil.yaml\ncontinuations:\n  - {name: a, type: "
                     "one-parameter, parameter: g, range: [0, 1], periodic: false}\n")
    done = subprocess.run([str(Path(sys.executable).with_name("whirl")), "run", str(study),
                           "-o", str(tmp_path / "out.h5")], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 1
    assert re.search(r"evil\.yaml:\d+: forces\.x: ", done.stderr), done.stderr
    assert "Traceback" not in done.stderr
    assert not marker.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["evil.yaml", "study.yaml"]


def test_a_missing_model_file_is_reported_at_the_key(tmp_path):
    study = tmp_path / "study.yaml"
    study.write_text("name: s\nmodel: ./nowhere.yaml\n")
    with pytest.raises(StudyError, match=r"study\.yaml:2: model: no model file './nowhere"):
        load_study(study)


# ------------------------------------------------------------------------------ expressions
@pytest.mark.parametrize("text", ["sqrt(a**2 + 1) * sin(b) - atan2(a, b) / 3",
                                  "max(a, b, 2) - min(a, -b) + abs(-a) * sign(b)",
                                  "exp(-a) + log(b) + tanh(a) + asinh(b) + pi",
                                  "1/2 * a - -b + +a"])
def test_expressions_evaluate_as_sympy_does(text):
    values = {"a": 0.7, "b": 1.3}
    expression = parse(text)
    symbols = {n: sp.Symbol(n) for n in values}
    exact = float(to_sympy(expression, symbols).subs({symbols[n]: v for n, v in
                                                      values.items()}))
    assert evaluate(expression, values) == pytest.approx(exact, rel=1e-13)
    assert expression.names == {"a", "b"}


def test_integers_stay_exact():
    assert to_sympy(parse("1/2"), {}) == sp.Rational(1, 2)


@pytest.mark.parametrize("text", ["a.b", "a[0]", "f(a)", "lambda: 1", "'s'", "a if b else c",
                                  "a and b", "(a, b)", "__import__('os')", "a // b", "a % b",
                                  "sqrt(x=1)", "", "a ** 1000"])
def test_refused_expressions(text):
    with pytest.raises(ExpressionError):
        parse(text)


def test_deep_nesting_is_refused_not_a_crash():
    with pytest.raises(ExpressionError):
        parse("(" * 5000 + "a" + ")" * 5000)
    with pytest.raises(ExpressionError):
        parse("-" * 100000 + "a")


# ------------------------------------------------------------------------------ content key
def test_the_key_follows_what_is_declared_not_how_it_is_written():
    key = model_from_text(GOOD, "m.yaml").key
    assert model_from_text("# a comment\n" + GOOD.replace("2*c", "2 * c"), "m.yaml").key == key
    assert model_from_text(GOOD.replace("2*c", "3*c"), "m.yaml").key != key
    # a default written out, or an optional key the format gained since, changes nothing
    defaults = GOOD.replace("stiffness: k_x}", "stiffness: k_x, amplitude: 1.0}") + \
        "states: []\nrates: {}\nprovisional: false\n"
    assert model_from_text(defaults, "m.yaml").key == key
    assert model_from_text(GOOD.replace("stiffness: k_x}", "stiffness: k_x, amplitude: 2.0}"),
                           "m.yaml").key != key


# ------------------------------------------------------------------------------ classical
def test_the_classical_model_file_gives_the_built_in_equations():
    """Right-hand side and Jacobian of the file model equal the built-in's at random states
    and parameters (two independent writings of the same equations)."""
    file_model = get_model(load_model_file(DATA / "classical_as_file.yaml"))
    built_in = get_model("classical")
    assert file_model.parameter_names == built_in.parameter_names
    rng = np.random.default_rng(7)
    datum = built_in.parameter_vector()
    for _ in range(5):
        y = rng.normal(size=4) * 0.3
        p = datum * (1 + 0.2 * rng.uniform(-1, 1, size=datum.size))
        p[built_in.parameter_names.index("N")] = 4.0
        np.testing.assert_allclose(file_model.rhs_numpy(y, p), built_in.rhs_numpy(y, p),
                                   rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(file_model.jacobian_numpy(y, p),
                                   built_in.jacobian_numpy(y, p), rtol=1e-11, atol=1e-11)
    assert file_model.family.time_scale == built_in.time_scale
    assert math.isclose(file_model.family.hub[0][0][1], -1.0)


def test_a_fresh_process_finds_a_model_file_by_its_reference():
    """A study travels to another process (a Dask worker) with its model's absolute path: the
    process reads the file itself."""
    code = ("from whirl_cli.models import get_model; import sys; "
            "print(get_model(sys.argv[1]).family.name)")
    done = subprocess.run([sys.executable, "-c", code, str(DATA / "classical_as_file.yaml")],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "classical_file"


def test_an_empty_or_missing_model_file(tmp_path):
    assert problems("") == ["model.yaml: the model file is empty"]
    with pytest.raises(StudyError, match=r"nowhere\.yaml: cannot read the model file"):
        load_model_file(tmp_path / "nowhere.yaml", "nowhere.yaml")


# ------------------------------------------------------------------------------ first order
def test_lorenz_numeric_equations_match_the_written_ones():
    """A model of first-order states only: the generated right-hand side, Jacobian and second
    derivatives against the Lorenz equations written out here."""
    model = get_model(load_model_file(DATA / "lorenz.model.yaml", "lorenz"), ())
    assert model.state_names == ("x", "y", "z") and model.n_dof == 0
    rho, sigma, beta = 28.0, 10.0, 8.0 / 3.0
    params = model.parameter_vector({"rho": rho})
    rng = np.random.default_rng(3)
    for x, y, z in rng.normal(size=(5, 3)) * 10:
        state = np.array([x, y, z])
        np.testing.assert_allclose(model.rhs_numpy(state, params),
                                   [sigma * (y - x), rho * x - y - x * z, x * y - beta * z],
                                   rtol=1e-14, atol=1e-12)
        np.testing.assert_allclose(model.jacobian_numpy(state, params),
                                   [[-sigma, sigma, 0], [rho - z, -1, -x], [y, x, -beta]],
                                   rtol=1e-14, atol=1e-12)
    second, third = model.derivative_tensors(np.zeros(3), params)
    expected = np.zeros((3, 3, 3))
    expected[1, 0, 2] = expected[1, 2, 0] = -1.0
    expected[2, 0, 1] = expected[2, 1, 0] = 1.0
    np.testing.assert_array_equal(second, expected)
    assert not third.any()
    assert not model.family.symmetric and not model.family.linear


def test_mixed_model_numeric_equations_match_the_written_ones():
    """A dof and a first-order state that loads it: state order q, dq, lam; the batched
    right-hand side (points on a trailing axis) as the single one."""
    model = get_model(load_model_file(DATA / "lagged_spring.model.yaml", "lagged"),
                      ("polynomial",))
    assert model.state_names == ("q", "dq", "lam") and model.positions == (0, 2)
    k, c, m, tau, mu = 2.0, 0.4, 1.0, 0.5, -2.0
    params = model.parameter_vector({})
    states = np.random.default_rng(5).normal(size=(3, 4))
    q, dq, lam = states
    expected = np.array([dq, (-c * dq - k * q + lam) / m, (mu + lam - lam**3 / 3) / tau])
    np.testing.assert_allclose(model.rhs_numpy(states, np.repeat(params[:, None], 4, axis=1)),
                               expected, rtol=1e-14)
    jacobian = model.jacobian_numpy(states[:, 0], params)
    np.testing.assert_allclose(jacobian, [[0, 1, 0], [-k / m, -c / m, 1 / m],
                                          [0, 0, (1 - lam[0] ** 2) / tau]], rtol=1e-14)


def test_a_study_of_a_first_order_model_takes_no_law(tmp_path):
    (tmp_path / "lorenz.model.yaml").write_text((DATA / "lorenz.model.yaml").read_text())
    study = tmp_path / "s.yaml"
    study.write_text("name: s\nmodel: ./lorenz.model.yaml\nnonlinearity: {type: polynomial}\n")
    with pytest.raises(StudyError, match=r"s\.yaml:3: nonlinearity: model lorenz has no dofs"):
        load_study(study)
    study.write_text("name: s\nmodel: ./lorenz.model.yaml\ncontinuations:\n  - {name: r, type: "
                     "one-parameter, parameter: rho, range: [0.5, 2], start_state: {w: 1}}\n")
    with pytest.raises(StudyError, match=r"start_state\.w: expected one of x, y, z"):
        load_study(study)
    study.write_text("name: s\nmodel: ./lorenz.model.yaml\n")
    assert load_study(study).variant().laws == ()


def test_a_model_needs_a_dof_or_a_state():
    text = "name: empty\nparameters: [{name: a, value: 1}]\n"
    (line,) = problems(text)
    assert "dofs: a model needs at least one dof" in line


# ------------------------------------------------------------------------------ built-ins
@pytest.mark.parametrize("name", ["classical", "gimballed", "oscillators"])
def test_built_in_models_are_model_files(name):
    """Each built-in is a file under models/builtin: read at start-up without line tracking,
    it declares exactly what the checked reading of a user's file gives."""
    from whirl_cli.models import BUILTIN, FAMILIES
    from whirl_cli.models.file import model_from_text

    path = BUILTIN / f"{name}.model.yaml"
    checked = model_from_text(path.read_text(), path.name, builtin=True)
    assert FAMILIES[name] == checked and FAMILIES[name].key == checked.key
    assert FAMILIES[name].name == name


def test_a_user_file_may_not_take_a_built_in_name():
    (line,) = problems(GOOD.replace("name: pair", "name: gimballed"))
    assert "name: 'gimballed' is the name of a built-in model" in line


def test_dofs_may_share_a_stiffness():
    """An isotropic spring (the gimballed model's K_beta on both gimbal dofs)."""
    family = model_from_text(GOOD.replace("stiffness: k_y,", "stiffness: k_x,"), "m.yaml")
    assert [d.stiffness for d in family.dofs] == ["k_x", "k_x"]


def test_api_loads_a_model_file_or_a_built_in(tmp_path):
    """api.load_model: the nacelle-on-wing example as numbers (its generated Jacobian at the
    datum agrees with central differences of its generated right-hand side); a built-in by
    name with laws; a bad file and an unknown name refused with their reasons."""
    from whirl_cli import api
    from whirl_cli.errors import WhirlError

    root = Path(__file__).resolve().parents[2]
    model = api.load_model(root / "studies" / "nacelle_on_wing" / "nacelle_on_wing.model.yaml")
    assert model.family.name == "nacelle_on_wing" and model.n_states == 6
    params = model.parameter_vector()
    jacobian = model.jacobian_numpy(np.zeros(model.n_states), params)
    step = 1e-7
    for k in range(model.n_states):
        probe = np.zeros(model.n_states)
        probe[k] = step
        slope = (model.rhs_numpy(probe, params) - model.rhs_numpy(-probe, params)) / (2 * step)
        np.testing.assert_allclose(jacobian[:, k], slope, rtol=1e-6, atol=1e-6)
    assert api.load_model("classical", ["freeplay", "polynomial"]).name == \
        "classical_fp_theta_poly_psi"
    (tmp_path / "bad.model.yaml").write_text(GOOD.replace("  x: -c*dx + g*y", "  x: -c*dx + q"))
    with pytest.raises(StudyError, match=r"bad\.model\.yaml:\d+: forces\.x: unknown name 'q'"):
        api.load_model(tmp_path / "bad.model.yaml")
    with pytest.raises(WhirlError, match="unknown model 'tiltrotor'"):
        api.load_model("tiltrotor")


#: Names the generated numeric module once used itself: its arguments (y, c, p) and
#: temporaries (t_0, r_0, m_0_0, s_0_0), as a model's states and parameters.
CLASHING = """\
name: clashing
description: names of the generated module's own
states:
  - {name: y}
  - {name: q}
  - {name: c}
parameters:
  - {name: p, value: 2.0}
  - {name: t_0, value: 0.5}
  - {name: r_0, value: 3.0}
  - {name: m_0_0, value: 0.25}
rates:
  y: q
  q: -p*y - t_0*q + c*y**2 - m_0_0*y**3
  c: -r_0*c + y*q*t_0
"""


def test_a_models_names_never_clash_with_the_generated_codes(tmp_path):
    """States and parameters named as the generated module's arguments and temporaries give
    the right-hand side, Jacobian, derivative tensors and simulation field written here."""
    path = tmp_path / "clashing.yaml"
    path.write_text(CLASHING)
    model = get_model(load_model_file(path))
    p, t0, r0, m00 = 2.0, 0.5, 3.0, 0.25
    params = model.parameter_vector({})
    state = np.array([0.3, -0.7, 1.1])
    y, q, c = state
    rates = [q, -p * y - t0 * q + c * y**2 - m00 * y**3, -r0 * c + y * q * t0]
    jacobian = [[0, 1, 0], [-p + 2 * c * y - 3 * m00 * y**2, -t0, y**2],
                [q * t0, y * t0, -r0]]
    np.testing.assert_allclose(model.rhs_numpy(state, params), rates, rtol=1e-12)
    np.testing.assert_allclose(model.jacobian_numpy(state, params), jacobian, rtol=1e-12)
    field, field_jacobian = model.field_at(params)
    np.testing.assert_allclose(field(state), rates, rtol=1e-12)
    np.testing.assert_allclose(field_jacobian(state), jacobian, rtol=1e-12)
    second, third = model.derivative_tensors(state, params)
    assert second[1, 0, 0] == pytest.approx(2 * c - 6 * m00 * y)
    assert second[1, 0, 2] == second[1, 2, 0] == pytest.approx(2 * y)
    assert second[2, 0, 1] == pytest.approx(t0)
    assert third[1, 0, 0, 0] == pytest.approx(-6 * m00)
    assert third[1, 0, 0, 2] == pytest.approx(2.0)
