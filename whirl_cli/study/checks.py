"""Meaning checks of a study against its model variant, on the raw data.

They add to the structural problems (malformed parts are left to those): parameter names the
study may use (:class:`~whirl_cli.study.resolve.Names`), law coefficients only under
``nonlinearity``, each law on a dof of the model and each dof with at most one law (every law
of a list naming its dof), a parameter given once, values and ranges inside the physical
bounds, the family's constraints on several parameters at once (e.g. I_d < I_y, for the
study's values and at each end of a range), unique continuation names, ``start``, ``slices``,
``orbits_at`` and ``explore`` inside ``range``, continuation names that share no stored AUTO
run name, one linear sweep per parameter and two different grid parameters (by any of their
names), ``plot_state``, seed keys, ``explore_initial`` keys
and the initial states of ``simulations`` states of the model, unique simulation names, their
overrides checked like the study's, ``law: exact`` only with a piecewise law, and what a law
requires of its coefficients together (freeplay: epsilon < delta, K_out > K_in).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from typing import Any

from ..documents.messages import choice_reason, dotted
from ..documents.source import Loc, Problem
from ..kinds import SimulationLaw
from ..models import family_of, is_known
from . import continuations
from .resolve import (
    Names,
    block_dof,
    finite,
    is_single,
    law_blocks,
    names_of_data,
    study_values,
)


def meaning_problems(data: dict) -> list[Problem]:
    """Checks against the model variant, on the raw data; malformed parts are skipped."""
    family = data.get("model")
    if not is_known(family):
        return []
    problems = _law_problems(data, family)
    if problems:
        return problems
    names = names_of_data(data)
    if names is None:
        return []
    values = study_values(data, names)
    problems = _override_problems(data.get("parameters"), names, family)
    problems += _constraint_problems(data.get("parameters"), names, family, values)
    problems += _plot_state_problems(data.get("plot_state"), family)
    for loc, block in law_blocks(data):
        if not isinstance(block, dict):
            continue
        dof = block_dof(block, family, is_single(data))
        found = [p for key, name in names.model.coefficient_names(dof).items() if key in block
                 for p in _bound_problems(loc + (key,), name, block[key], names)]
        problems += found or _combination_problems(loc, block, dof, names, values)
    items = data.get("continuations")
    problems += _continuation_problems(items, names, family, values)
    problems += _continuation_name_problems(items, names)
    linear = data.get("linear")
    sweeps = linear.get("sweeps") if isinstance(linear, dict) else None
    for i, sweep in _dict_items(sweeps):
        problems += _sweep_problems(("linear", "sweeps", i), sweep, names, family, values)
    problems += _repeated_sweeps(sweeps, names)
    grid = linear.get("grid") if isinstance(linear, dict) else None
    for axis in ("x", "y"):
        spec = grid.get(axis) if isinstance(grid, dict) else None
        if isinstance(spec, dict):
            axis_spec = {k: v for k, v in spec.items() if k != "multiples"}  # sweeps only
            problems += _sweep_problems(("linear", "grid", axis), axis_spec, names, family,
                                        values)
    problems += _grid_axes_problems(grid, names)
    problems += _simulation_problems(data.get("simulations"), names, family, values)
    return problems


def _known_canonical(name: Any, names: Names) -> str | None:
    """The canonical name of a parameter name the study may use, else None."""
    known = isinstance(name, str) and name in names.known_parameter_names()
    return names.canonical(name) if known else None


def _spelled(name: str, other: str, canonical: str) -> str:
    """How two spellings of one parameter name it ("" when they are the same)."""
    return "" if name == other else f" ({name!r} and {other!r} both name {canonical})"


def _repeated_sweeps(sweeps: Any, names: Names) -> list[Problem]:
    """A second linear sweep of a parameter, by any of its names: a result file stores one
    sweep per parameter (``linear/sweeps/<parameter>``)."""
    first: dict[str, tuple[int, str]] = {}
    problems: list[Problem] = []
    for i, sweep in _dict_items(sweeps):
        name = sweep.get("parameter")
        canonical = _known_canonical(name, names)
        if canonical is None:
            continue
        if canonical in first:
            k, other = first[canonical]
            problems.append((("linear", "sweeps", i, "parameter"),
                             f"a second sweep of {canonical}{_spelled(name, other, canonical)}"
                             f", the first is linear.sweeps[{k}]; a study sweeps a parameter "
                             "once (widen that range instead)"))
        else:
            first[canonical] = (i, name)
    return problems


def _grid_axes_problems(grid: Any, names: Names) -> list[Problem]:
    """The two axes of a linear grid, one parameter twice (by any of its names)."""
    axes = [grid.get(a) if isinstance(grid, dict) else None for a in ("x", "y")]
    given = [a.get("parameter") if isinstance(a, dict) else None for a in axes]
    x, y = (_known_canonical(name, names) for name in given)
    if x is None or x != y:
        return []
    return [(("linear", "grid", "y", "parameter"), f"the same parameter as x"
             f"{_spelled(given[1], given[0], y)}; a grid needs two different parameters")]


def _continuation_name_problems(items: Any, names: Names) -> list[Problem]:
    """Continuation names that would share AUTO run names (and the result file's run
    records, ``runs/<run>``) with another continuation's: a continuation's runs are named
    ``<name>.<run>``, and with a smoothed law (freeplay) a one-parameter continuation is
    repeated as ``<name>_eps<k>``."""
    named = [(i, item["name"], item.get("type")) for i, item in _dict_items(items)
             if isinstance(item.get("name"), str)]
    smoothed = bool(names.model.smoothing_parameters)
    problems: list[Problem] = []
    for i, name, _ in named:
        for _, other, kind in named:
            if name.startswith(other + "."):
                reason = f"its runs are named {other}.<run>"
            elif smoothed and _repeated(kind) and re.fullmatch(
                    re.escape(other) + r"_eps\d+", name):
                reason = (f"with a smoothed law its repetitions are named {other}_eps<k>")
            else:
                continue
            problems.append((("continuations", i, "name"), f"{name!r} would share AUTO run "
                             f"names with continuation {other!r} ({reason}); choose another "
                             "name"))
            break
    return problems


def _repeated(kind: Any) -> bool:
    """Whether a smoothed law repeats a continuation of type ``kind`` as ``<name>_eps<k>``."""
    found = continuations.get(kind)
    return found is not None and found.repeated


def _simulation_problems(items: Any, names: Names, family: str,
                         values: dict[str, float]) -> list[Problem]:
    """Each simulation: a unique name (given, or ``sim_<k>``), its overrides (as the study's,
    and the constraints with them on top of the study's values), initial-state keys states
    of the model, and ``law: exact`` only with a piecewise law (freeplay)."""
    states = family_of(family).state_names
    problems: list[Problem] = []
    taken: set[str] = set()
    for i, item in _dict_items(items):
        loc = ("simulations", i)
        unnamed = item.get("name") is None
        name = f"sim_{i + 1}" if unnamed else item["name"]
        if isinstance(name, str) and name in taken:
            how = " (an unnamed simulation's name, from its position)" if unnamed else ""
            problems.append((loc + ("name",), f"duplicate simulation name {name!r}{how}"))
        if isinstance(name, str):
            taken.add(name)
        parameters = item.get("parameters")
        found = _override_problems(parameters, names, family, loc + ("parameters",))
        if not found and isinstance(parameters, dict):
            mine = {names.canonical(k): float(v) for k, v in parameters.items()
                    if finite(v) is not None}
            found = _constraint_problems(parameters, names, family, {**values, **mine},
                                         loc + ("parameters",))
        problems += found
        initial = item.get("initial")
        if isinstance(initial, dict):
            problems += [(loc + ("initial", key), choice_reason(states, repr(key)))
                         for key in initial if isinstance(key, str) and key not in states]
        if item.get("law") == SimulationLaw.EXACT and not names.model.piecewise_dofs:
            problems.append((loc + ("law",), "the exact law needs a piecewise stiffness law "
                             "(type: freeplay) on a dof; this study has none (use smoothed)"))
    return problems


def _law_problems(data: dict, family: str) -> list[Problem]:
    """Each law on a dof of the model, each dof with at most one law, and a dof named by every
    law of a list."""
    dofs = family_of(family).dof_names
    single = is_single(data)
    problems: list[Problem] = []
    seen: dict[str, tuple] = {}
    for loc, block in law_blocks(data):
        if not isinstance(block, dict):
            continue
        if not dofs:
            problems.append((loc or ("nonlinearity",), f"model {family_of(family).name} has no "
                             "dofs (only first-order states): a stiffness law has nothing to "
                             "act on"))
            continue
        dof = block_dof(block, family, single)
        if dof is None:
            if block.get("type") is not None:
                problems.append((loc + ("dof",), "required in a list of laws (each law names "
                                 f"its dof: {', '.join(dofs)})"))
            continue
        if not isinstance(dof, str):
            continue  # a structural problem
        if dof not in dofs:
            problems.append((loc + ("dof",), choice_reason(dofs, repr(dof))))
        elif dof in seen:
            problems.append((loc + ("dof",), f"a second law on {dof} (the first is at "
                             f"{dotted(seen[dof])}); a dof takes at most one law"))
        else:
            seen[dof] = loc
    return problems


def _combination_problems(loc: Loc, block: dict, dof: str, names: Names,
                          values: dict[str, float]) -> list[Problem]:
    """What a law says about its coefficient values together (freeplay: epsilon < delta,
    K_out > K_in), each at the first of its keys the block gives (else at the block)."""
    law = names.model.law_on(dof)
    given = {key: values[name] for key, name in names.model.coefficient_names(dof).items()}
    return [(loc + next(((k,) for k in keys if k in block), ()), reason)
            for keys, reason in law.problems(given)]


def _law_range_problems(loc: Loc, canonical: str, bounds: Any, names: Names,
                        values: dict[str, float]) -> list[Problem]:
    """A continuation of a law coefficient (or of a stiffness a law names, freeplay's K_out)
    whose range reaches values the law refuses together with the others (epsilon >= delta,
    K_out <= K_in): the first such end."""
    ends = [finite(b) for b in bounds] if isinstance(bounds, list) and len(bounds) == 2 else []
    for dof in names.model.family.dof_names:
        coefficients = names.model.coefficient_names(dof)
        if canonical not in coefficients.values():
            continue
        law = names.model.law_on(dof)
        for end in (e for e in ends if e is not None):
            given = {key: (end if name == canonical else values[name])
                     for key, name in coefficients.items()}
            for _, reason in law.problems(given):
                return [(loc, f"the range reaches {end!r} where {reason}")]
    return []


def _plot_state_problems(state: Any, family: str) -> list[Problem]:
    """``plot_state`` a state of the model: a dof or a rate."""
    states = family_of(family).state_names
    if not isinstance(state, str) or state in states:
        return []
    return [(("plot_state",), choice_reason(states, repr(state)))]


def _sweep_problems(loc: Loc, spec: dict, names: Names, family: str,
                    values: dict[str, float]) -> list[Problem]:
    """The parameter and range of a linear sweep or grid axis."""
    name = spec.get("parameter")
    found = _parameter_problems(loc + ("parameter",), name, names, family)
    if found or not isinstance(name, str):
        return found
    canonical = names.canonical(name)
    bounds = spec.get("range")
    if spec.get("multiples") is True:
        found = _multiples_problems(loc, canonical, bounds, names)
        if found:
            return found
        datum = names.parameter(canonical).default
        bounds = [b * datum for b in bounds] if isinstance(bounds, list) and len(bounds) == 2 \
            and all(finite(b) is not None for b in bounds) else bounds
    return _range_problems(loc + ("range",), canonical, bounds, names, "swept") \
        or _range_constraint_problems(loc + ("range",), canonical, bounds, family, values)


def _multiples_problems(loc: Loc, canonical: str, bounds: Any, names: Names) -> list[Problem]:
    """A sweep in multiples of its parameter's datum: a non-zero datum, multiples > 0."""
    parameter = names.parameter(canonical)
    if parameter.default == 0.0:
        unit = f" {parameter.unit}" if parameter.unit not in ("", "1") else ""
        return [(loc + ("multiples",), f"the datum of {canonical} is 0{unit}: it has no "
                 f"multiples; give the range in {canonical}'s unit (multiples: false)")]
    ends = [finite(b) for b in bounds] if isinstance(bounds, list) and len(bounds) == 2 else []
    bad = [e for e in ends if e is not None and not e > 0]
    if bad:
        return [(loc + ("range",), f"with multiples: true the range is in multiples of the "
                 f"datum of {canonical} ({parameter.default:g}) and must be > 0, got "
                 f"{bad[0]!r}")]
    return []


def _dict_items(items: Any) -> Iterator[tuple[int, dict]]:
    """(index, item) for the mapping items of a list; nothing if ``items`` is no list."""
    if isinstance(items, list):
        yield from ((i, item) for i, item in enumerate(items) if isinstance(item, dict))


def _parameter_problems(loc: Loc, name: Any, names: Names, family: str) -> list[Problem]:
    if not isinstance(name, str) or name in names.known_parameter_names():
        return []
    known = ", ".join(names.known_parameter_names())
    return [(loc, f"unknown parameter {name!r} for model {family} (known: {known})")]


def _override_problems(parameters: Any, names: Names, family: str,
                       prefix: Loc = ("parameters",)) -> list[Problem]:
    """Overrides (the study's ``parameters``, or a simulation's at ``prefix``): known
    names, no law coefficient, each parameter once, inside its bounds."""
    problems: list[Problem] = []
    spelled: dict[str, str] = {}  # canonical name -> the key that gave it first
    for name, value in parameters.items() if isinstance(parameters, dict) else ():
        loc = prefix + (name,)
        found = _parameter_problems(loc, name, names, family)
        if not found and names.canonical(name) in names.model.law_parameter_names():
            found = [(loc, _law_coefficient_reason(name, names))]
        if not found:
            canonical = names.canonical(name)
            if canonical in spelled:
                found = [(loc, _twice(name, spelled[canonical], canonical))]
            spelled.setdefault(canonical, name)
            found = found or _bound_problems(loc, canonical, value, names)
        problems += found
    return problems


def _broken(family: str, values: dict[str, float]) -> list:
    """The family's constraints that ``values`` (canonical name -> SI value) break."""
    return [c for c in family_of(family).constraints if not c.holds(values)]


def _constraint_problems(parameters: Any, names: Names, family: str,
                         values: dict[str, float], prefix: Loc = ("parameters",)
                         ) -> list[Problem]:
    """Constraints the study's values break, reported at the first of their parameters the
    study sets under ``parameters`` (at ``parameters`` if it sets none of them); ``prefix``:
    where those overrides are (a simulation's ``parameters``)."""
    given = {names.canonical(k): k for k in parameters if isinstance(k, str)
             and k in names.known_parameter_names()} if isinstance(parameters, dict) else {}
    problems: list[Problem] = []
    for constraint in _broken(family, values):
        keys = [given[n] for n in constraint.names if n in given]
        loc = prefix + (keys[0],) if keys else prefix
        shown = ", ".join(f"{n} = {values[n]:g}" for n in constraint.names)
        problems.append((loc, f"{constraint.reason}, got {shown}"))
    return problems


def _range_constraint_problems(loc: Loc, canonical: str, bounds: Any, family: str,
                               values: dict[str, float]) -> list[Problem]:
    """A range end of ``canonical`` at which a constraint of the family breaks."""
    if not (isinstance(bounds, list) and len(bounds) == 2):
        return []
    for end in (finite(b) for b in bounds):
        if end is None:
            continue
        for constraint in _broken(family, {**values, canonical: end}):
            if canonical in constraint.names:
                return [(loc, f"the range reaches {end!r}, where {constraint.reason}")]
    return []


def _law_coefficient_reason(name: str, names: Names) -> str:
    """Where a law coefficient given under ``parameters`` belongs."""
    canonical = names.canonical(name)
    for dof in names.model.family.dof_names:
        for key, coefficient in names.model.coefficient_names(dof).items():
            if coefficient == canonical:
                law = names.model.law_on(dof).name
                there = "" if key == name else f" as {key}"
                return f"set {name} under nonlinearity (type: {law}, dof: {dof}){there}"
    return f"set {name} under nonlinearity"


def _twice(name: str, other: str, canonical: str) -> str:
    """Why a parameter given under two spellings is refused."""
    same = f"both name {canonical}" if canonical not in (name, other) else \
        f"{(other if name == canonical else name)!r} is an alias of {canonical}"
    return f"{name!r} and {other!r} are the same parameter ({same}); give it once"


def _bound_problems(loc: Loc, canonical: str, value: Any, names: Names) -> list[Problem]:
    """A value outside the parameter's physical bounds (malformed values are reported as
    structural problems)."""
    number = finite(value)
    parameter = names.parameter(canonical)
    if number is None or parameter.bounds.contains(number):
        return []
    return [(loc, f"{canonical} must be {parameter.bounds.text(parameter.unit)}, got "
             f"{value!r}")]


def _range_problems(loc: Loc, canonical: str, bounds: Any, names: Names,
                    swept: str) -> list[Problem]:
    """A continuation or sweep range reaching outside the parameter's physical bounds, or a
    parameter that takes whole numbers only (which cannot be continued or swept)."""
    parameter = names.parameter(canonical)
    if parameter.bounds.integer:
        return [(loc, f"{canonical} takes whole numbers only ({parameter.bounds.text()}) and "
                 f"cannot be {swept}")]
    ends = [finite(b) for b in bounds] if isinstance(bounds, list) and len(bounds) == 2 else []
    outside = [e for e in ends if e is not None and not parameter.bounds.contains(e)]
    if not outside:
        return []
    return [(loc, f"the range reaches {outside[0]!r}, outside the bounds of {canonical} "
             f"({parameter.bounds.text(parameter.unit)})")]


def _continuation_problems(
    items: Any, names: Names, family: str, values: dict[str, float]
) -> list[Problem]:
    problems: list[Problem] = []
    taken: set[str] = set()
    for i, item in _dict_items(items):
        loc = ("continuations", i)
        name = item.get("name")
        if isinstance(name, str) and name in taken:
            problems.append((loc + ("name",), f"duplicate continuation name {name!r}"))
        if isinstance(name, str):
            taken.add(name)
        kind = continuations.get(item.get("type")) or continuations.first()
        problems += kind.problems(loc, item, names, family, values)
    return problems


def pair_problems(loc: Loc, item: dict, names: Names, family: str,
                  values: dict[str, float]) -> list[Problem]:
    """A two-parameter continuation: its parameters, range, start, slices and seeds."""
    return _pair_problems(loc, item, names, family, values) + \
        _seed_problems(loc, item.get("seeds"), family)


def single_problems(loc: Loc, item: dict, names: Names, family: str,
                    values: dict[str, float]) -> list[Problem]:
    """A one-parameter continuation: its parameter, range, start, ``orbits_at``,
    ``explore``, seeds and the states it names."""
    parameter = item.get("parameter")
    found = _parameter_problems(loc + ("parameter",), parameter, names, family)
    if not found and isinstance(parameter, str):
        canonical = names.canonical(parameter)
        found = _range_problems(loc + ("range",), canonical, item.get("range"), names,
                                "continued") or _range_constraint_problems(
            loc + ("range",), canonical, item.get("range"), family, values)
        found = found or _start_problems(loc, item, values[canonical])
        found = found or _law_range_problems(loc + ("range",), canonical,
                                             item.get("range"), names, values)
        found += _orbits_problems(loc, item)
        found += _orbits_problems(loc, item, "explore")
        found += _seed_problems(loc, item.get("seeds"), family)
        for key in ("explore_initial", "start_state"):
            found += _initial_problems(loc + (key,), item.get(key), family)
        section = item.get("explore_section")
        if isinstance(section, str):
            found += _state_problems(loc + ("explore_section",), section, family)
    return found


def _seed_problems(loc: Loc, seeds: Any, family: str) -> list[Problem]:
    """Seeds naming states the model lacks."""
    states = family_of(family).state_names
    if not isinstance(seeds, list):
        return []
    return [(loc + ("seeds", k, name), choice_reason(states, repr(name)))
            for k, seed in enumerate(seeds) if isinstance(seed, dict)
            for name in seed if isinstance(name, str) and name not in states]


def _initial_problems(loc: Loc, initial: Any, family: str) -> list[Problem]:
    """An initial state (``explore_initial``) naming states the model lacks."""
    states = family_of(family).state_names
    if not isinstance(initial, dict):
        return []
    return [(loc + (name,), choice_reason(states, repr(name)))
            for name in initial if isinstance(name, str) and name not in states]


def _state_problems(loc: Loc, name: str, family: str) -> list[Problem]:
    """A state name (``explore_section``) the model lacks."""
    states = family_of(family).state_names
    return [] if name in states else [(loc, choice_reason(states, repr(name)))]


def _orbits_problems(loc: Loc, item: dict, key: str = "orbits_at") -> list[Problem]:
    """``orbits_at`` (or ``explore``: ``key``) values outside the continuation's range."""
    bounds, orbits = item.get("range"), item.get(key)
    if not (isinstance(bounds, list) and len(bounds) == 2 and isinstance(orbits, list)):
        return []
    lower, upper = (finite(b) for b in bounds)
    if lower is None or upper is None or not lower < upper:
        return []
    return [(loc + (key, k), f"{number!r} is outside the range [{lower!r}, {upper!r}]")
            for k, number in enumerate(map(finite, orbits))
            if number is not None and not lower <= number <= upper]


def _pair_problems(loc: Loc, item: dict, names: Names, family: str,
                   values: dict[str, float]) -> list[Problem]:
    """Parameters, range keys, start and slices of a two-parameter continuation."""
    pair = item.get("parameters")
    if not isinstance(pair, list) or len(pair) != 2:
        return []
    problems: list[Problem] = []
    for k, name in enumerate(pair):
        problems += _parameter_problems(loc + ("parameters", k), name, names, family)
    if problems or not all(isinstance(p, str) for p in pair):
        return problems
    first, second = (names.canonical(p) for p in pair)
    if first == second:
        return [(loc + ("parameters",), f"expected two different parameters, got {pair!r}")]
    bounds = item.get("range")
    if not isinstance(bounds, dict):
        return problems
    canonical: dict[str, str] = {}
    for key in (k for k in bounds if isinstance(k, str)):
        name = names.canonical(key) if key in names.known_parameter_names() else key
        if name in canonical:
            return [(loc + ("range", key), _twice(key, canonical[name], name))]
        canonical[name] = key
    if set(canonical) != {first, second}:
        return [(loc + ("range",), f"expected the keys {first}, {second}, got "
                 f"{', '.join(map(str, bounds)) or 'none'}")]
    for name in (first, second):
        problems += _range_problems(loc + ("range", canonical[name]), name,
                                    bounds[canonical[name]], names, "continued")
    if problems:
        return problems
    start_item = {"range": bounds[canonical[first]], "start": item.get("start")}
    problems += _start_problems(loc, start_item, values[first])
    limits = bounds[canonical[second]]
    slices = item.get("slices")
    if isinstance(limits, list) and len(limits) == 2 and isinstance(slices, list):
        lower, upper = (finite(b) for b in limits)
        for k, value in enumerate(slices):
            number = finite(value.get("value") if isinstance(value, dict) else value)
            if None not in (lower, upper, number) and lower < upper and not (
                    lower <= number <= upper):
                problems.append((loc + ("slices", k), f"slice {number!r} is outside the range "
                                 f"[{lower!r}, {upper!r}] of {second}"))
    return problems


def _start_problems(loc: Loc, item: dict, study_value: float) -> list[Problem]:
    """``start`` (or the study value when unset) outside ``range``."""
    bounds = item.get("range")
    if not isinstance(bounds, list) or len(bounds) != 2:
        return []
    lower, upper = (finite(b) for b in bounds)
    written = item.get("start") is not None
    start = finite(item["start"]) if written else study_value
    if lower is None or upper is None or start is None or not lower < upper:
        return []  # reported as a structural problem
    if lower <= start <= upper:
        return []
    key = "start" if written else "range"
    return [(loc + (key,), f"start {start!r} is outside the range [{lower!r}, {upper!r}]")]

