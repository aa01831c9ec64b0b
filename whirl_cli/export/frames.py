"""Tables (:mod:`whirl_cli.export.tables`) as a pandas DataFrame or an xarray Dataset.

pandas and xarray are imported here, when first asked for (never on ``whirl run``'s path);
without them a :class:`~whirl_cli.errors.WhirlError` says what to install.
"""

from __future__ import annotations

import importlib

import numpy as np

from ..errors import WhirlError
from .tables import POINT_TYPES, Column, Table, flat_columns

#: The optional extra that installs pandas and xarray (and h5netcdf, for NetCDF files).
EXTRA = "pip install 'whirl[export]'"


def optional(module: str, needed_for: str):
    """The module ``module``, or :class:`WhirlError` naming the extra that installs it."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise WhirlError(f"{needed_for} needs {module}: {EXTRA}") from None


def dataframe(table: Table, split_complex: bool = False):
    """``table`` as a DataFrame: one row per row, one column per
    :func:`~whirl_cli.export.tables.flat_columns` header (``theta max [rad]``)."""
    pandas = optional("pandas", "a DataFrame")
    frame = pandas.DataFrame(dict(flat_columns(table, split_complex)))
    frame.index.name = table.columns[0].dims[0] if table.columns else None
    return frame


def dataset(table: Table):
    """``table`` as a Dataset: its columns as variables over named dimensions (``point``,
    ``state``, ``parameter``, ``mode``, ...), the labels of a dimension as its coordinate
    (``state`` = the state names, ``state_units`` beside), units and long names as
    attributes, point type codes with CF ``flag_values``/``flag_meanings``; each
    continuation parameter also a coordinate along the rows (e.g. ``K_theta``). A column
    named as a dimension is ``<name>_value`` (the special points' ``state_value``)."""
    xarray = optional("xarray", "an xarray Dataset")
    variables = {_variable(c.name, table): xarray.Variable(c.dims, _plain(c.values),
                                                           _attributes(c))
                 for c in table.columns if c.name != table.index}
    coordinates = _coordinates(table, {d for c in table.columns for d in c.dims}, variables)
    attributes = {k: v for k, v in table.attributes.items() if isinstance(v, str | int | float)}
    return xarray.Dataset(variables, coordinates, attributes)


def _variable(name: str, table: Table) -> str:
    """A column's variable name: its own, or ``<name>_value`` where a dimension's coordinate
    has it (a special point's ``state`` along the dimension ``state``)."""
    return f"{name}_value" if name in table.axes else name


def _plain(values: np.ndarray) -> np.ndarray:
    """Text as numpy strings (an empty column of objects has no type NetCDF can store)."""
    values = np.asarray(values)
    return values.astype(str) if values.dtype == object else values


def _attributes(column: Column) -> dict[str, object]:
    found: dict[str, object] = {"long_name": column.long_name} if column.long_name else {}
    if column.units:
        found["units"] = column.units
    if column.name == "point_type":
        found["flag_values"] = np.array([code for code, _ in POINT_TYPES], dtype=np.int64)
        found["flag_meanings"] = " ".join(name for _, name in POINT_TYPES)
    return found


def _coordinates(table: Table, dims: set[str], variables: dict) -> dict[str, object]:
    """The coordinates of ``table``'s dimensions ``dims`` (labels, their units, the rows'
    names where ``table.index`` gives them), and the continuation parameters along the rows."""
    found: dict[str, object] = {}
    for dim in sorted(dims):
        axis = table.axes.get(dim)
        if axis is None:
            continue
        found[dim] = (dim, np.array(axis.names, dtype=str) if axis.labelled
                      else np.arange(1, len(axis.names) + 1))
        if axis.units is not None:
            found[f"{dim}_units"] = (dim, np.array(axis.units, dtype=str))
    if table.index is not None:
        index = table[table.index]
        found[index.dims[0]] = (index.dims[0], _plain(index.values))
    if "parameters" in variables and "parameter" in table.axes:
        axis, values = table.axes["parameter"], np.asarray(table["parameters"].values)
        rows = table["parameters"].dims[0]
        for k, name in enumerate(axis.names):
            if name not in variables and name not in found and name not in dims:
                unit = axis.units[k] if axis.units else ""
                found[name] = (rows, values[:, k], {"units": unit} if unit else {})
    return found
