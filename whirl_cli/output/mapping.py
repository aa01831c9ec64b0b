"""How a result dataclass maps onto HDF5: one declaration per class, read and written by the
same few functions.

A :class:`Field` says where one dataclass field lives in the group of its object: an attribute,
or a dataset (with its units; a dataset may carry the names and units of its columns, which
are dataclass fields of their own). :func:`write_record` and :func:`read_record` store and
recover an object (a branch, an orbit, a linear sweep, ...) from those declarations;
:func:`write_table` and :func:`read_table` do the same for a list of objects stored column by
column (special points, cross-checks, unsafe intervals). ``store.py`` holds the declarations
and the file's layout of groups; nothing else names a field.

Reading checks what it reads against the same declarations: a required dataset or attribute
that is missing, one whose type does not fit its ``kind`` (a stability flag stored as
strings), or a dataset whose shape does not fit its ``shape`` (points whose columns do not
match their names) raise :class:`Damaged`, naming the HDF5 path.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import h5py
import numpy as np

_STR = h5py.string_dtype()
#: A :attr:`Field.default` meaning: the field must be in the file.
REQUIRED = object()


@dataclass(frozen=True)
class Field:
    """Where a dataclass field ``name`` is stored in its object's group.

    ``stored``: "attribute" or "dataset". ``kind``: "text", "int", "float", "bool",
    "optional_float" (None stored as NaN; each element converted on reading) or "array"
    (read as stored). ``key``: its HDF5 name, if not
    ``name``; ``units``: the ``units`` attribute of its dataset. Either may be a function of
    the object's ``kind`` attribute (periodic branches store Floquet multipliers where
    equilibria store eigenvalues). ``columns``: (names field, units field or None) of the
    object, written as the dataset's ``names`` and ``units`` attributes and read back from
    them; ``unit_field``: the object's field holding the dataset's ``units`` attribute.
    ``width``: columns of a table's 2-D column (an int, or the name of a context value), so
    that an empty table keeps its shape. ``default``: the value where an older file lacks the
    field (a function of nothing, or a value); a dataset with default None is optional: not
    written when the object's value is None. ``shape``: the dataset's axes, checked on
    reading: an int is a fixed size; a name is the size every dataset of the group naming
    it shares or, for a ``columns`` names field, the number of its names. ``derived``:
    written from the object's attribute of that name, never read (e.g. a point type's name
    beside its code). ``codes``: an IntEnum whose members the integer dataset holds, written
    beside it as the attributes ``flag_values`` and ``flag_meanings`` (the CF conventions'
    pair: the codes and their names, space-separated), so that a reader of the file alone
    can name them. ``vocabulary``: for a text field, what reads its text into the value (an
    enum, or a parser such as ``Origin.parse``; ValueError: the file is :class:`Damaged`);
    ``spelled``: what writes the value as that text (``str``).
    """

    name: str
    stored: str = "dataset"
    kind: str = "array"
    key: str | Callable[[str], str] | None = None
    units: str | Callable[[str], str] | None = None
    columns: tuple[str, str | None] | None = None
    unit_field: str | None = None
    width: int | str | None = None
    default: Any = REQUIRED
    derived: bool = False
    shape: tuple[int | str, ...] | None = None
    codes: Any = None
    vocabulary: Callable[[str], Any] | None = None
    spelled: Callable[[Any], str] = str

    def hdf5_key(self, kind: str = "") -> str:
        return _choose(self.key, kind) or self.name

    def hdf5_units(self, kind: str = "") -> str | None:
        return _choose(self.units, kind)


def _choose(value, kind: str):
    return value(kind) if callable(value) else value


class Damaged(ValueError):
    """A result file holding something else than its declarations say: ``where`` (the HDF5
    path of the group or dataset) and what is wrong there."""

    def __init__(self, where: str, reason: str) -> None:
        super().__init__(f"{where}: {reason}")


def _path(group: h5py.Group, key: str) -> str:
    return f"{group.name.rstrip('/')}/{key}"


def member(group: h5py.Group, key: str):
    """The required member ``key`` of ``group``; :class:`Damaged` where it is missing."""
    if key not in group:
        raise Damaged(_path(group, key), "missing")
    return group[key]


def attribute(obj, key: str):
    """The required attribute ``key`` of a group or dataset; :class:`Damaged` if missing."""
    if key not in obj.attrs:
        raise Damaged(obj.name, f"attribute {key!r} missing")
    return obj.attrs[key]


#: NumPy dtype kinds each field ``kind`` accepts in a file, and its word for them.
_ACCEPTS = {"text": ("OSU", "text"), "int": ("iu", "integers"), "float": ("iuf", "numbers"),
            "optional_float": ("iuf", "numbers"), "bool": ("biu", "booleans"),
            "array": ("biufc", "numbers")}
_FOUND = {"O": "strings", "S": "strings", "U": "strings", "b": "booleans", "i": "integers",
          "u": "integers", "f": "floats", "c": "complex numbers"}


def _check_type(where: str, dtype: np.dtype, kind: str, what: str = "") -> None:
    """:class:`Damaged` unless ``dtype`` (of a dataset, or of an attribute's value) fits a
    field of ``kind``."""
    accepted, word = _ACCEPTS[kind]
    if dtype.kind not in accepted:
        found = _FOUND.get(dtype.kind, f"of type {dtype}")
        raise Damaged(where, f"{what}stored as {found}, expected {word}")


def _check_shape(where: str, shape: tuple[int, ...], declared: tuple[int | str, ...],
                 sizes: dict[str, int], values: dict[str, Any]) -> None:
    """:class:`Damaged` unless ``shape`` fits ``declared`` (see :attr:`Field.shape`);
    ``sizes``: the named sizes seen so far in the group (updated), ``values``: the names
    read so far."""
    if len(shape) != len(declared):
        raise Damaged(where, f"shape {shape}, expected {len(declared)} dimension(s)")
    for size, axis in zip(shape, declared, strict=True):
        if isinstance(axis, int):
            expected, what = axis, ""
        elif axis in values:
            expected, what = len(values[axis]), f" (its {axis.replace('_', ' ')})"
        else:
            expected = sizes.setdefault(axis, size)
            what = f" ({axis}, as in the other datasets of its group)"
        if size != expected:
            raise Damaged(where, f"shape {shape}: {size} where {expected} belong{what}")


def _names(dataset: h5py.Dataset, key: str) -> tuple[str, ...]:
    """A dataset's ``names`` or ``units`` attribute (a list of strings)."""
    value = attribute(dataset, key)
    if np.size(value):  # an empty list is stored as an empty array of floats
        _check_type(dataset.name, np.asarray(value).dtype, "text", f"attribute {key!r} ")
    return texts(np.atleast_1d(value))


def text(value) -> str:
    """An HDF5 string (bytes or str) as str."""
    return value.decode() if isinstance(value, bytes) else str(value)


def texts(values) -> tuple[str, ...]:
    return tuple(text(v) for v in values)


def _strings(values) -> np.ndarray:
    return np.array([str(v) for v in values], dtype=object)


def _optional(value) -> float | None:
    """A float stored NaN where the dataclass holds None."""
    number = float(value)
    return number if np.isfinite(number) else None


_CONVERT: dict[str, Callable[[Any], Any]] = {
    "text": text, "int": int, "float": float, "bool": bool, "array": lambda v: v,
    "optional_float": _optional}
_NUMPY = {"int": np.int64, "float": float, "bool": bool}


def _encoded(values, kind: str) -> dict:
    """``create_dataset`` arguments for ``values`` (an array, or a sequence for a column)."""
    if kind == "text":
        array = np.asarray(values, dtype=object)
        return {"data": _strings(array.ravel()).reshape(array.shape), "dtype": _STR}
    if kind in _NUMPY:
        return {"data": np.asarray(values).astype(_NUMPY[kind])}
    if kind == "optional_float":
        return {"data": np.array([np.nan if v is None else v for v in values], dtype=float)}
    return {"data": values}


def _decoded(data, kind: str):
    """A dataset's value as the dataclass holds it (text arrays as str, elementwise)."""
    if kind == "text":
        array = np.asarray(data, dtype=object)
        return np.array(texts(array.ravel())).reshape(array.shape)
    if kind == "bool":
        return np.asarray(data).astype(bool)
    return data


def _attach(dataset: h5py.Dataset, field: Field, obj, kind: str) -> None:
    if field.columns is not None:
        names, units = field.columns
        dataset.attrs["names"] = list(getattr(obj, names))
        if units is not None:
            dataset.attrs["units"] = list(getattr(obj, units))
    elif field.unit_field is not None:
        dataset.attrs["units"] = getattr(obj, field.unit_field)
    elif field.hdf5_units(kind) is not None:
        dataset.attrs["units"] = field.hdf5_units(kind)
    _name_codes(dataset, field)


def _name_codes(dataset: h5py.Dataset, field: Field) -> None:
    """The ``flag_values``/``flag_meanings`` of a field with ``codes`` (see :class:`Field`)."""
    if field.codes is not None:
        dataset.attrs["flag_values"] = np.array([int(c) for c in field.codes], dtype=np.int64)
        dataset.attrs["flag_meanings"] = " ".join(c.name for c in field.codes)


def _attribute(field: Field, value):
    """An attribute value as h5py takes it: tuples as lists of names or arrays of numbers,
    words of a vocabulary as their text."""
    if field.vocabulary is not None:
        return field.spelled(value)
    if isinstance(value, tuple):
        return np.array(value, dtype=float) if field.kind == "float" else list(value)
    return value


def write_record(group: h5py.Group, obj, fields: Sequence[Field]) -> None:
    """Store ``obj``'s ``fields`` in ``group``: attributes first (in one update), then the
    datasets in declaration order."""
    kind = str(getattr(obj, "kind", ""))
    group.attrs.update({f.hdf5_key(kind): _attribute(f, getattr(obj, f.name)) for f in fields
                        if f.stored == "attribute"})
    for field in fields:
        if field.stored == "dataset":
            value = getattr(obj, field.name)
            if value is None and field.default is None:
                continue  # an optional dataset, absent (read back as None)
            dataset = group.create_dataset(field.hdf5_key(kind), **_encoded(value, field.kind))
            _attach(dataset, field, obj, kind)
    _attach_scales(group, fields, kind)


def _attach_scales(group: h5py.Group, fields: Sequence[Field], kind: str) -> None:
    """HDF5 dimension scales where the declaration gives one: an axis (a name in ``shape``,
    not a names field) along which exactly one one-dimensional dataset lies is that
    dataset's (a sweep's ``values``, a grid's ``x`` and ``y``, a time history's ``time``),
    attached to that axis of every other dataset of the group that has it. A tool reading
    the file alone (h5py's ``dims``, netCDF readers) then knows the coordinates."""
    names = {f.columns[0] for f in fields if f.columns is not None}
    stored = [f for f in fields if f.stored == "dataset" and f.shape
              and f.hdf5_key(kind) in group]
    lines: dict[str, list[Field]] = {}
    for field in stored:
        if len(field.shape) == 1 and isinstance(field.shape[0], str) \
                and field.shape[0] not in names:
            lines.setdefault(field.shape[0], []).append(field)
    scales = {axis: group[found[0].hdf5_key(kind)] for axis, found in lines.items()
              if len(found) == 1}
    for axis, scale in scales.items():
        scale.make_scale(axis)
    for field in stored:
        dataset = group[field.hdf5_key(kind)]
        for position, axis in enumerate(field.shape):
            if axis in scales and dataset != scales[axis]:
                dataset.dims[position].attach_scale(scales[axis])


def read_record(group: h5py.Group, fields: Sequence[Field]) -> dict[str, Any]:
    """The dataclass fields stored in ``group`` (the keyword arguments of its class), those
    a dataset's ``names``/``units`` attributes carry included; :class:`Damaged` where the
    group does not hold what ``fields`` declare."""
    values: dict[str, Any] = {}
    for field in (f for f in fields if f.stored == "attribute"):
        values[field.name] = _read_attribute(group, field)
    kind = str(values.get("kind", ""))
    sizes: dict[str, int] = {}
    for field in (f for f in fields if f.stored == "dataset" and not f.derived):
        key = field.hdf5_key(kind)
        if key not in group:
            values[field.name] = _missing(field, _path(group, key))
            continue
        dataset = group[key]
        if not isinstance(dataset, h5py.Dataset):
            raise Damaged(dataset.name, "a group where a dataset belongs")
        _check_type(dataset.name, dataset.dtype, field.kind)
        if field.columns is not None:
            names, units = field.columns
            values[names] = _names(dataset, "names")
            if units is not None:
                values[units] = _names(dataset, "units")
                if len(values[units]) != len(values[names]):
                    raise Damaged(dataset.name, f"{len(values[units])} units for "
                                  f"{len(values[names])} names")
        if field.unit_field is not None:
            values[field.unit_field] = text(attribute(dataset, "units"))
        if field.shape is not None:
            _check_shape(dataset.name, dataset.shape, field.shape, sizes, values)
        values[field.name] = _decoded(dataset[()], field.kind)
    return values


def _read_attribute(group: h5py.Group, field: Field):
    key = field.hdf5_key()
    if key not in group.attrs:
        return _missing(field, group.name, key)
    value = group.attrs[key]
    if np.size(value):  # an empty list is stored as an empty array of floats
        _check_type(group.name, np.asarray(value).dtype, field.kind, f"attribute {key!r} ")
    if field.kind == "array":
        return value
    if isinstance(value, np.ndarray):  # a list of names, or of numbers
        return tuple(_CONVERT[field.kind](v) for v in value)
    return _word(field, _CONVERT[field.kind](value), f"{group.name}: attribute {key!r}")


def _word(field: Field, value, where: str):
    """``value`` read as its field's vocabulary (as it is without one); :class:`Damaged`
    naming ``where`` if it is not a word of it."""
    return value if field.vocabulary is None else word(field.vocabulary, value, where,
                                                       field.name)


def word(vocabulary: Callable[[str], Any], value: str, where: str, what: str):
    """``value`` read as a word of ``vocabulary`` (e.g. an enum); :class:`Damaged` naming
    ``where`` and ``what`` it is if it is none."""
    try:
        return vocabulary(value)
    except ValueError:
        raise Damaged(where, f"unknown {what} {value!r}") from None


def _missing(field: Field, where: str, attribute_key: str = ""):
    """The default of a field missing from the file; :class:`Damaged` if it is required."""
    if field.default is REQUIRED:
        raise Damaged(where, f"attribute {attribute_key!r} missing" if attribute_key
                      else "missing")
    return field.default() if callable(field.default) else field.default


def write_table(group: h5py.Group, rows: Sequence, fields: Sequence[Field],
                context: dict[str, int] | None = None,
                attributes: dict[str, dict] | None = None) -> None:
    """Store ``rows`` (dataclass objects) in ``group``, one dataset per field: a column of
    one value per row (2-D for array fields, ``width`` wide). ``context``: values of the
    width names; ``attributes``: more attributes of a field's dataset (e.g. the names and
    units of a state column the rows do not hold), by field name."""
    context = context or {}
    attributes = attributes or {}
    for field in fields:
        values = [getattr(row, field.name) for row in rows]
        if field.vocabulary is not None:
            values = [field.spelled(v) for v in values]
        if field.width is not None:
            width = field.width if isinstance(field.width, int) else context[field.width]
            values = np.array(values, dtype=float).reshape(len(rows), width)
        dataset = group.create_dataset(field.hdf5_key(), **_encoded(values, field.kind))
        if field.columns is not None:
            names, units = field.columns
            dataset.attrs["names"] = list(getattr(rows[0], names)) if rows else []
            if units is not None:
                dataset.attrs["units"] = list(getattr(rows[0], units)) if rows else []
        elif field.hdf5_units() is not None:
            dataset.attrs["units"] = field.hdf5_units()
        _name_codes(dataset, field)
        dataset.attrs.update(attributes.get(field.name, {}))


def read_table(group: h5py.Group, cls: type, fields: Sequence[Field]) -> tuple:
    """The ``cls`` objects stored column by column in ``group`` by :func:`write_table`;
    :class:`Damaged` where a column is missing, of another type, or of another length or
    width than the others."""
    columns: dict[str, Any] = {}
    shared: dict[str, Any] = {}
    for field in (f for f in fields if not f.derived):
        key = field.hdf5_key()
        if key not in group:
            continue
        dataset = group[key]
        if not isinstance(dataset, h5py.Dataset):
            raise Damaged(dataset.name, "a group where a dataset belongs")
        _check_type(dataset.name, dataset.dtype, field.kind)
        columns[field.name] = dataset[()]
        if field.columns is not None:
            names, units = field.columns
            shared[names] = _names(dataset, "names")
            if units is not None and "units" in dataset.attrs:  # older files: none
                shared[units] = _names(dataset, "units")
        _check_column(dataset, field, len(columns[next(iter(columns))]), shared)
    rows = []
    for k in range(len(columns[next(iter(columns))]) if columns else 0):
        values = dict(shared)
        for field in (f for f in fields if not f.derived):
            if field.name in columns:
                values[field.name] = _word(field, _CONVERT[field.kind](columns[field.name][k]),
                                           _path(group, field.hdf5_key()))
            else:
                values[field.name] = _missing(field, _path(group, field.hdf5_key()))
        rows.append(cls(**values))
    return tuple(rows)


def _check_column(dataset: h5py.Dataset, field: Field, rows: int, shared: dict) -> None:
    """:class:`Damaged` unless a table's column has ``rows`` rows, and the width its field
    declares (a fixed width, or its number of names, where there are rows)."""
    width: tuple[int | str, ...] = ()
    if field.width is not None:
        width = (field.width if isinstance(field.width, int)
                 else field.columns[0] if field.columns is not None and rows else "width",)
    _check_shape(dataset.name, dataset.shape, ("rows", *width), {"rows": rows}, shared)
