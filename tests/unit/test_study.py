"""Study files: loading, defaults, and every error reason word for word (whirl_cli.study)."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pydantic import BaseModel, ValidationError

from whirl_cli.errors import StudyError
from whirl_cli.study import (
    MAX_BYTES,
    AutoSettings,
    Linear,
    LinearSpec,
    LinearSweepSpec,
    OneParameterContinuation,
    Polynomial,
    Study,
    TwoParameterContinuation,
    load_study,
    schema_reference,
    validate_text,
)

#: The same study as ../shared/hooks/smoke_linear_case2.yaml.
SMOKE = """\
name: smoke-linear-case2
model: classical
parameters: {K_psi: 0.3}
nonlinearity: {type: linear}
continuations:
  - name: ktheta
    type: one-parameter
    parameter: K1
    start: 0.5
    range: [-0.3, 0.5]
    periodic: false
    branch_points: true
"""
HEAD = "name: s\nmodel: classical\n"
MODELS: tuple[type[BaseModel], ...] = (
    Study,
    Linear,
    Polynomial,
    OneParameterContinuation,
    LinearSpec,
    LinearSweepSpec,
    AutoSettings,
)
KNOWN = (
    "C_l_alpha, C_psi, C_theta, I_x, I_y, K1, K2, K2_psi, K2_theta, K3, K3_psi, K3_theta, "
    "K_psi, K_theta, N, Omega, R, V, a, aero_coupling, c, rho"
)


def problems(text: str, filename: str = "s.yaml") -> list[str]:
    """The message lines of the StudyError that ``text`` raises."""
    with pytest.raises(StudyError) as caught:
        validate_text(text, filename)
    return caught.value.message.splitlines()


# --------------------------------------------------------------------------- valid studies
def test_smoke_study_loads_with_defaults():
    study = validate_text(SMOKE, "smoke.yaml")
    assert (study.name, study.description, study.model) == ("smoke-linear-case2", "", "classical")
    assert study.parameters == {"K_psi": 0.3}
    assert study.nonlinearity == (Linear(type="linear", dof="theta"),)  # one law: a list of one
    assert study.linear is None
    assert study.plots == ("bifurcation",)
    assert study.auto == AutoSettings()
    assert study.auto.max_steps is None and study.auto.timeout is None
    (run,) = study.continuations
    assert run == OneParameterContinuation(
        name="ktheta", type="one-parameter", parameter="K_theta", start=0.5, range=(-0.3, 0.5)
    )
    assert (run.periodic, run.branch_points) == (False, True)
    assert study.parameter_values() == {"K_psi": 0.3, "K2_theta": 0.0, "K3_theta": 0.0}
    assert study.variant().name == "classical_poly"
    assert study.source == SMOKE
    assert study.sha256 == hashlib.sha256(SMOKE.encode()).hexdigest()
    assert study.path == "smoke.yaml"


def test_load_study_reads_a_file(tmp_path):
    path = tmp_path / "smoke.yaml"
    path.write_text(SMOKE, encoding="utf-8")
    study = load_study(path)
    assert study.model_dump() == validate_text(SMOKE).model_dump()
    assert study.path == str(path)
    assert study.source == SMOKE


def test_study_is_frozen():
    study = validate_text(SMOKE)
    with pytest.raises(ValidationError):
        study.name = "other"
    with pytest.raises(ValidationError):
        study.continuations[0].start = 0.1


def test_every_model_forbids_extra_keys_and_is_frozen():
    for model in MODELS:
        assert model.model_config["extra"] == "forbid"
        assert model.model_config["frozen"] is True


def test_canonical_names_and_filled_starts():
    study = validate_text(
        HEAD
        + "parameters: {K_theta: 0.3, V: 5}\n"
        "nonlinearity: {type: polynomial, K2: -10, K3: 350.0}\n"
        "continuations:\n"
        "  - {name: k, type: one-parameter, parameter: K_theta, range: [-0.3, 0.5]}\n"
        "  - {name: v, type: one-parameter, parameter: V, range: [0, 10], periodic: true}\n"
        "  - {name: k3, type: one-parameter, parameter: K3, range: [0, 400]}\n"
        "  - {name: psi, type: one-parameter, parameter: K_psi, range: [0, 1]}\n"
        "linear: {sweeps: [{parameter: K_theta, range: [0, 1]}, {parameter: V, range: [0, 10], "
        "points: 11}]}\n"
        "plots: [bifurcation, linear]\n"
    )
    assert study.parameters == {"K_theta": 0.3, "V": 5.0}  # keys as written
    assert study.nonlinearity == (
        Polynomial(type="polynomial", dof="theta", K2=-10.0, K3=350.0),)
    assert [(c.parameter, c.start) for c in study.continuations] == [
        ("K_theta", 0.3),  # the override
        ("V", 5.0),
        ("K3_theta", 350.0),  # from the nonlinearity, by its thesis name K3
        ("K_psi", 0.4),  # the model's datum
    ]
    assert study.continuations[1].periodic is True
    assert study.linear.sweeps == (
        LinearSweepSpec(parameter="K_theta", range=(0.0, 1.0), points=201),
        LinearSweepSpec(parameter="V", range=(0.0, 10.0), points=11),
    )
    assert study.plots == ("bifurcation", "linear")
    assert study.parameter_values() == {"K_theta": 0.3, "V": 5.0, "K2_theta": -10.0,
                                        "K3_theta": 350.0}


def test_dof_psi_makes_K1_the_alias_of_K_psi():
    """With one law, K1, K2, K3 (the thesis' names) are its dof's stiffness and coefficients;
    what leaves the study is named by dof."""
    study = validate_text(
        HEAD + "parameters: {K_theta: 0.5, K1: 0.2}\nnonlinearity: {type: polynomial, dof: psi, "
        "K2: 3}\ncontinuations: [{name: k, type: one-parameter, parameter: K1, range: [0, 1]},"
        " {name: c, type: one-parameter, parameter: K2, range: [0, 4]}]\n"
    )
    assert study.variant().name == "classical_poly"  # one program for laws on either dof
    assert [(c.parameter, c.start) for c in study.continuations] == [("K_psi", 0.2),
                                                                     ("K2_psi", 3.0)]
    assert study.parameter_values() == {"K_theta": 0.5, "K_psi": 0.2, "K2_psi": 3.0,
                                        "K3_psi": 0.0}


def test_start_value_fills_a_start_left_unset():
    study = validate_text(SMOKE)
    run = OneParameterContinuation(name="k", type="one-parameter", parameter="K_psi", range=(0, 1))
    assert run.start is None
    assert run.start_value(study) == 0.3
    assert study.continuations[0].start_value(study) == 0.5


def test_auto_settings():
    study = validate_text(
        HEAD + "auto:\n  max_steps: 500\n  step_initial: 1e-3\n  step_min: 1.0e-6\n"
        "  step_max: 0.05\n  mesh_intervals: 40\n  collocation_points: 4\n"
        "  newton_max_iterations: 8\n  tolerance: 1e-7\n  timeout: 60\n  max_amplitude: 0.5\n"
    )
    assert study.auto == AutoSettings(
        max_steps=500, step_initial=1e-3, step_min=1e-6, step_max=0.05, mesh_intervals=40,
        collocation_points=4, newton_max_iterations=8, tolerance=1e-7, timeout=60.0,
        max_amplitude=0.5,
    )


def test_yaml_reading_avoids_yaml_1_1_surprises():
    """1e-6 is a number; yes/on and dates are strings; true/false are booleans."""
    study = validate_text(
        "name: 2024-01-01\nmodel: classical\ndescription: yes\nparameters: {C_psi: 1e-3}\n"
        "continuations: [{name: on, type: one-parameter, parameter: V, range: [0, 1e1], "
        "periodic: True}]\n"
    )
    assert (study.name, study.description) == ("2024-01-01", "yes")
    assert study.parameters == {"C_psi": 0.001}
    assert study.continuations[0].name == "on"
    assert study.continuations[0].range == (0.0, 10.0)
    assert study.continuations[0].periodic is True


def test_explicit_core_tags_and_a_byte_order_mark_are_fine():
    study = validate_text("\ufeffname: !!str 2024\nmodel: classical\nparameters: !!map {V: 1}\n")
    assert study.name == "2024"
    assert study.parameters == {"V": 1.0}


def test_nulls_mean_unset_where_a_key_is_optional():
    study = validate_text(HEAD + "linear: null\nnonlinearity: {type: linear, dof: ~}\n"
                          "auto: {timeout: null}\n")
    assert study.linear is None
    assert study.nonlinearity[0].dof == "theta"
    assert study.auto.timeout is None


def test_model_validate_fills_the_same_defaults():
    study = Study.model_validate(
        {"name": "s", "model": "classical",
         "continuations": [{"name": "k", "type": "one-parameter", "parameter": "K_theta",
                            "range": [0, 1]}]}
    )
    assert study.nonlinearity[0].dof == "theta"
    assert study.continuations[0].parameter == "K_theta"
    assert study.continuations[0].start == 0.4


# --------------------------------------------------------------------------- reasons
@pytest.mark.parametrize(
    ("body", "expected"),
    [
        ("parameters: {V: ten}\n", "s.yaml:3: parameters.V: expected a number, got 'ten'"),
        ("parameters: {V: '3'}\n", "s.yaml:3: parameters.V: expected a number, got '3'"),
        ("parameters: {V: true}\n", "s.yaml:3: parameters.V: expected a number, got true"),
        ("parameters: {V: [1]}\n", "s.yaml:3: parameters.V: expected a number, got a list"),
        ("parameters: {V: {a: 1}}\n", "s.yaml:3: parameters.V: expected a number, got a mapping"),
        ("parameters: {V: .nan}\n", "s.yaml:3: parameters.V: expected a finite number, got .nan"),
        ("parameters: {V: .inf}\n", "s.yaml:3: parameters.V: expected a finite number, got .inf"),
        (
            "nonlinearity: {type: polynomial, K2: -.inf}\n",
            "s.yaml:3: nonlinearity.K2: expected a finite number, got -.inf",
        ),
        ("auto: {max_steps: 2.5}\n", "s.yaml:3: auto.max_steps: expected an integer, got 2.5"),
        ("auto: {max_steps: false}\n", "s.yaml:3: auto.max_steps: expected an integer, got false"),
        ("description: 3\n", "s.yaml:3: description: expected a string, got 3"),
        ("description: null\n", "s.yaml:3: description: expected a string, got null"),
        ("parameters: [V]\n", "s.yaml:3: parameters: expected a mapping, got a list"),
        ("auto: 5\n", "s.yaml:3: auto: expected a mapping, got 5"),
        ("nonlinearity: linear\n", "s.yaml:3: nonlinearity: expected a mapping (one law) or a "
         "list of mappings (one law per dof), got 'linear'"),
        ("continuations: {a: 1}\n", "s.yaml:3: continuations: expected a list, got a mapping"),
        ("continuations: [5]\n", "s.yaml:3: continuations[0]: expected a mapping, got 5"),
        ("plots: bifurcation\n", "s.yaml:3: plots: expected a list, got 'bifurcation'"),
        (
            "nonlinearity: {type: cubic}\n",
            "s.yaml:3: nonlinearity.type: expected one of linear, polynomial, freeplay, "
            "got 'cubic'",
        ),
        (
            "nonlinearity: {type: 3}\n",
            "s.yaml:3: nonlinearity.type: expected one of linear, polynomial, freeplay, got 3",
        ),
        (
            "plots: [bifurcation, bubble]\n",
            "s.yaml:3: plots[1]: expected one of bifurcation, linear, root_locus, "
            "damping_multiples, projections, period, phase, boundary, amplitude, "
            "time_history, hub_path, law, poincare, spectrum, orbit_diagram, got 'bubble'",
        ),
        (
            "nonlinearity: {type: linear, dof: phi}\n",
            "s.yaml:3: nonlinearity.dof: expected one of theta, psi, got 'phi'",
        ),
        ("nonlinearity:\n  dof: psi\n", "s.yaml:3: nonlinearity.type: required key is missing"),
        (
            "plot_state: phi\n",
            "s.yaml:3: plot_state: expected one of theta, psi, dtheta, dpsi, got 'phi'",
        ),
        ("plot_state: [psi]\n", "s.yaml:3: plot_state: expected a string, got a list"),
        (
            "nonlinearity: {type: linear, K2: 1}\n",
            "s.yaml:3: nonlinearity.K2: unknown key (allowed: type, dof)",
        ),
        (
            "nonlinearity: {type: polynomial, K4: 1}\n",
            "s.yaml:3: nonlinearity.K4: unknown key (allowed: type, dof, K2, K3)",
        ),
        (
            "grid: {x: 1}\n",
            "s.yaml:3: grid: unknown key (allowed: name, description, model, parameters, "
            "nonlinearity, continuations, linear, simulations, plots, plot_state, cross_check, "
            "auto)",
        ),
        ("linear: {grid: 1}\n", "s.yaml:3: linear.grid: expected a mapping, got 1"),
        ("linear: {table: 1}\n",
         "s.yaml:3: linear.table: unknown key (allowed: sweeps, grid)"),
        (
            "parameters: {K_phi: 1}\n",
            f"s.yaml:3: parameters.K_phi: unknown parameter 'K_phi' for model classical "
            f"(known: {KNOWN})",
        ),
        (
            "parameters: {K2: 1}\n",
            "s.yaml:3: parameters.K2: set K2 under nonlinearity (type: polynomial, dof: theta)",
        ),
        (
            "parameters:\n  V: 3\n  K3: 1\n",
            "s.yaml:5: parameters.K3: set K3 under nonlinearity (type: polynomial, dof: theta)",
        ),
        (
            "linear:\n  sweeps:\n    - {parameter: V, range: [0, 10]}\n"
            "    - {parameter: K_psi, range: [0, 1], points: 1}\n",
            "s.yaml:6: linear.sweeps[1].points: must be >= 2, got 1",
        ),
        (
            "linear: {sweeps: [{parameter: V, range: [0, 10], points: 100001}]}\n",
            "s.yaml:3: linear.sweeps[0].points: must be <= 100000, got 100001",
        ),
        (
            "linear: {sweeps: [{parameter: V, range: [0, 10], points: 2.5}]}\n",
            "s.yaml:3: linear.sweeps[0].points: expected an integer, got 2.5",
        ),
        (
            "linear:\n  sweeps:\n    - parameter: Vee\n      range: [0, 10]\n",
            f"s.yaml:5: linear.sweeps[0].parameter: unknown parameter 'Vee' for model "
            f"classical (known: {KNOWN})",
        ),
        (
            "linear:\n  sweeps:\n    - parameter: V\n",
            "s.yaml:5: linear.sweeps[0].range: required key is missing",
        ),
        ("auto: {step_min: -1}\n", "s.yaml:3: auto.step_min: must be > 0, got -1"),
        ("auto: {timeout: 0}\n", "s.yaml:3: auto.timeout: must be > 0, got 0"),
        ("auto: {max_steps: 0}\n", "s.yaml:3: auto.max_steps: must be >= 1, got 0"),
        ("auto: {mesh_intervals: 1}\n", "s.yaml:3: auto.mesh_intervals: must be >= 2, got 1"),
        (
            "auto: {collocation_points: 8}\n",
            "s.yaml:3: auto.collocation_points: must be <= 7, got 8",
        ),
        (
            "auto: {step_max: 1, stepmax: 1}\n",
            "s.yaml:3: auto.stepmax: unknown key (allowed: max_steps, step_initial, step_min, "
            "step_max, mesh_intervals, collocation_points, newton_max_iterations, tolerance, "
            "timeout, max_amplitude)",
        ),
    ],
)
def test_reason(body, expected):
    assert problems(HEAD + body) == [expected]


RUN = "continuations:\n  - name: k1\n    type: one-parameter\n    parameter: K1\n"


@pytest.mark.parametrize(
    ("body", "expected"),
    [
        (
            "    range: [0.5, -0.3]\n",
            "s.yaml:7: continuations[0].range: expected [lower, upper] with lower < upper, "
            "got [0.5, -0.3]",
        ),
        (
            "    range: [0, 1, 2]\n",
            "s.yaml:7: continuations[0].range: expected [lower, upper], two numbers, "
            "got [0, 1, 2]",
        ),
        (
            "    range: [0, .nan]\n",
            "s.yaml:7: continuations[0].range[1]: expected a finite number, got .nan",
        ),
        (
            "    range: [0, 'a']\n",
            "s.yaml:7: continuations[0].range[1]: expected a number, got 'a'",
        ),
        (
            "    range: 0.5\n",
            "s.yaml:7: continuations[0].range: expected [lower, upper], two numbers, got 0.5",
        ),
        (
            "    start: 0.7\n    range: [-0.3, 0.5]\n",
            "s.yaml:7: continuations[0].start: start 0.7 is outside the range [-0.3, 0.5]",
        ),
        (  # unset start: the datum K1 = 0.4, reported on the range
            "    range: [0.5, 1.0]\n",
            "s.yaml:7: continuations[0].range: start 0.4 is outside the range [0.5, 1.0]",
        ),
        (
            "    start: x\n    range: [-0.3, 0.5]\n",
            "s.yaml:7: continuations[0].start: expected a number, got 'x'",
        ),
        (
            "    range: [0, 1]\n    periodic: yes\n",
            "s.yaml:8: continuations[0].periodic: expected true or false, got 'yes'",
        ),
        (
            "    range: [0, 1]\n    branch_points: 1\n",
            "s.yaml:8: continuations[0].branch_points: expected true or false, got 1",
        ),
        (
            "    range: [0, 1]\n    loci: [hopf]\n",
            "s.yaml:8: continuations[0].loci: unknown key (allowed: name, type, parameter, "
            "start, range, periodic, branch_points, period_doubling, spread_equilibria, "
            "start_state, orbits_at, seeds, explore, explore_initial, explore_transient, "
            "explore_section)",
        ),
        ("", "s.yaml:4: continuations[0].range: required key is missing"),
    ],
)
def test_continuation_reason(body, expected):
    assert problems(HEAD + RUN + body) == [expected]


def test_continuation_keys():
    item = "continuations:\n  - name: {}\n    type: {}\n    parameter: {}\n    range: [0, 1]\n"
    assert problems(HEAD + item.format("k", "three-parameter", "K1")) == [
        "s.yaml:5: continuations[0].type: expected one of one-parameter, two-parameter, "
        "got 'three-parameter'"
    ]
    assert problems(HEAD + item.format("k", "two-parameter", "K1")) == [
        "s.yaml:4: continuations[0].parameters: required key is missing",
        "s.yaml:6: continuations[0].parameter: unknown key (allowed: name, type, parameters, "
        "range, start, slices, seeds, loci, snaking_folds, method, resolution)",
        "s.yaml:7: continuations[0].range: expected a mapping, got a list",
    ]
    assert problems(HEAD + item.format("k", "one-parameter", "K_phi")) == [
        "s.yaml:6: continuations[0].parameter: unknown parameter 'K_phi' for model classical "
        f"(known: {KNOWN})"
    ]
    assert problems(HEAD + item.format("a b", "one-parameter", "K1")) == [
        "s.yaml:4: continuations[0].name: expected letters, digits, '_', '.', '-' (starting "
        "with a letter or digit), got 'a b'"
    ]
    assert problems(HEAD + "continuations:\n  - type: one-parameter\n    range: [0, 1]\n") == [
        "s.yaml:4: continuations[0].name: required key is missing",
        "s.yaml:4: continuations[0].parameter: required key is missing",
    ]


def test_duplicate_continuation_name():
    run = "  - {name: k1, type: one-parameter, parameter: V, range: [0, 10]}\n"
    assert problems(HEAD + "continuations:\n" + run * 3) == [
        "s.yaml:5: continuations[1].name: duplicate continuation name 'k1'",
        "s.yaml:6: continuations[2].name: duplicate continuation name 'k1'",
    ]


def test_study_name_reasons():
    assert problems("name: a b\nmodel: classical\n") == [
        "s.yaml:1: name: expected letters, digits, '_', '.', '-' (starting with a letter or "
        "digit), got 'a b'"
    ]
    assert problems("name: -a\nmodel: classical\n")[0].endswith("got '-a'")
    assert problems("name: 3\nmodel: classical\n") == ["s.yaml:1: name: expected a string, got 3"]
    assert problems(f"name: {'a' * 65}\nmodel: classical\n") == [
        "s.yaml:1: name: must be at most 64 characters, got 65"
    ]
    assert validate_text(f"name: {'a' * 64}\nmodel: classical\n").name == "a" * 64


def test_model_reasons():
    assert problems("name: s\nmodel: foo\n") == [
        "s.yaml:2: model: unknown model 'foo' (built-in: classical, gimballed, oscillators; "
        "or a model file path ending in .yaml)"
    ]
    assert problems("# a comment\n\nname: s\n") == ["s.yaml:3: model: required key is missing"]


def test_three_errors_are_reported_in_line_order():
    text = (
        "name: s\n"
        "model: classical\n"
        "parameters: {V: ten}\n"  # line 3
        "continuations:\n"
        "  - name: k1\n"
        "    type: one-parameter\n"
        "    parameter: K_phi\n"  # line 7
        "    range: [0, 1]\n"
        "auto: {tolerance: -1}\n"  # line 9
    )
    assert problems(text) == [
        "s.yaml:3: parameters.V: expected a number, got 'ten'",
        f"s.yaml:7: continuations[0].parameter: unknown parameter 'K_phi' for model classical "
        f"(known: {KNOWN})",
        "s.yaml:9: auto.tolerance: must be > 0, got -1",
    ]


def test_problems_on_one_line_are_sorted_by_path():
    assert problems(HEAD + "auto: {timeout: 0, max_steps: 0, foo: 1}\n") == [
        "s.yaml:3: auto.foo: unknown key (allowed: max_steps, step_initial, step_min, "
        "step_max, mesh_intervals, collocation_points, newton_max_iterations, tolerance, "
        "timeout, max_amplitude)",
        "s.yaml:3: auto.max_steps: must be >= 1, got 0",
        "s.yaml:3: auto.timeout: must be > 0, got 0",
    ]


def test_the_file_name_is_the_one_given():
    assert problems("name: s\nmodel: foo\n", "studies/x.yaml") == [
        "studies/x.yaml:2: model: unknown model 'foo' (built-in: classical, gimballed, "
        "oscillators; or a model file path ending in .yaml)"
    ]


# --------------------------------------------------------------------------- whole-file problems
@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("", "s.yaml: the study file is empty"),
        ("# nothing\n\n", "s.yaml: the study file is empty"),
        ("---\n", "s.yaml: the study file is empty"),
        ("- a\n- b\n", "s.yaml:1: a study must be a YAML mapping of keys, got a list"),
        ("hello\n", "s.yaml:1: a study must be a YAML mapping of keys, got 'hello'"),
        (
            "name: s\nmodel: a: b\n",
            "s.yaml:2: YAML syntax error: mapping values are not allowed here",
        ),
        (
            "name: s\nmodel: [1\n",
            "s.yaml:3: YAML syntax error: expected ',' or ']', but got '<stream end>'",
        ),
        ("name: s\n---\nname: t\n", "s.yaml:2: YAML syntax error: but found another document"),
        (
            "name: s\nmodel: \x00\n",
            "s.yaml:2: YAML syntax error: unacceptable character #x0000: special characters "
            "are not allowed",
        ),
        (
            HEAD + "nonlinearity:\n  type: polynomial\n  K2: 1\n  K2: 2\n",
            "s.yaml:6: nonlinearity.K2: duplicate key 'K2'",
        ),
        (
            "name: s\nname: t\nmodel: classical\n",
            "s.yaml:2: name: duplicate key 'name'",
        ),
        (
            HEAD + "description: " + "[" * 40 + "]" * 40 + "\n",
            "s.yaml:3: YAML nesting deeper than 32 levels is not allowed in study files",
        ),
        (
            HEAD + "parameters: {V: !!int ten}\n",
            "s.yaml:3: parameters.V: cannot read 'ten' as !!int",
        ),
    ],
)
def test_whole_file_problem(text, expected):
    assert problems(text) == [expected]


def test_anchors_and_aliases_are_refused():
    assert problems("name: &n s\nmodel: classical\ndescription: *n\n") == [
        "s.yaml:1: YAML anchors and aliases are not allowed in study files",
        "s.yaml:3: YAML anchors and aliases are not allowed in study files",
    ]


def test_non_core_tags_are_refused():
    assert problems("name: !foo s\nmodel: !!python/object:os.system x\nauto: !!set {}\n") == [
        "s.yaml:1: YAML tag '!foo' is not allowed in study files",
        "s.yaml:2: YAML tag '!!python/object:os.system' is not allowed in study files",
        "s.yaml:3: YAML tag '!!set' is not allowed in study files",
    ]
    assert problems("name: !!binary aGk=\nmodel: classical\n") == [
        "s.yaml:1: YAML tag '!!binary' is not allowed in study files"
    ]


def test_too_large_text():
    text = HEAD + "description: " + "a" * MAX_BYTES + "\n"
    size = len(text.encode())
    assert problems(text) == [
        f"s.yaml: the study file is too large ({size} bytes; the limit is 1048576)"
    ]


# --------------------------------------------------------------------------- files
def load_problems(path: Path) -> list[str]:
    with pytest.raises(StudyError) as caught:
        load_study(path)
    return caught.value.message.splitlines()


def test_missing_file(tmp_path):
    assert load_problems(tmp_path / "nope.yaml") == [
        "nope.yaml: cannot read the study file (No such file or directory)"
    ]


def test_directory(tmp_path):
    (tmp_path / "dir.yaml").mkdir()
    assert load_problems(tmp_path / "dir.yaml") == [
        "dir.yaml: cannot read the study file (Is a directory)"
    ]


def test_non_utf8_file(tmp_path):
    path = tmp_path / "latin.yaml"
    path.write_bytes(b"name: s\ndescription: caf\xe9\n")
    assert load_problems(path) == ["latin.yaml: not UTF-8 text (byte 0xe9 at offset 24)"]


def test_huge_file(tmp_path):
    path = tmp_path / "huge.yaml"
    path.write_bytes(b"name: s\n" + b"#" * (3 * MAX_BYTES))
    assert load_problems(path) == [
        f"huge.yaml: the study file is too large ({3 * MAX_BYTES + 8} bytes; the limit is "
        "1048576)"
    ]


def test_file_problems_use_the_base_name(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text("name: s\nmodel: foo\n")
    assert load_problems(path) == [
        "bad.yaml:2: model: unknown model 'foo' (built-in: classical, gimballed, oscillators; "
        "or a model file path ending in .yaml)"]


# --------------------------------------------------------------------------- no tracebacks
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.text(alphabet=st.sampled_from(list("name: model[]{},-&*!?'\"#\n\t .0123456789eKV")))
       .map(lambda tail: HEAD + tail))
def test_arbitrary_text_gives_a_study_or_a_study_error(text):
    try:
        assert isinstance(validate_text(text), Study)
    except StudyError as error:
        assert error.message


SCALARS = st.one_of(
    st.sampled_from(["~", "yes", ".nan", "-.inf", "[]", "{}", "[1, 2]", "{a: 1}", "'x'", "K1",
                     "theta", "polynomial", "2.5", "0", "-1", "1e400", "!!int x", "&a 1", "*a"]),
    st.integers(-10, 10).map(str),
    st.floats(allow_nan=False).map(repr),
)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_any_value_in_a_full_study_gives_a_study_or_a_study_error(data):
    template = (
        "name: {}\nmodel: {}\nparameters: {{K_psi: {}, {}: 1}}\n"
        "nonlinearity: {{type: {}, dof: {}, K2: {}}}\n"
        "continuations:\n  - {{name: {}, type: {}, parameter: {}, start: {}, range: [{}, {}],"
        " periodic: {}}}\n"
        "linear: {{sweeps: [{{parameter: {}, range: {}, points: {}}}]}}\nplots: [{}]\n"
        "auto: {{max_steps: {}, tolerance: {}}}\n"
    )
    values = [data.draw(SCALARS) for _ in range(template.count("{}"))]
    text = template.format(*values)
    try:
        assert isinstance(validate_text(text), Study)
    except StudyError as error:
        assert all(line.startswith("<study>") for line in error.message.splitlines())


# --------------------------------------------------------------------------- reference
def test_schema_reference_lists_every_key_with_a_description():
    table = schema_reference()
    lines = table.splitlines()
    assert lines[0] == "| Key | Type | Default | Description |"
    rows = {line.split("|")[1].strip().strip("`"): line for line in lines[2:]}
    expected = {"name", "description", "model", "parameters", "nonlinearity", "continuations",
                "linear", "plots", "plot_state", "cross_check", "auto", "nonlinearity[].type",
                "nonlinearity[].dof", "nonlinearity[].K2", "nonlinearity[].K3",
                "nonlinearity[].delta", "nonlinearity[].K_out", "nonlinearity[].K_in",
                "nonlinearity[].epsilon", "linear.sweeps",
                "linear.sweeps[].parameter", "linear.sweeps[].range", "linear.sweeps[].points",
                "linear.sweeps[].multiples", "linear.sweeps[].spacing",
                "linear.grid", "linear.grid.x", "linear.grid.y"}
    expected |= {f"linear.grid.{axis}.{k}" for axis in "xy" for k in ("parameter", "range",
                                                                      "points", "spacing")}
    expected |= {f"continuations[].{k}" for k in OneParameterContinuation.model_fields}
    expected |= {f"continuations[].{k}" for k in TwoParameterContinuation.model_fields}
    expected |= {f"auto.{k}" for k in AutoSettings.model_fields}
    expected |= {"continuations[].slices[].value", "continuations[].slices[].label"}
    expected |= {"simulations"} | {f"simulations[].{k}" for k in (
        "name", "parameters", "initial", "duration", "samples", "law")}
    assert set(rows) == expected
    for line in lines[2:]:
        cells = [c.strip() for c in line.strip("|").split(" | ")]
        assert len(cells) == 4 and all(cells), line
    assert "`linear` or `polynomial`" in rows["nonlinearity[].type"]
    assert "| required |" in rows["name"]
    assert "`201`" in rows["linear.sweeps[].points"]
    assert "N m/rad^3" in rows["nonlinearity[].K2"]


def test_every_field_has_a_description():
    for model in MODELS:
        for name, field in model.model_fields.items():
            assert field.description, f"{model.__name__}.{name}"


def test_docs_yaml_reference_is_generated_from_the_schema():
    from pathlib import Path

    from whirl_cli.study import schema_reference

    doc = (Path(__file__).resolve().parents[2] / "docs" / "study-yaml.md").read_text()
    assert schema_reference() in doc


# --------------------------------------------------------------------------- issue 13: 3, 4
HEAD = "name: s\nmodel: classical\n"


def test_a_parameter_given_by_name_and_by_alias_is_refused():
    """Before, ``{K1: 0.1, K_theta: 0.4}`` was accepted and the last one won."""
    assert problems(HEAD + "parameters: {K1: 0.1, K_theta: 0.4}\n") == [
        "s.yaml:3: parameters.K_theta: 'K_theta' and 'K1' are the same parameter ('K1' "
        "is an alias of K_theta); give it once"]
    pair = ("continuations:\n  - name: b\n    type: two-parameter\n    parameters: [K1, K_psi]\n"
            "    range: {K1: [-0.3, 0.5], K_psi: [0, 0.5], K_theta: [0, 1]}\n")
    assert problems(HEAD + pair) == [
        "s.yaml:7: continuations[0].range.K_theta: 'K_theta' and 'K1' are the same parameter "
        "('K1' is an alias of K_theta); give it once"]


@pytest.mark.parametrize(("override", "reason"), [
    ("I_y: 0", "I_y must be > 0 kg m^2, got 0"),
    ("N: 2.5", "N must be an integer >= 3, got 2.5"),
    ("N: 2", "N must be an integer >= 3, got 2"),
    ("rho: -1", "rho must be >= 0 kg/m^3, got -1"),
    ("R: 0", "R must be > 0 m, got 0"),
    ("Omega: -40", "Omega must be > 0 rad/s, got -40"),
    ("C_theta: -0.001", "C_theta must be >= 0 N m s/rad, got -0.001"),
    ("K_psi: 1.0e+12", "K_psi must be in [-1e+09, 1e+09] N m/rad, got 1000000000000.0"),
])
def test_non_physical_parameters_are_refused(override, reason):
    name = override.split(":")[0]
    assert problems(HEAD + f"parameters: {{{override}}}\n") == [
        f"s.yaml:3: parameters.{name}: {reason}"]


def test_law_coefficients_have_bounds_too():
    assert problems(HEAD + "nonlinearity: {type: polynomial, K2: 1.0e+308}\n") == [
        "s.yaml:3: nonlinearity.K2: K2_theta must be in [-1e+09, 1e+09] N m/rad^3, got 1e+308"]


def test_ranges_stay_within_the_bounds_and_whole_numbers_are_not_continued():
    text = HEAD + (
        "continuations:\n"
        "  - {name: a, type: one-parameter, parameter: V, range: [-1, 10]}\n"
        "  - {name: b, type: one-parameter, parameter: N, range: [3, 10]}\n"
        "  - {name: c, type: two-parameter, parameters: [K1, rho],"
        " range: {K1: [-0.3, 0.5], rho: [-1, 1]}}\n"
        "linear:\n  sweeps: [{parameter: N, range: [3, 5]}, {parameter: c, range: [-1, 1]}]\n")
    assert problems(text) == [
        "s.yaml:4: continuations[0].range: the range reaches -1.0, outside the bounds of V "
        "(>= 0 m/s)",
        "s.yaml:5: continuations[1].range: N takes whole numbers only (an integer >= 3) and "
        "cannot be continued",
        "s.yaml:6: continuations[2].range.rho: the range reaches -1.0, outside the bounds of "
        "rho (>= 0 kg/m^3)",
        "s.yaml:8: linear.sweeps[0].range: N takes whole numbers only (an integer >= 3) and "
        "cannot be swept",
        "s.yaml:8: linear.sweeps[1].range: the range reaches -1.0, outside the bounds of c "
        "(>= 0 m)"]


def test_orbits_at_values_outside_the_range_are_refused():
    text = HEAD + ("continuations:\n  - {name: a, type: one-parameter, parameter: K1,"
                   " range: [-0.3, 0.5], orbits_at: [0.1, 0.6]}\n")
    assert problems(text) == [
        "s.yaml:4: continuations[0].orbits_at[1]: 0.6 is outside the range [-0.3, 0.5]"]


def test_every_datum_lies_within_its_bounds_and_models_lists_them():
    from whirl_cli.models import all_variants

    for model in all_variants():
        for parameter in model.parameters:
            assert parameter.bounds.contains(parameter.default), parameter
        assert "an integer >= 3" in model.describe()


# --------------------------------------------------------------------------- issue 14: laws
def test_several_laws_each_name_their_dof_and_take_a_dof_once():
    text = HEAD + ("nonlinearity:\n"
                   "  - {type: polynomial, dof: theta, K2: 10}\n"
                   "  - {type: polynomial, K2: 10}\n"
                   "  - {type: linear, dof: theta}\n"
                   "  - {type: polynomial, dof: phi}\n")
    assert problems(text) == [
        "s.yaml:5: nonlinearity[1].dof: required in a list of laws (each law names its dof: "
        "theta, psi)",
        "s.yaml:6: nonlinearity[2].dof: a second law on theta (the first is at "
        "nonlinearity[0]); a dof takes at most one law",
        "s.yaml:7: nonlinearity[3].dof: expected one of theta, psi, got 'phi'"]


def test_a_law_coefficient_belongs_under_its_law():
    text = HEAD + ("parameters: {K2_psi: 1.0}\nnonlinearity:\n"
                   "  - {type: polynomial, dof: theta, K2: 10}\n"
                   "  - {type: polynomial, dof: psi}\n")
    assert problems(text) == [
        "s.yaml:3: parameters.K2_psi: set K2_psi under nonlinearity (type: polynomial, dof: "
        "psi) as K2"]


def test_with_several_laws_the_thesis_names_are_not_known():
    """K1, K2, K3 name a single law's dof; with two laws they would be ambiguous."""
    text = HEAD + ("nonlinearity:\n  - {type: polynomial, dof: theta, K2: 10}\n"
                   "  - {type: polynomial, dof: psi, K2: 10}\n"
                   "continuations: [{name: k, type: one-parameter, parameter: K1, "
                   "range: [0, 1]}]\n")
    (problem,) = problems(text)
    assert problem.startswith("s.yaml:6: continuations[0].parameter: unknown parameter 'K1'")
    assert "K2_psi, K2_theta" in problem and ", K1," not in problem


def test_two_laws_resolve_to_parameters_named_by_dof():
    study = validate_text(HEAD + ("parameters: {K_psi: 0.3}\nnonlinearity:\n"
                                  "  - {type: polynomial, dof: theta, K2: -10, K3: 350}\n"
                                  "  - {type: polynomial, dof: psi, K2: -10, K3: 350}\n"))
    assert study.parameter_values() == {"K_psi": 0.3, "K2_theta": -10.0, "K3_theta": 350.0,
                                        "K2_psi": -10.0, "K3_psi": 350.0}
    assert study.variant().name == "classical_poly"


# --------------------------------------------------------------------------- issue 17: 3
PAIR = ("continuations:\n  - name: b\n    type: two-parameter\n    parameters: [K1, K_psi]\n"
        "    range: {K1: [-0.3, 0.5], K_psi: [0, 0.5]}\n")


def test_slices_are_numbers_or_labelled_mappings():
    study = validate_text(HEAD + PAIR + "    slices: [0.4, {value: 0.3, label: case 2}]\n",
                          "s.yaml")
    (spec,) = study.continuations
    assert spec.slice_values == (0.4, 0.3)
    assert spec.slice_labels == ("", "case 2")


def test_a_labelled_slice_is_checked_like_a_number():
    assert problems(HEAD + PAIR + "    slices: [{value: 0.7, label: far}]\n") == [
        "s.yaml:8: continuations[0].slices[0]: slice 0.7 is outside the range [0.0, 0.5] of "
        "K_psi"]
    found = problems(HEAD + PAIR + "    slices: [{label: x}, {value: 0.1, name: y}, ten]\n")
    assert len(found) == 3
    assert found[2] == ("s.yaml:8: continuations[0].slices[2]: expected a finite number or a "
                        "mapping {value, label}, got 'ten'")
    assert problems(HEAD + PAIR + "    slices: [.nan]\n") == [
        "s.yaml:8: continuations[0].slices[0]: expected a finite number, got .nan"]
    assert found[0].startswith("s.yaml:8: continuations[0].slices[0].value: ")
    assert found[1].startswith("s.yaml:8: continuations[0].slices[1].name: ")


def test_a_law_type_of_the_wrong_type_is_a_message_not_a_crash():
    assert problems(HEAD + "nonlinearity: {type: [1, 2]}\n") == [
        "s.yaml:3: nonlinearity.type: expected one of linear, polynomial, freeplay, got a list"]
