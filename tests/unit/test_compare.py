"""``whirl compare`` on synthetic results: physics is compared, point indices are not."""

from __future__ import annotations

from dataclasses import replace

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

from whirl_cli.cli import cli
from whirl_cli.output import store
from whirl_cli.output.compare import (
    Tolerances,
    compare_curves,
    compare_files,
    compare_results,
    different_models,
    monotone_stretches,
)
from whirl_cli.results import (
    PointType,
    Provenance,
    SpecialPoint,
    StudyResult,
)

from .compare_data import HOPF, make_result


def with_branch(result: StudyResult, name: str, **changes) -> StudyResult:
    continuation = result.continuations[0]
    branches = tuple(replace(b, **changes) if b.name == name else b
                     for b in continuation.branches)
    return replace(result, continuations=(replace(continuation, branches=branches),))


def with_point(result: StudyResult, row: int, **changes) -> StudyResult:
    continuation = result.continuations[0]
    points = list(continuation.special_points)
    points[row] = replace(points[row], **changes)
    return replace(result, continuations=(replace(continuation,
                                                  special_points=tuple(points)),))


def paths(differences) -> list[str]:
    return [d.path for d in differences]


def test_identical_results_agree():
    assert compare_results(make_result(), make_result()) == []


def test_different_sampling_of_the_same_curves_agrees():
    """Point indices and step sizes are not physics: resampled branches still agree."""
    assert compare_results(make_result(), make_result(main_points=157, periodic_points=230)) \
        == []


def test_provenance_that_changes_legitimately_is_ignored():
    other = make_result()
    other = replace(other, provenance=replace(
        other.provenance, created="2027-01-01T00:00:00Z", whirl_version="9.9",
        auto_version="1.0", git_describe="abc-dirty"))
    assert compare_results(make_result(), other) == []
    other = replace(other, provenance=replace(other.provenance, study_sha256="def"))
    assert compare_results(make_result(), other) == []  # provenance: a note, not drift
    assert paths(compare_results(make_result(), other, strict=True)) == ["/@study_sha256"]


def test_moved_hopf_point_is_named_by_path():
    moved = with_point(make_result(), 0, parameters=np.array([HOPF + 1e-3]))
    (difference,) = compare_results(make_result(), moved)
    assert difference.path == "/continuations/k1/special_points/parameters[0]"
    assert "0.2" in difference.a and "0.201" in difference.b
    # within the default tolerance (1e-6 x the K1 span of 0.8): no drift
    assert compare_results(make_result(),
                           with_point(make_result(), 0, parameters=np.array([HOPF + 1e-7]))) \
        == []


def test_special_point_state_period_criticality():
    base = make_result()
    changed = with_point(base, 1, state=np.array([0.2, 0.1, 0.6, 0.4 + 1e-4]), period=0.41)
    changed = with_point(changed, 0, criticality="supercritical")
    assert sorted(paths(compare_results(base, changed))) == [
        "/continuations/k1/special_points/criticality[0]",
        "/continuations/k1/special_points/period[1]",
        "/continuations/k1/special_points/state[1, 3]"]


def test_missing_special_point_is_reported():
    base = make_result()
    continuation = base.continuations[0]
    fewer = replace(base, continuations=(replace(continuation,
                                                 special_points=continuation.special_points[:1]),))
    (difference,) = compare_results(base, fewer)
    assert difference.path == "/continuations/k1/special_points"
    assert "LPC" in difference.a


def test_symmetric_points_are_paired_by_position_not_order():
    base = make_result()
    continuation = base.continuations[0]
    twins = (SpecialPoint("main_down", 3, PointType.BP, ("K1",), np.array([0.1]),
                          np.array([0.05, 0, 0, 0]), np.nan, True),
             SpecialPoint("main_down", 4, PointType.BP, ("K1",), np.array([0.1]),
                          np.array([-0.05, 0, 0, 0]), np.nan, True))
    a = replace(base, continuations=(replace(
        continuation, special_points=continuation.special_points + twins),))
    b = replace(base, continuations=(replace(
        continuation, special_points=continuation.special_points + twins[::-1]),))
    assert compare_results(a, b) == []


def test_flipped_stability_over_a_stretch_is_caught():
    base = make_result()
    stable = base.continuations[0].branches[0].stable.copy()
    stable[20:60] = ~stable[20:60]
    (difference,) = compare_results(base, with_branch(base, "main_down", stable=stable))
    assert difference.path == "/continuations/k1/branches/main_down/stable"
    assert difference.a == "stable" and difference.b == "unstable"


def test_stability_may_disagree_within_one_cell_of_a_special_point():
    base = make_result()
    branch = base.continuations[0].branches[0]
    row = int(np.flatnonzero(branch.point_type == PointType.HB)[0])
    stable = branch.stable.copy()
    stable[row] = not stable[row]  # where exactly the switch falls is not physics
    assert compare_results(base, with_branch(base, "main_down", stable=stable)) == []


def test_branch_state_drift_is_caught_on_common_parameter_values():
    base = make_result()
    branch = base.continuations[0].branches[1]
    high = branch.state_max.copy()
    high[:, 0] *= 1.001
    found = compare_results(base, with_branch(base, "periodic_1", state_max=high))
    assert {d.path for d in found} == {"/continuations/k1/branches/periodic_1/state_max"}
    assert len(found) == 2  # both monotone stretches, below and above the fold
    assert all("K1 =" in d.note for d in found)


def test_branch_end_status_and_presence():
    base = make_result()
    changed = with_branch(base, "main_down", end="amplitude bound", status="mx")
    assert sorted(paths(compare_results(base, changed))) == [
        "/continuations/k1/branches/main_down/@end",
        "/continuations/k1/branches/main_down/@status"]
    continuation = base.continuations[0]
    fewer = replace(base, continuations=(replace(continuation,
                                                 branches=continuation.branches[:1]),))
    assert "/continuations/k1/branches/periodic_1" in paths(compare_results(base, fewer))


def test_extra_fold_changes_the_monotone_stretches():
    base = make_result()
    branch = base.continuations[0].branches[1]
    shorter = replace(branch, parameters=branch.parameters[:60], state_max=branch.state_max[:60],
                      state_min=branch.state_min[:60], stable=branch.stable[:60],
                      point_type=branch.point_type[:60])
    found = compare_results(base, with_branch(base, "periodic_1", **{
        k: getattr(shorter, k) for k in ("parameters", "state_max", "state_min", "stable",
                                          "point_type")}))
    assert "/continuations/k1/branches/periodic_1/parameters" in paths(found)


def test_linear_sweeps_compare_elementwise():
    base = make_result()
    sweep = base.linear_sweeps[0]
    close = replace(sweep, eigenvalues=sweep.eigenvalues * (1 + 1e-12))
    assert compare_results(base, replace(base, linear_sweeps=(close,))) == []
    far = replace(sweep, damping_ratio=sweep.damping_ratio * (1 + 1e-6))
    (difference,) = compare_results(base, replace(base, linear_sweeps=(far,)))
    assert difference.path.startswith("/linear/sweeps/V/damping_ratio[")
    whirl = sweep.whirl.copy()
    whirl[3, 0] = "BW"
    (difference,) = compare_results(base, replace(base, linear_sweeps=(replace(
        sweep, whirl=whirl),)))
    assert difference.path == "/linear/sweeps/V/whirl[3, 0]"


def test_mode_groups_compare_when_stored():
    """Mode groups (models with several, e.g. gimballed) compare element by element; stored
    in one file and not the other is a difference; absent in both (one group) agrees."""
    base = make_result()
    sweep = base.linear_sweeps[0]
    groups = np.array([["nacelle", "gimbal"]] * 11, dtype=object)
    grouped = replace(base, linear_sweeps=(replace(sweep, mode_group=groups),))
    assert compare_results(grouped, grouped) == []
    other = groups.copy()
    other[5, 1] = "nacelle"
    (difference,) = compare_results(grouped, replace(base, linear_sweeps=(replace(
        sweep, mode_group=other),)))
    assert difference.path == "/linear/sweeps/V/mode_group[5, 1]"
    (difference,) = compare_results(base, grouped)
    assert difference.path == "/linear/sweeps/V/mode_group"


def test_run_status_is_compared_but_not_wall_time():
    base = make_result()
    slower = replace(base, runs=(replace(base.runs[0], wall_seconds=5.0, n_points=7),))
    assert compare_results(base, slower) == []
    failed = replace(base, runs=(replace(base.runs[0], status="mx"),))
    assert paths(compare_results(base, failed)) == ["/runs/k1.main_down"]


def test_tolerances_from_cli_options():
    assert Tolerances.from_options() == Tolerances()
    chosen = Tolerances.from_options(rtol=1e-3, atol=1e-2)
    assert (chosen.period, chosen.linear, chosen.parameter) == (1e-3, 1e-3, 1e-3)
    assert (chosen.state, chosen.branch_state) == (1e-2, 1e-2)
    moved = with_point(make_result(), 0, parameters=np.array([HOPF + 1e-5]))
    assert compare_results(make_result(), moved) != []
    assert compare_results(make_result(), moved, chosen) == []


def test_monotone_stretches_cut_at_folds_and_lines():
    values = np.array([0.0, 1.0, 2.0, 1.5, 1.5, 1.5, 3.0])
    assert [(s.start, s.stop, s.direction) for s in monotone_stretches(values, 1e-9)] == [
        (0, 2, 1), (2, 3, -1), (3, 5, 0), (5, 6, 1)]
    assert [s.direction for s in monotone_stretches(np.array([1.0]), 1e-9)] == [0]


def circle(points: int, radius: float = 1.0) -> np.ndarray:
    angle = np.linspace(0, 2 * np.pi, points)
    return np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])


def test_curves_compare_by_distance_not_by_sampling():
    assert compare_curves("/boundaries/b/hopf", circle(4001), circle(3001), 1e-5) == []
    (difference,) = compare_curves("/boundaries/b/hopf", circle(4001), circle(3001, 1.001),
                                   1e-5)
    assert difference.path == "/boundaries/b/hopf"


def write_pair(tmp_path, curve_b: np.ndarray):
    """Two result files, equal but for a locus curve under /boundaries (layout of
    output/store.py)."""
    a, b = tmp_path / "a.h5", tmp_path / "b.h5"
    for path, curve in ((a, circle(2001)), (b, curve_b)):
        store.write(make_result(), path, overwrite=True)
        with h5py.File(path, "r+") as handle:
            group = handle.create_group("boundaries/k1-kpsi")
            group.attrs.update(parameters=["K1", "K_psi"], units=["N m/rad", "N m/rad"],
                               method="loci", slices=np.array([0.1, 0.2]))
            group.create_dataset("loci/hopf_1", data=curve).attrs["kind"] = "hopf"
            group.create_dataset("unsafe/polygon_0", data=circle(50, 0.5))
            table = group.create_group("unsafe_intervals")
            for key in ("slice_value", "lower", "upper"):
                table.create_dataset(key, data=np.array([0.1]))
            table.create_dataset("cause", data=["flutter"], dtype=h5py.string_dtype())
    return a, b


def test_files_with_boundaries(tmp_path):
    a, b = write_pair(tmp_path, circle(1500))
    assert compare_files(a, b) == []
    a, b = write_pair(tmp_path, circle(1500) + [0.0, 0.01])
    assert paths(compare_files(a, b)) == ["/boundaries/k1-kpsi/loci/hopf_1"]


@pytest.fixture
def files(tmp_path):
    a, b = tmp_path / "a.h5", tmp_path / "b.h5"
    store.write(make_result(), a)
    moved = with_point(make_result(main_points=150), 0, parameters=np.array([HOPF + 1e-3]))
    store.write(moved, b)
    return a, b


def test_cli_exit_status_and_output(files):
    a, b = files
    runner = CliRunner()
    same = runner.invoke(cli, ["compare", str(a), str(a)])
    assert same.exit_code == 0, same.output
    assert "agree" in same.output
    drift = runner.invoke(cli, ["compare", str(a), str(b)])
    assert drift.exit_code == 1
    assert "/continuations/k1/special_points/parameters[0]: K1 = 0.2 vs 0.201" in drift.output
    assert "differ (1 difference(s))" in drift.output
    relaxed = runner.invoke(cli, ["compare", str(a), str(b), "--rtol", "1e-2"])
    assert relaxed.exit_code == 0, relaxed.output


@pytest.mark.parametrize("option", ["--rtol", "--atol"])
@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "-1"])
def test_cli_refuses_tolerances_that_are_not_finite_and_non_negative(files, option, value):
    """A NaN tolerance made a file differ from itself (no difference is <= NaN); an infinite
    one accepts anything. Both are usage errors, before either file is read."""
    a, _ = files
    result = CliRunner().invoke(cli, ["compare", str(a), str(a), option, value])
    assert result.exit_code == 2, result.output
    assert f"Invalid value for '{option}'" in result.output
    assert "differ" not in result.output and "agree" not in result.output


def test_cli_prints_at_most_the_limit(tmp_path):
    base = make_result()
    sweep = base.linear_sweeps[0]
    other = replace(base, provenance=replace(base.provenance, study_sha256="zzz",
                                             study_yaml="other"), study_name="y",
                    linear_sweeps=(replace(sweep, values=sweep.values + 1,
                                           eigenvalues=sweep.eigenvalues + 1,
                                           damping_ratio=sweep.damping_ratio + 1,
                                           frequency=sweep.frequency + 1),))
    a, b = store.write(base, tmp_path / "a.h5"), store.write(other, tmp_path / "b.h5")
    result = CliRunner().invoke(cli, ["compare", str(a), str(b), "--limit", "3", "--strict"])
    assert result.exit_code == 1
    assert "... and 4 more" in result.output


@pytest.mark.parametrize("changes", [{"model": "gimballed_poly"},
                                     {"provenance": Provenance(model_key="another")}])
def test_results_of_different_models_are_not_compared(tmp_path, changes):
    """Another model variant, or a model file declaring other equations or values (its
    stored model_key): one line saying so, exit 1, no list of differences."""
    base = make_result()
    other = replace(base, **changes)
    a, b = store.write(base, tmp_path / "a.h5"), store.write(other, tmp_path / "b.h5")
    result = CliRunner().invoke(cli, ["compare", str(a), str(b)])
    assert result.exit_code == 1
    assert result.output.strip().splitlines() == [
        f"{a} and {b} are results of different models "
        f"({different_models(base, other)}): not compared"]
    assert different_models(base, base) == ""


def test_a_file_with_a_linear_grid_agrees_with_its_copy(tmp_path):
    """The grid's x and y are dimension scales: their links to the datasets are object
    references, which differ between two files of the same content."""
    import shutil

    from whirl_cli.results import LinearGrid

    x, y = np.linspace(0.0, 1.0, 4), np.linspace(0.0, 2.0, 3)
    grid = LinearGrid("K_theta", "K_psi", "N m/rad", "N m/rad", x, y,
                      np.subtract.outer(y, x), np.ones((3, 4), dtype=bool), (), ())
    path = store.write(replace(make_result(), linear_grid=grid), tmp_path / "a.h5")
    shutil.copy(path, tmp_path / "b.h5")
    result = CliRunner().invoke(cli, ["compare", str(path), str(tmp_path / "b.h5")])
    assert result.exit_code == 0, result.output
    assert "agree" in result.output
