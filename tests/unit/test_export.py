"""``whirl export``: the exported files, read with the libraries their users read them with
(scipy.io.loadmat, xarray, pandas), hold the values of the HDF5 file, read here with h5py
itself; bad outputs are refused in one line, with nothing written and nothing replaced."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import h5py
import numpy as np
import pytest
import scipy.io

from ..conftest import ROOT

REFERENCES = ROOT / "tests" / "regression" / "references"
HARDENING = REFERENCES / "hardening_case2.h5"  # periodic branches: Floquet multipliers
AIRSPEED = REFERENCES / "linear_datum_airspeed.h5"  # a linear sweep


def whirl(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "whirl_cli", *map(str, args)],
                          capture_output=True, text=True, timeout=120, cwd=cwd)


#: AUTO's TY codes and their names, as AUTO's documentation lists them (0: a plain point).
AUTO_NAMES = {0: "REGULAR", 1: "BP", 2: "LP", 3: "HB", 4: "RG", 5: "LPC", 6: "BPC", 7: "PD",
              8: "TR", 9: "EP", -4: "UZ", -9: "MX"}


def named(codes) -> list[str]:
    return [AUTO_NAMES[int(c)] for c in np.ravel(codes)]


def texts(values) -> list[str]:
    return [v.decode() if isinstance(v, bytes) else str(v) for v in np.ravel(values)]


def branches(path):
    """(continuation, branch, its HDF5 group) of every branch in the file at ``path``."""
    handle = h5py.File(path, "r")
    return handle, [(c, b, handle[f"continuations/{c}/branches/{b}"])
                    for c in handle["continuations"]
                    for b in handle[f"continuations/{c}/branches"]]


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """The reference files exported in each format, once."""
    folder = tmp_path_factory.mktemp("export")
    for source in (HARDENING, AIRSPEED):
        for suffix in (".mat", ".nc", ".csv"):
            out = folder / f"{source.stem}{suffix}"
            extra = ["--branches"] if suffix == ".csv" else []
            done = whirl("export", source, "-o", out, *extra)
            assert done.returncode == 0, done.stderr
            assert f"wrote {out}" in done.stdout
    return folder


def _cells(value) -> list[str]:
    """A cellstr as loadmat returns it, as a list of str."""
    return [str(np.ravel(cell)[0]) if np.size(cell) else "" for cell in np.ravel(value)]


def test_mat_holds_every_branch_and_special_point_as_in_the_hdf5_file(exported):
    for source in (HARDENING, AIRSPEED):
        mat = scipy.io.loadmat(exported / f"{source.stem}.mat")
        handle, found = branches(source)
        with handle:
            for continuation, name, group in found:
                node = mat["continuations"][0, 0][continuation][0, 0]
                branch = node["branches"][0, 0][name][0, 0]
                for key in ("parameters", "state_max", "state_min", "period", "point_type",
                            "label"):
                    stored = group[key][()]
                    np.testing.assert_array_equal(branch[key].reshape(stored.shape), stored)
                complex_key = "floquet_multipliers" if "floquet_multipliers" in group \
                    else "eigenvalues"
                assert np.iscomplexobj(branch[complex_key])
                np.testing.assert_array_equal(branch[complex_key], group[complex_key][()])
                assert _cells(branch["parameter_names"]) == \
                    texts(group["parameters"].attrs["names"])
                assert _cells(branch["state_units"]) == \
                    texts(group["state_max"].attrs["units"])
                assert _cells(branch["type_name"]) == named(group["point_type"][()])
                points = handle[f"continuations/{continuation}/special_points"]
                table = node["special_points"][0, 0]
                assert _cells(table["type_name"]) == texts(points["type_name"][()])
                np.testing.assert_array_equal(table["parameters"], points["parameters"][()])
                np.testing.assert_array_equal(table["state"], points["state"][()])


def test_mat_loads_as_plain_structs_with_named_fields(exported):
    mat = scipy.io.loadmat(exported / "hardening_case2.mat", simplify_cells=True)
    k1 = mat["continuations"]["k1"]
    assert "LPC" in list(k1["special_points"]["type_name"])
    periodic = k1["branches"]["periodic_1"]
    assert periodic["kind"] == "periodic" and periodic["units"]["period"] == "s"
    assert list(k1["parameter_names"]) == ["K_theta"] or k1["parameter_names"] == "K_theta"
    with h5py.File(HARDENING, "r") as handle:
        assert mat["attributes"]["study_sha256"] == handle.attrs["study_sha256"]
        assert mat["attributes"]["study_name"] == handle.attrs["study_name"]


def test_netcdf_has_labelled_arrays_with_named_dimensions(exported):
    xarray = pytest.importorskip("xarray")
    path = exported / "hardening_case2.nc"
    handle, found = branches(HARDENING)
    with handle:
        for continuation, name, group in found:
            data = xarray.open_dataset(path, group=f"continuations/{continuation}/branches/"
                                                   f"{name}")
            with data:
                assert set(data.sizes) == {"point", "parameter", "state", "mode"}
                assert list(data["state"].values) == texts(group["state_max"].attrs["names"])
                assert list(data["state_units"].values) == \
                    texts(group["state_max"].attrs["units"])
                np.testing.assert_array_equal(data["state_max"].values, group["state_max"][()])
                np.testing.assert_array_equal(data["parameters"].values,
                                              group["parameters"][()])
                np.testing.assert_array_equal(data["K_theta"].values,
                                              group["parameters"][:, 0])
                key = "floquet_multipliers" if "floquet_multipliers" in group \
                    else "eigenvalues"
                np.testing.assert_array_equal(data[key].values, group[key][()])
                assert data["period"].attrs["units"] == "s"
                assert data["stable"].dtype == bool
                meanings = data["point_type"].attrs["flag_meanings"].split()
                values = list(data["point_type"].attrs["flag_values"])
                assert meanings[values.index(5)] == "LPC"
        points = handle["continuations/k1/special_points"]
        data = xarray.open_dataset(path, group="continuations/k1/special_points")
        with data:
            assert list(data["type_name"].values) == texts(points["type_name"][()])
            np.testing.assert_array_equal(data["state_value"].values, points["state"][()])


def test_netcdf_opens_as_one_tree_with_provenance_and_sweeps(exported):
    xarray = pytest.importorskip("xarray")
    with xarray.open_datatree(exported / "linear_datum_airspeed.nc") as tree:
        sweep = tree["linear/sweeps/V"].to_dataset()
        with h5py.File(AIRSPEED, "r") as handle:
            stored = handle["linear/sweeps/V"]
            np.testing.assert_array_equal(sweep["eigenvalues"].values,
                                          stored["eigenvalues"][()])
            np.testing.assert_array_equal(sweep["values"].values, stored["values"][()])
            assert sweep["values"].attrs["units"] == texts([stored["values"].attrs["units"]])[0]
            assert tree.attrs["study_sha256"] == handle.attrs["study_sha256"]
        assert set(sweep.sizes) == {"point", "mode"}


def test_csv_special_points_are_the_summary_and_branches_their_points(exported):
    pandas = pytest.importorskip("pandas")
    table = pandas.read_csv(exported / "hardening_case2.csv")
    summary = whirl("summary", HARDENING, "--format", "csv")
    assert (exported / "hardening_case2.csv").read_text() == summary.stdout
    handle, found = branches(HARDENING)
    with handle:
        points = handle["continuations/k1/special_points"]
        listed = [k for k, name in enumerate(texts(points["type_name"][()]))
                  if name not in ("RG", "UZ", "EP", "MX", "REGULAR")]
        np.testing.assert_allclose(table["K_theta [N m/rad]"],
                                   points["parameters"][listed, 0], rtol=0, atol=1e-12)
        for continuation, name, group in found:
            frame = pandas.read_csv(exported / f"hardening_case2_{continuation}_{name}.csv")
            assert list(frame["point"]) == list(range(len(group["period"])))
            # pandas' default parser may miss the last bit (float_precision="round_trip": none)
            close = {"rtol": 0, "atol": 1e-12}
            np.testing.assert_allclose(frame["K_theta [N m/rad]"], group["parameters"][:, 0],
                                       **close)
            np.testing.assert_allclose(frame["theta max [rad]"], group["state_max"][:, 0],
                                       **close)
            key, word = ("floquet_multipliers", "multiplier") \
                if "floquet_multipliers" in group else ("eigenvalues", "eigenvalue")
            values = group[key][:, 0]
            real = frame.filter(like=f"{word} 1 real").iloc[:, 0].to_numpy()
            finite = np.isfinite(values.real)
            np.testing.assert_allclose(real[finite], values.real[finite], **close)
            assert np.isnan(real[~finite]).all()
            assert list(frame["type_name"]) == named(group["point_type"][()])


def test_the_legacy_file_exports_too(tmp_path):
    for suffix in (".mat", ".nc", ".csv"):
        done = whirl("export", ROOT / "tests/data/legacy_hardening_case2.h5", "-o",
                      tmp_path / f"old{suffix}")
        assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("output, reason", [
    ("out.txt", "the suffix '.txt'; the output's suffix chooses the format, one of "
                ".mat, .nc, .csv"),
    ("out", "no suffix"),
])
def test_an_unknown_format_is_refused_in_one_line(tmp_path, output, reason):
    done = whirl("export", HARDENING, "-o", tmp_path / output)
    assert done.returncode == 1 and reason in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and not list(tmp_path.iterdir())


def test_branch_files_are_for_csv_only(tmp_path):
    done = whirl("export", HARDENING, "-o", tmp_path / "out.mat", "--branches")
    assert done.returncode == 1 and "a file per branch is for .csv only" in done.stderr
    assert not list(tmp_path.iterdir())


def test_existing_outputs_are_kept_unless_overwrite_and_never_another_kind(tmp_path):
    mine = tmp_path / "mine.mat"
    mine.write_text("my notes\n")
    for extra in ([], ["--overwrite"]):
        done = whirl("export", HARDENING, "-o", mine, *extra)
        assert done.returncode == 1, done.stdout
        assert mine.read_text() == "my notes\n"
    assert "not a MAT-file" in done.stderr
    # a result file is never replaced by a NetCDF export
    result = tmp_path / "result.nc"
    shutil.copy(HARDENING, result)
    done = whirl("export", HARDENING, "-o", result, "--overwrite")
    assert done.returncode == 1 and "a whirl result file, not a NetCDF-4 file" in done.stderr
    assert result.read_bytes() == HARDENING.read_bytes()
    # its own kind of file is replaced with --overwrite only
    ours = tmp_path / "ours.mat"
    assert whirl("export", HARDENING, "-o", ours).returncode == 0
    again = whirl("export", HARDENING, "-o", ours)
    assert again.returncode == 1 and "pass --overwrite" in again.stderr
    assert whirl("export", HARDENING, "-o", ours, "--overwrite").returncode == 0


def test_a_branch_file_in_the_way_stops_the_export_before_anything_is_written(tmp_path):
    os.mkfifo(tmp_path / "out_k1_main_down.csv")
    done = whirl("export", HARDENING, "-o", tmp_path / "out.csv", "--branches")
    assert done.returncode == 1 and "a FIFO (named pipe)" in done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out_k1_main_down.csv"]


def test_an_input_that_is_not_a_result_file_is_one_line(tmp_path):
    text = tmp_path / "notes.h5"
    text.write_text("hello\n")
    for source, reason in ((text, "not an HDF5 file"), (tmp_path / "absent.h5",
                                                          "no such file")):
        done = whirl("export", source, "-o", tmp_path / "out.mat")
        assert done.returncode == 1 and reason in done.stderr
        assert len(done.stderr.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.h5"]
