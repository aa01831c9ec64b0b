"""The HDF5 layout is one mapping (issue 14, item 6): every field of every stored result
dataclass is declared once in ``output/store.py`` (or is a group name or a collection the file
layout holds), and the writer and the reader both go by those declarations."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import yaml

from whirl_cli import results
from whirl_cli.output import store

#: Fields the layout holds as a group's name or as collections of their own, not as fields.
STRUCTURAL = {
    results.Branch: {"name", "orbits"},
    results.Orbit: {"label"},
    results.SpecialPoint: set(),
    results.CrossCheck: set(),
    results.LinearSweep: set(),
    results.LinearGrid: {"flutter", "divergence"},
    results.Boundary: {"name", "loci", "intervals", "polygons",
                       "bounding_ends"},  # bounding_ends: attributes of the loci
    results.UnsafeInterval: set(),
    results.RunRecord: {"name"},
    results.FreeplayAmplitudes: {"branch"},
    results.SeedOutcome: set(),
    results.Simulation: {"name", "first_order"},  # first_order: the file's root attribute
}
DECLARATIONS = {
    results.Branch: store.BRANCH, results.Orbit: store.ORBIT,
    results.SpecialPoint: store.SPECIAL_POINT, results.CrossCheck: store.CROSS_CHECK,
    results.LinearSweep: store.LINEAR_SWEEP, results.LinearGrid: store.LINEAR_GRID,
    results.Boundary: store.BOUNDARY, results.UnsafeInterval: store.UNSAFE_INTERVAL,
    results.RunRecord: store.RUN, results.FreeplayAmplitudes: store.FREEPLAY,
    results.SeedOutcome: store.SEED, results.Simulation: store.SIMULATION,
}


def declared(fields) -> set[str]:
    """Field names a declaration stores: its own and those its datasets carry as attributes."""
    names = {f.name for f in fields if not f.derived}
    for f in fields:
        if f.columns is not None:
            names |= {n for n in f.columns if n is not None}
        if f.unit_field is not None:
            names.add(f.unit_field)
    return names


@pytest.mark.parametrize("cls", list(DECLARATIONS), ids=lambda c: c.__name__)
def test_every_field_is_declared_exactly_once(cls):
    fields = {f.name for f in dataclasses.fields(cls)}
    mapped = declared(DECLARATIONS[cls])
    assert mapped | STRUCTURAL[cls] == fields
    assert not mapped & STRUCTURAL[cls]
    keys = [f.hdf5_key() for f in DECLARATIONS[cls]]
    assert len(keys) == len(set(keys))  # no two fields in one place


def branch(name: str, kind: str, n: int) -> results.Branch:
    rng = np.random.default_rng(1)
    return results.Branch(
        name=name, kind=kind, origin=results.Origin("o"), parameter_names=("V",),
        parameter_units=("m/s",),
        state_names=("q1", "q2"), state_units=("m", "m/s"), parameters=rng.normal(size=(n, 1)),
        state_max=rng.normal(size=(n, 2)), state_min=rng.normal(size=(n, 2)),
        l2_norm=rng.normal(size=n), period=rng.normal(size=n), stable=rng.random(n) > 0.5,
        point_type=np.arange(n, dtype=np.int64), label=np.arange(n, dtype=np.int64),
        eigenvalues=rng.normal(size=(n, 2)) + 1j, end="range",
        orbits=(results.Orbit(3, 4, 1, np.array([0.5]), 0.2, np.linspace(0, 0.2, 5),
                              rng.normal(size=(5, 2))),) if n else (),
        stability_known=rng.random(n) > 0.5)


def synthetic_result() -> results.StudyResult:
    point = results.SpecialPoint("b_periodic", 1, 5, ("V",), np.array([0.5]), np.zeros(2), 0.2,
                                 True, label=3, status="bracketed", criticality="subcritical",
                                 note="n", bracket=np.array([0.4, 0.6]), residual=0.1,
                                 parameter_units=("m/s",), refined=np.array([0.51, 0.52]),
                                 refined_by="epsilon locus")
    result = results.StudyResult(
        "s", "m", (results.ContinuationResult(
            "c", "one-parameter", (branch("b_equilibrium", results.BranchKind.EQUILIBRIUM, 4),
                                   branch("b_periodic", results.BranchKind.PERIODIC, 3),
                                   branch("failed", results.BranchKind.PERIODIC, 0)), (point,),
            (results.CrossCheck("b_periodic", 1, "orbit", 0.5, 1.0, 1.001, True, "q1"),),
            seeds=(results.SeedOutcome(1, np.array([0.1, 0.0]), "periodic", 0.2, "b_periodic",
                                       "settled"),
                   results.SeedOutcome(2, np.array([0.0, 0.2]), "equilibrium", float("nan"),
                                       "", "at rest"))),
                   results.ContinuationResult("empty", "one-parameter", (), ())),
        (results.LinearSweep("V", "m/s", np.arange(3.0), np.ones((3, 2)) * 1j,
                             np.zeros((3, 2)), np.ones((3, 2)),
                             np.array([["FW", "BW"]] * 3)),
         results.LinearSweep("K", "N m/rad", np.arange(3.0), np.ones((3, 2)) * 1j,
                             np.zeros((3, 2)), np.ones((3, 2)),
                             np.array([["FW", "BW"]] * 3),
                             np.array([["nacelle", "gimbal"]] * 3))),
        (results.RunRecord("c.run", "ok", "ok", "IPS = 1\n", 0, 0.5, 4),), {"a": "b"},
        (results.Boundary("bd", ("V", "K"), ("m/s", "N m/rad"), "loci",
                          {"l1": ("hopf", np.ones((4, 2)))},
                          (results.UnsafeInterval(0.1, 1.0, 2.0, "flutter"),),
                          (np.zeros((5, 2)),), (0.1, 0.2)),),
        results.LinearGrid("V", "K", "m/s", "N m/rad", np.arange(3.0), np.arange(2.0),
                           np.zeros((2, 3)), np.zeros((2, 3), dtype=bool),
                           (np.ones((3, 2)),), ()),
        (results.ParameterValue("V", 7.0, 6.7, "m/s"),
         results.ParameterValue("K", 0.3, 0.4, "N m/rad")))
    return result


def test_a_result_with_every_kind_of_record_round_trips(tmp_path):
    result = synthetic_result()
    back = store.read(store.write(result, tmp_path / "r.h5"))
    assert repr(back) == repr(result)  # every value, type and order
    with store.opened(tmp_path / "r.h5") as handle:  # Floquet multipliers stored as such
        periodic = handle["continuations/c/branches/b_periodic"]
        assert "floquet_multipliers" in periodic and "eigenvalues" not in periodic
        assert periodic["floquet_multipliers"].attrs["units"] == "1"
        assert handle["linear/sweeps/V/values"].attrs["units"] == "m/s"


def test_every_physical_dataset_says_its_units(tmp_path):
    """Issue 17, item 5: every dataset of numbers that are not counts, codes or flags carries
    ``units`` (one per column where the columns differ, one per row for cross-checks)."""
    import h5py

    path = store.write(synthetic_result(), tmp_path / "r.h5")
    missing = []
    with h5py.File(path) as handle:
        def visit(name, item):
            if isinstance(item, h5py.Dataset) and item.dtype.kind in "fc" and \
                    "units" not in item.attrs:
                missing.append(name)
        handle.visititems(visit)
        points = handle["continuations/c/special_points"]
        assert list(points["parameters"].attrs["units"]) == ["m/s"]
        assert list(points["state"].attrs["units"]) == ["m", "m/s"]
        assert points["lyapunov"].attrs["units"] == "1/(s m^2)"
        checks = handle["continuations/c/cross_checks"]
        assert list(checks["parameter"].attrs["units"]) == ["m/s"]
        assert list(checks["expected"].attrs["units"]) == ["m"]  # q1's unit
        assert handle.attrs["whirl_schema"] == store.SCHEMA == 2
    assert missing == []


def test_every_branch_says_how_it_ends():
    """The ends AUTO's stops give, for a run of any kind (issue 17, item 5)."""
    from dataclasses import replace

    from whirl_cli.continuation.engine import run_end
    from whirl_cli.models import get_model

    model = get_model("oscillators")
    b = branch("b", results.BranchKind.EQUILIBRIUM, 4)
    b = replace(b, parameter_names=("V",), parameters=np.array([[0.0], [1.0], [2.0], [3.0]]),
                state_max=np.zeros((4, model.n_states)), state_min=np.zeros((4, model.n_states)),
                point_type=np.array([0, 0, 0, results.PointType.UZ]))  # AUTO's UZSTOP stop
    assert run_end(b, {"UZSTOP": {"V": [-1.0, 3.0]}}, model) == "range"
    assert run_end(b, {"UZSTOP": {"V": [-1.0, 5.0]}, "NMX": 4}, model) == "step limit"
    # at a bound without a UZ stop: one that only starts there (max_steps: 1) has not reached it
    start = replace(b, parameters=b.parameters[::-1], point_type=np.array([0, 0, 0, 9]))
    assert run_end(start, {"UZSTOP": {"V": [0.0, 3.0]}, "NMX": 4}, model) == "step limit"
    big = b.state_max.copy()
    big[-1, 0] = 1.5 * model.dofs[0].amplitude
    dof = model.dofs[0].name
    assert run_end(replace(b, state_max=big), {"UZSTOP": {f"max_{dof}": 1.5}}, model) == \
        "amplitude bound"
    assert run_end(replace(b, status="mx"), {}, model) == "no convergence (MX)"
    ended = replace(b, point_type=np.array([0, 0, 0, 9]))
    assert run_end(ended, {"NMX": 100}, model) == "AUTO end point"


@pytest.mark.parametrize("name", ["data/legacy_hardening_case2",
                                  "regression/references/linear_datum_airspeed"])
def test_a_schema_1_file_still_reads_and_plots(tmp_path, name):
    """Files written in schema 1 (no units on special points, no parameter set; a committed
    reference and an older result): they read, the parameter set read off the study stored
    with them, the units they lack left empty, and every plot kind draws."""
    from click.testing import CliRunner

    from whirl_cli.cli import cli

    from ..conftest import ROOT

    path = ROOT / "tests" / f"{name}.h5"
    with store.opened(path) as handle:
        assert handle.attrs["whirl_schema"] == 1
    result = store.read(path)
    written = yaml.safe_load(result.provenance.study_yaml).get("parameters", {})
    values = {p.name: p.value for p in result.parameters}
    assert result.parameters
    assert all(values[name] == value for name, value in written.items())
    assert all(p.parameter_units == () for c in result.continuations for p in c.special_points)
    run = CliRunner().invoke(cli, ["plot", str(path), "-o", str(tmp_path)])
    assert run.exit_code == 0, run.output
    assert list(tmp_path.glob("*.png"))


@pytest.mark.parametrize(("end", "truncated"), [
    ("step limit", True),
    ("returns to HB at V = 0.3 on main; other end: step limit", True),
    ("period blow-up: homoclinic approach; other end: amplitude bound", False),
    ("range", False), ("closed", False),
    ("not continued after its last chunk of steps", False),
])
def test_only_a_branch_stopped_at_the_step_limit_fails_the_study(end, truncated):
    from dataclasses import replace

    from whirl_cli.verdict import verdict

    b = replace(branch("p", results.BranchKind.PERIODIC, 3), end=end)
    result = results.StudyResult("s", "m", (results.ContinuationResult(
        "c", "one-parameter", (b,), ()),), (), ())
    problems = verdict(result).problems
    assert b.truncated is truncated
    assert len(problems) == truncated
    assert all(p.startswith("p stopped at the step limit") for p in problems)


def test_point_type_codes_are_named_in_the_file(tmp_path):
    """A reader with h5py alone can name every point type: the point_type datasets of a
    branch and of the special points carry flag_values and flag_meanings (CF style) that
    map each stored code to its name."""
    import h5py

    main = branch("main_down", "equilibrium", 4)
    point = results.SpecialPoint("main_down", 3, results.PointType.HB, ("V",),
                                 np.array([1.0]), np.zeros(2), 0.5, True)
    result = results.StudyResult("s", "m", (results.ContinuationResult(
        "c", "one-parameter", (main,), (point,)),), (), ())
    path = store.write(result, tmp_path / "r.h5")
    with h5py.File(path) as handle:
        for key in ("continuations/c/branches/main_down/point_type",
                    "continuations/c/special_points/point_type"):
            dataset = handle[key]
            names = dict(zip(dataset.attrs["flag_values"].tolist(),
                             dataset.attrs["flag_meanings"].split(), strict=True))
            assert names[3] == "HB" and names[101] == "HOMOCLINIC" and names[0] == "REGULAR"
            assert all(names[int(code)] == results.PointType(int(code)).name
                       for code in dataset[()])


def test_coordinates_are_hdf5_dimension_scales(tmp_path):
    """Where the declaration gives a coordinate (an axis along which exactly one 1-D dataset
    lies), the file says so: an orbit's time is the dimension scale of its states' first axis,
    a linear sweep's values of its eigenvalues, damping ratios, frequencies and whirl senses;
    a branch's points have no single coordinate and get none. Read back, nothing changes."""
    import h5py

    values = np.linspace(0.0, 1.0, 5)
    eigenvalues = np.column_stack([-1 + values + 2j, -1 + values - 2j])
    sweep = results.LinearSweep("V", "m/s", values, eigenvalues, -eigenvalues.real / 2.2,
                                np.abs(eigenvalues.imag), np.array([["FW", "BW"]] * 5))
    main = branch("main_down", "periodic", 6)
    result = results.StudyResult("s", "m", (results.ContinuationResult(
        "c", "one-parameter", (main,), ()),), (sweep,), ())
    path = store.write(result, tmp_path / "r.h5")
    with h5py.File(path) as handle:
        sweeps = handle["linear/sweeps/V"]
        for key in ("eigenvalues", "damping_ratio", "frequency", "whirl"):
            (scale,) = sweeps[key].dims[0].values()
            assert scale.name == "/linear/sweeps/V/values"
        orbit = handle["continuations/c/branches/main_down/orbits/3"]
        (scale,) = orbit["states"].dims[0].values()
        assert scale.name.endswith("/orbits/3/time") and not len(orbit["states"].dims[1])
        points = handle["continuations/c/branches/main_down"]
        assert all(not len(points[k].dims[0]) for k in ("period", "l2_norm", "stable"))
    read = store.read(path)
    np.testing.assert_array_equal(read.linear_sweeps[0].values, values)
    np.testing.assert_array_equal(read.continuations[0].branches[0].orbits[0].states,
                                  main.orbits[0].states)
