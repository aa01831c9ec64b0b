"""Model-dependent defaults of a study, filled on the raw data before the schema checks it.

``nonlinearity`` (one law mapping, or a list of them) gets its ``dof`` where a single law leaves
it out (the family's first dof) and the defaults a law derives from other values (freeplay's
``epsilon`` = delta/100); continuations and linear sweeps get canonical parameter names
(``K1`` -> ``K_theta``), ``start`` (the parameter's study value) and the ``slices`` of a
two-parameter continuation. :class:`whirl_cli.study.schema.Study` applies them (a
before-validator) and the meaning checks (:mod:`whirl_cli.study.checks`) read the study values,
so this module imports neither; it also holds what both share: the test for a finite number,
the law blocks of raw data and :class:`Names`, the parameter names a study may use.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

from pydantic import BaseModel

from ..documents.values import is_number
from ..models import LAWS, Model, Parameter, family_of, get_model, is_known

#: Study law types: ``linear`` is the polynomial law with zero coefficients.
LAW_TYPES = ("linear", *LAWS)
#: The thesis' names of the single law's coefficients (``K1`` its dof's linear stiffness).
THESIS_NAMES = ("K1", "K2", "K3")


def finite(value: Any) -> float | None:
    """``value`` as a float if it is a finite number, else None."""
    return float(value) if is_number(value) and math.isfinite(value) else None


def law_blocks(data: dict) -> list[tuple[tuple, Any]]:
    """(key path, block) of every law of raw study data: the ``nonlinearity`` mapping, or the
    items of its list; ``[((), None)]`` when there is none (linear springs)."""
    block = data.get("nonlinearity")
    if isinstance(block, list | tuple):
        return [(("nonlinearity", i), item) for i, item in enumerate(block)]
    if block is None:
        return [((), None)]
    return [(("nonlinearity",), block)]


def is_single(data: dict) -> bool:
    """True if the study gives its law as one mapping (or none), not as a list."""
    return not isinstance(data.get("nonlinearity"), list | tuple)


def _get(block: Any, key: str) -> Any:
    """A key of a law block given as a mapping or as a validated model."""
    if isinstance(block, dict):
        return block.get(key)
    return getattr(block, key, None)


def block_dof(block: Any, family: str, single: bool) -> Any:
    """The dof a law block names; a law given as a single mapping without one acts on the
    family's first dof (in a list every law names its dof)."""
    dof = _get(block, "dof")
    dofs = family_of(family).dof_names
    return dofs[0] if dof is None and single and dofs else dof


@dataclass(frozen=True)
class Names:
    """The parameter names a study may use: its variant's, and with one law the thesis' names
    ``K1``, ``K2``, ``K3`` for that law's dof (``K1`` = ``K_theta`` for a law on pitch).
    Duck-types the name lookups of :class:`whirl_cli.models.Model`."""

    model: Model
    aliases: tuple[tuple[str, str], ...] = ()

    @cached_property
    def _table(self) -> dict[str, str]:
        table = {name: self.model.canonical(name) for name in self.model.known_parameter_names()}
        return {**table, **dict(self.aliases)}

    def canonical(self, name: str) -> str:
        return self._table[name]

    def known_parameter_names(self) -> tuple[str, ...]:
        return tuple(sorted(self._table))

    def parameter(self, name: str) -> Parameter:
        return self.model.parameter(self.canonical(name))

    def defaults(self) -> dict[str, float]:
        return self.model.defaults()


def names_of(family: str, laws: list[tuple[str, Any]]) -> Names | None:
    """The :class:`Names` of a study of ``family`` with these (dof, block) laws, or None when
    a dof is unknown, named twice or a law type unknown."""
    declared = family_of(family)
    dofs = [dof for dof, _ in laws]
    if not all(isinstance(d, str) for d in dofs) or not set(dofs) <= set(declared.dof_names) \
            or len(set(dofs)) != len(dofs):
        return None
    types = {dof: _get(block, "type") for dof, block in laws}
    if not all(isinstance(t, str) and t in LAW_TYPES for t in types.values()):
        return None  # an unknown or malformed type (e.g. a list): reported by the schema
    per_dof = tuple("polynomial" if types.get(d, "linear") == "linear" else types[d]
                    for d in declared.dof_names)
    model = get_model(family, per_dof)
    aliases: tuple[tuple[str, str], ...] = ()
    if len(laws) == 1:
        (dof, _), = laws
        coefficients = model.coefficient_names(dof)
        aliases = (("K1", declared.dof(dof).stiffness),) + tuple(
            (key, coefficients[key]) for key in THESIS_NAMES[1:] if key in coefficients)
    return Names(model, aliases)


def names_of_data(data: dict) -> Names | None:
    """The :class:`Names` the raw study data asks for, or None when its model or laws are
    invalid (reported by the checks)."""
    family = data.get("model")
    if not is_known(family):
        return None
    blocks = law_blocks(data)
    single = is_single(data)
    laws = []
    for _, block in blocks:
        if block is None:
            if family_of(family).dofs:  # none: a first-order model has no stiffness law
                laws.append((family_of(family).dofs[0].name, {"type": "linear"}))
            continue
        if not isinstance(block, dict | BaseModel):
            return None
        dof = block_dof(block, family, single)
        if not isinstance(dof, str):
            return None
        laws.append((dof, block))
    return names_of(family, laws)


def study_values(data: dict, names: Names) -> dict[str, float]:
    """Canonical name -> value: datum values, then valid overrides and the law coefficients
    from raw data."""
    values = names.defaults()
    known = names.known_parameter_names()
    parameters = data.get("parameters")
    for name, value in parameters.items() if isinstance(parameters, dict) else ():
        if name in known and finite(value) is not None:
            values[names.canonical(name)] = float(value)
    blocks = law_blocks(data)
    for _, block in blocks:
        if not isinstance(block, dict):
            continue
        block = _with_derived_defaults(block)
        dof = block_dof(block, data["model"], is_single(data))
        if dof not in names.model.family.dof_names:
            continue
        for key, name in names.model.coefficient_names(dof).items():
            if finite(block.get(key)) is not None:
                values[name] = float(block[key])
    return values


def _with_derived_defaults(block: Any) -> Any:
    """A raw law block with the defaults its law derives from other values (freeplay's
    epsilon = delta/100) filled; anything else unchanged."""
    law = LAWS.get(block.get("type")) if isinstance(block, dict) else None
    if law is None:
        return block
    given = {key: float(value) for key, value in block.items()
             if isinstance(key, str) and finite(value) is not None}
    return {**block, **law.derived_defaults(given)}


def resolved(data: dict) -> dict:
    """``data`` with dof, law defaults, canonical parameter names and start values filled
    where possible."""
    data = _named_simulations(data)
    names = names_of_data(data)
    if names is None:
        return data
    data = dict(data)
    laws = data.get("nonlinearity")
    if isinstance(laws, list | tuple):
        data["nonlinearity"] = [_with_derived_defaults(b) for b in laws]
    elif laws is not None:
        data["nonlinearity"] = _with_derived_defaults(laws)
    block = data.get("nonlinearity", {"type": "linear"})
    dofs = names.model.family.dof_names
    if not dofs and "nonlinearity" not in data:
        data["nonlinearity"] = []  # a first-order model: no stiffness law
    if dofs and isinstance(block, dict) and block.get("dof") is None:
        data["nonlinearity"] = {**block, "dof": dofs[0]}
    elif dofs and isinstance(block, BaseModel) and getattr(block, "dof", None) is None:
        data["nonlinearity"] = block.model_copy(update={"dof": dofs[0]})
    values = study_values(data, names)
    items = data.get("continuations")
    if isinstance(items, list | tuple):
        data["continuations"] = [_resolved_continuation(c, names, values) for c in items]
    linear = data.get("linear")
    if isinstance(linear, dict) and isinstance(linear.get("sweeps"), list | tuple):
        sweeps = [resolved_parameter(s, names, None) for s in linear["sweeps"]]
        data["linear"] = {**linear, "sweeps": sweeps}
    linear = data.get("linear")
    if isinstance(linear, dict) and isinstance(linear.get("grid"), dict):
        grid = {k: resolved_parameter(v, names, None) for k, v in linear["grid"].items()}
        data["linear"] = {**linear, "grid": grid}
    return data


def _named_simulations(data: dict) -> dict:
    """``data`` with every simulation mapping named (``sim_<k>``, k its position from 1)."""
    items = data.get("simulations")
    if not isinstance(items, list | tuple):
        return data
    return {**data, "simulations": [
        {**item, "name": f"sim_{k}"} if isinstance(item, dict) and item.get("name") is None
        else item for k, item in enumerate(items, 1)]}


def _resolved_continuation(item: Any, names: Names, values: dict[str, float] | None) -> Any:
    """A continuation mapping resolved as its type resolves it (a mapping without a known
    ``type``: as the first type)."""
    from . import continuations  # its types resolve with this module's functions

    if not isinstance(item, dict):
        return item
    kind = continuations.get(item.get("type")) or continuations.first()
    return kind.resolved(item, names, values)


def resolved_pair(item: dict, names: Names, values: dict[str, float] | None) -> dict:
    """A two-parameter continuation with canonical parameter names, ``start`` and ``slices``
    filled; the keys of ``range`` stay as written (see ``TwoParameterContinuation.bounds``)."""
    pair = item.get("parameters")
    known = names.known_parameter_names()
    if not (isinstance(pair, list | tuple) and len(pair) == 2
            and all(isinstance(p, str) and p in known for p in pair)):
        return item
    first, second = (names.canonical(p) for p in pair)
    item = {**item, "parameters": [first, second]}  # range keys stay as written (line numbers)
    if values is not None:
        if item.get("start") is None:
            item["start"] = values[first]
        if not item.get("slices"):
            item["slices"] = [values[second]]
    return item


def resolved_parameter(item: Any, names: Names, values: dict[str, float] | None) -> Any:
    """A continuation or sweep with its canonical parameter name (and start, given values)."""
    name = item.get("parameter") if isinstance(item, dict) else None
    if not isinstance(name, str) or name not in names.known_parameter_names():
        return item
    item = {**item, "parameter": names.canonical(name)}
    if values is not None and item.get("start") is None:
        item["start"] = values[item["parameter"]]
    return item

