"""Model-dependent defaults of a study, filled on the raw data before the schema checks it.

``nonlinearity.dof`` (the family's default), canonical parameter names of continuations and
linear sweeps (``K_theta`` -> ``K1``), ``start`` (the parameter's study value) and the
``slices`` of a two-parameter continuation. :class:`whirl_cli.study.schema.Study` applies them
(a before-validator) and the meaning checks (:mod:`whirl_cli.study.checks`) read the study
values, so this module imports neither; it also holds what both share, the test for a finite
number and the stiffness law's parameter names.
"""

from __future__ import annotations

import math
from typing import Any

from pydantic import BaseModel

from ..models import FAMILIES, Model, get_model

#: Parameters of the stiffness law, set under ``nonlinearity`` rather than ``parameters``.
_LAW_PARAMETERS = ("K2", "K3")


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _finite(value: Any) -> float | None:
    """``value`` as a float if it is a finite number, else None."""
    return float(value) if _is_number(value) and math.isfinite(value) else None


def _variant_of(data: dict) -> Model | None:
    """The variant the raw study data asks for, or None when its model or dof is invalid."""
    family = data.get("model")
    if not isinstance(family, str) or family not in FAMILIES:
        return None
    _, dofs, default = FAMILIES[family]
    block = data.get("nonlinearity")
    dof = block.get("dof") if isinstance(block, dict) else getattr(block, "dof", None)
    dof = default if dof is None else dof
    return get_model(family, "polynomial", dof) if dof in dofs else None


def _study_values(data: dict, variant: Model) -> dict[str, float]:
    """Canonical name -> value: datum values, then valid overrides and K2/K3 from raw data."""
    values = variant.defaults()
    known = variant.known_parameter_names()
    parameters = data.get("parameters")
    for name, value in parameters.items() if isinstance(parameters, dict) else ():
        if name in known and _finite(value) is not None:
            values[variant.canonical(name)] = float(value)
    block = data.get("nonlinearity")
    if isinstance(block, dict) and block.get("type") == "polynomial":
        for name in _LAW_PARAMETERS:
            if _finite(block.get(name)) is not None:
                values[name] = float(block[name])
    return values


def _resolved(data: dict) -> dict:
    """``data`` with dof, canonical parameter names and start values filled where possible."""
    variant = _variant_of(data)
    if variant is None:
        return data
    data = dict(data)
    block = data.get("nonlinearity", {"type": "linear"})
    if isinstance(block, dict) and block.get("dof") is None:
        data["nonlinearity"] = {**block, "dof": variant.dof}
    elif isinstance(block, BaseModel) and block.dof is None:
        data["nonlinearity"] = block.model_copy(update={"dof": variant.dof})
    values = _study_values(data, variant)
    items = data.get("continuations")
    if isinstance(items, list | tuple):
        data["continuations"] = [_resolved_item(c, variant, values) for c in items]
    linear = data.get("linear")
    if isinstance(linear, dict) and isinstance(linear.get("sweeps"), list | tuple):
        sweeps = [_resolved_item(s, variant, None) for s in linear["sweeps"]]
        data["linear"] = {**linear, "sweeps": sweeps}
    linear = data.get("linear")
    if isinstance(linear, dict) and isinstance(linear.get("grid"), dict):
        grid = {k: _resolved_item(v, variant, None) for k, v in linear["grid"].items()}
        data["linear"] = {**linear, "grid": grid}
    return data


def _resolved_pair(item: dict, variant: Model, values: dict[str, float] | None) -> dict:
    """A two-parameter continuation with canonical parameter names, ``start`` and ``slices``
    filled; the keys of ``range`` stay as written (see ``TwoParameterContinuation.bounds``)."""
    pair = item.get("parameters")
    known = variant.known_parameter_names()
    if not (isinstance(pair, list | tuple) and len(pair) == 2
            and all(isinstance(p, str) and p in known for p in pair)):
        return item
    first, second = (variant.canonical(p) for p in pair)
    item = {**item, "parameters": [first, second]}  # range keys stay as written (line numbers)
    if values is not None:
        if item.get("start") is None:
            item["start"] = values[first]
        if not item.get("slices"):
            item["slices"] = [values[second]]
    return item


def _resolved_item(item: Any, variant: Model, values: dict[str, float] | None) -> Any:
    """A continuation or sweep with its canonical parameter name (and start, given values)."""
    if isinstance(item, dict) and item.get("type") == "two-parameter":
        return _resolved_pair(item, variant, values)
    name = item.get("parameter") if isinstance(item, dict) else None
    if not isinstance(name, str) or name not in variant.known_parameter_names():
        return item
    item = {**item, "parameter": variant.canonical(name)}
    if values is not None and item.get("start") is None:
        item["start"] = values[item["parameter"]]
    return item

