"""The result objects in a notebook: short reprs (name, kind, points, special points) and an
HTML view, continuations and branches looked up by name, a branch as a DataFrame or an xarray
Dataset in one call; and ``api.run`` runs as many jobs as ``whirl run`` by default."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from whirl_cli import api, cli
from whirl_cli.jobs import default_jobs

from ..conftest import ROOT

HARDENING = ROOT / "tests" / "regression" / "references" / "hardening_case2.h5"
AIRSPEED = ROOT / "tests" / "regression" / "references" / "linear_datum_airspeed.h5"


@pytest.fixture(scope="module")
def result():
    return api.read(HARDENING)


def test_reprs_are_short_and_say_what_is_there(result):
    text = repr(result)
    assert len(text) < 300
    assert "hardening-case2" in text and "k1 (one-parameter, 6 branches" in text
    assert "6 HB, 1 BP, 3 LPC" in text
    continuation = repr(result["k1"])
    assert len(continuation) < 300 and "points=628" in continuation
    branch = repr(result["k1"]["periodic_1"])
    assert branch == ("Branch('periodic_1', kind='periodic', points=128, "
                      "parameters=('K_theta',), special points: 3 LPC, status='ok')")
    sweep = repr(api.read(AIRSPEED).linear_sweeps[0])
    assert len(sweep) < 400 and "eigenvalues=<201 x 4 complex128>" in sweep


def test_every_result_class_with_arrays_has_a_short_repr(result):
    """Orbits, sweeps and the like hold arrays of any length: none repeats them."""
    objects = [result, *result.continuations, *result["k1"].branches,
               *result["k1"]["periodic_1"].orbits, *api.read(AIRSPEED).linear_sweeps]
    assert all(len(repr(o)) < 500 for o in objects), max(map(repr, objects), key=len)


def test_the_html_views_are_tables(result):
    page = result._repr_html_()
    assert page.startswith("<table>") and "<td>k1</td>" in page and "<td>628</td>" in page
    assert "<td>periodic_1</td>" in result["k1"]._repr_html_()
    assert page.count("<tr>") == 2  # header and one continuation
    assert result["k1"]["periodic_1"]._repr_html_().count("<td>LPC</td>") == 3


def test_continuations_and_branches_by_name(result):
    assert result["k1"] is result.continuation("k1") is result.continuations[0]
    branch = result["k1"]["secondary_1a"]
    assert branch is result.continuation("k1").branch("secondary_1a")
    assert branch.name == "secondary_1a"
    assert "k1" in result and "nope" not in result and "periodic_5" in result["k1"]
    assert [c.name for c in result] == ["k1"]
    with pytest.raises(KeyError, match=r"no branch 'main' in continuation 'k1' \(branches: "
                                       r"'main_down', "):
        result["k1"]["main"]
    with pytest.raises(KeyError, match=r"no continuation 'k2' in study 'hardening-case2' "
                                       r"\(continuations: 'k1'\)"):
        result.continuation("k2")


def test_a_branch_as_a_dataframe_in_one_call(result):
    frame = result["k1"]["periodic_1"].to_dataframe()
    with h5py.File(HARDENING, "r") as handle:
        group = handle["continuations/k1/branches/periodic_1"]
        assert len(frame) == len(group["period"])
        np.testing.assert_array_equal(frame["K_theta [N m/rad]"], group["parameters"][:, 0])
        np.testing.assert_array_equal(frame["psi min [rad]"], group["state_min"][:, 1])
        np.testing.assert_array_equal(frame["multiplier 3 [-]"],
                                      group["floquet_multipliers"][:, 2])
        np.testing.assert_array_equal(frame["period [s]"], group["period"][()])


def test_a_branch_as_an_xarray_dataset_in_one_call(result):
    pytest.importorskip("xarray")
    data = result["k1"]["main_down"].to_xarray()
    assert dict(data.sizes) == {"point": 204, "parameter": 1, "state": 4, "mode": 4}
    with h5py.File(HARDENING, "r") as handle:
        group = handle["continuations/k1/branches/main_down"]
        np.testing.assert_array_equal(data["state_max"].sel(state="theta"),
                                      group["state_max"][:, 0])
        np.testing.assert_array_equal(data["eigenvalues"].values, group["eigenvalues"][()])
    assert data["period"].attrs["units"] == "s" and data.attrs["kind"] == "equilibrium"


def test_api_run_runs_as_many_jobs_as_whirl_run(monkeypatch):
    from whirl_cli import pipeline

    jobs = next(p for p in cli.run.params if p.name == "jobs")
    assert jobs.default == default_jobs()
    monkeypatch.setattr("os.cpu_count", lambda: 5)
    seen = {}

    def run_study(study, workroot, jobs, **_):
        seen["jobs"] = jobs

    monkeypatch.setattr(pipeline, "run_study", run_study)
    api.run(ROOT / "studies" / "thesis_ch3" / "linear_case2.yaml")
    assert seen["jobs"] == 5 == default_jobs()
