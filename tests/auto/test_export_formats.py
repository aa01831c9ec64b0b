"""A fresh result (linear case 2, real AUTO) exported to MATLAB, NetCDF and CSV: its Hopf
points read back with scipy.io.loadmat, xarray and pandas equal the HDF5 file's to 1e-12;
and a study changed with ``model_copy`` is stored as the study that ran."""

from __future__ import annotations

import subprocess
import sys

import h5py
import numpy as np
import pytest
import scipy.io

from whirl_cli import api
from whirl_cli.study import stored_study

from ..conftest import STUDIES


@pytest.fixture(scope="module")
def linear_case2(tmp_path_factory):
    """linear_case2.yaml run once by ``whirl run`` and exported by ``whirl export``."""
    folder = tmp_path_factory.mktemp("linear-case2")
    result = folder / "lc2.h5"
    run = [sys.executable, "-m", "whirl_cli", "run", str(STUDIES / "linear_case2.yaml"),
           "-o", str(result), "--no-plots", "-j", "2"]
    subprocess.run(run, check=True, capture_output=True, timeout=300)
    for suffix in (".mat", ".nc", ".csv"):
        subprocess.run([sys.executable, "-m", "whirl_cli", "export", str(result), "-o",
                        str(folder / f"lc2{suffix}")], check=True, capture_output=True,
                       timeout=120)
    return folder


def _hopf(path) -> np.ndarray:
    """K_theta of the Hopf points (AUTO's TY 3) in the HDF5 file, read with h5py."""
    with h5py.File(path, "r") as handle:
        points = handle["continuations/k1/special_points"]
        return points["parameters"][:, 0][points["point_type"][()] == 3]


def test_the_hopf_points_are_the_same_in_all_three_formats(linear_case2):
    xarray = pytest.importorskip("xarray")
    pandas = pytest.importorskip("pandas")
    hopf = _hopf(linear_case2 / "lc2.h5")
    assert len(hopf) == 2
    close = {"rtol": 0, "atol": 1e-12}

    mat = scipy.io.loadmat(linear_case2 / "lc2.mat", simplify_cells=True)
    table = mat["continuations"]["k1"]["special_points"]
    names = np.array(list(table["type_name"]))
    np.testing.assert_allclose(np.ravel(table["parameters"])[names == "HB"], hopf, **close)

    with xarray.open_dataset(linear_case2 / "lc2.nc",
                             group="continuations/k1/special_points") as data:
        chosen = data.where(data["type_name"] == "HB", drop=True)
        np.testing.assert_allclose(chosen["K_theta"].values, hopf, **close)
        assert data["K_theta"].attrs["units"] == "N m/rad"

    frame = pandas.read_csv(linear_case2 / "lc2.csv")
    np.testing.assert_allclose(frame[frame["type"] == "HB"]["K_theta [N m/rad]"], hopf,
                               **close)


def test_a_model_copy_is_computed_and_stored_as_the_study_that_ran(tmp_path):
    study = api.load(STUDIES / "linear_case2.yaml")
    changed = study.model_copy(update={"parameters": {"K_psi": 0.35}})
    api.save(api.run(changed, jobs=2), tmp_path / "changed.h5")
    api.save(api.run(study, jobs=2), tmp_path / "file.h5")
    back = api.read(tmp_path / "changed.h5")
    stored = stored_study(back.provenance)
    assert stored.parameters == {"K_psi": 0.35}
    assert {p.name: p.value for p in back.parameters}["K_psi"] == 0.35  # what was computed
    original = api.read(tmp_path / "file.h5").provenance
    assert back.provenance.study_sha256 != original.study_sha256
    assert original.study_yaml == (STUDIES / "linear_case2.yaml").read_text()
    assert list(_hopf(tmp_path / "changed.h5")) != list(_hopf(tmp_path / "file.h5"))
