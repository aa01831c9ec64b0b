"""A result as a NetCDF-4 file (xarray, written by h5netcdf: no system library needed).

Groups as in the HDF5 file: the root holds the provenance as attributes, ``parameters`` the
parameter set (dimension ``parameter``), ``continuations/<name>/branches/<branch>`` a branch
(dimensions
``point``, ``parameter``, ``state``, ``mode``), ``continuations/<name>/special_points`` its
special points (``special_point``), ``linear/sweeps/<parameter>`` a linear sweep. Read one
with ``xarray.open_dataset(path, group="continuations/k1/branches/main_down")``, all with
``xarray.open_datatree(path)``.
"""

from __future__ import annotations

from ..results import StudyResult
from .frames import dataset, optional
from .tables import (
    branch_table,
    parameter_table,
    root_attributes,
    special_point_table,
    sweep_table,
)


def groups(result: StudyResult) -> dict[str, object]:
    """Group path -> Dataset of every part of ``result``."""
    xarray = optional("xarray", "a NetCDF file")
    found: dict[str, object] = {"/": xarray.Dataset(attrs=root_attributes(result)),
                                "/parameters": dataset(parameter_table(result))}
    for continuation in result.continuations:
        where = f"/continuations/{continuation.name}"
        found[where] = xarray.Dataset(attrs={"name": continuation.name,
                                             "kind": str(continuation.kind)})
        found[f"{where}/special_points"] = dataset(special_point_table(continuation))
        for branch in continuation.branches:
            found[f"{where}/branches/{branch.name}"] = dataset(branch_table(branch))
    for sweep in result.linear_sweeps:
        found[f"/linear/sweeps/{sweep.parameter}"] = dataset(sweep_table(sweep))
    return found


def render(result: StudyResult) -> bytes:
    """The NetCDF-4 file of ``result``."""
    xarray = optional("xarray", "a NetCDF file")
    optional("h5netcdf", "a NetCDF file")
    tree = xarray.DataTree.from_dict(groups(result))
    return bytes(tree.to_netcdf(engine="h5netcdf"))
