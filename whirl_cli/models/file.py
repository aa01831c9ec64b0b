"""Model files: a model declared as YAML data, read into a :class:`~.declaration.Family`.

A model file (format: ``docs/model-files.md``) declares a family: its dofs (in state order,
each with the parameter of its linear structural stiffness), first-order ``states`` if any,
parameters (datum value, unit, bounds, aliases), optional named ``definitions``, the mass
matrix, the generalised forces G per dof and the ``rates`` F per first-order state, all in the
form

    M(p) q'' = G(q, q', x, p) - S(q, p),     S_i = K_i q_i   (or a stiffness law),
    x' = F(q, q', x, p),

with expressions written as text and read by :mod:`~.expressions` (a whitelist, never
``eval``). Problems are reported together as ``file:line: key: reason`` lines
(:class:`~whirl_cli.errors.StudyError`), nothing run; the checks at the datum follow once every
name resolves. What a file leaves out is derived:
``time_scale`` from the linear frequencies at the datum, ``symmetric`` and ``linear`` from
the forces (probed at the datum), each dof's rate name ``d<dof>``.

Reading a file needs neither sympy nor numpy (numpy only to derive an unstated
``time_scale``); sympy is imported when code is generated, by :class:`FileEquations`.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

from pydantic import BaseModel, BeforeValidator, Field, ValidationError

from ..documents.messages import report, translate
from ..documents.source import Tree, compose, read_text
from ..documents.values import Boolean, Number, Positive, Strict, Text, fail
from ..errors import StudyError
from .declaration import (
    AUTO_NAME_LENGTH,
    NAME_RE,
    NON_NEGATIVE,
    POSITIVE,
    RESERVED_NAMES,
    Bounds,
    Constraint,
    Dof,
    Family,
    FirstOrderState,
    ModeGroup,
    Parameter,
)
from .expressions import (
    CONSTANTS,
    FUNCTIONS,
    Comparison,
    Expression,
    ExpressionError,
    evaluate,
    parse,
    parse_comparison,
)
from .laws import LAWS

#: Names a study reserves for the single law's coefficients (``K1`` = the dof's stiffness).
THESIS_NAMES = frozenset({"K1", "K2", "K3"})
#: Largest number of dofs, and of first-order states, a model file may declare.
MAX_DOFS = 32
#: Probe states (multiples of each dof's amplitude) for the derived ``symmetric``/``linear``.
PROBES = (0.37, -0.61)


def _as_expression(value: Any) -> Expression:
    try:
        return parse(value)
    except ExpressionError as error:
        fail(str(error).replace("{", "{{").replace("}", "}}"))


def _as_comparison(value: Any) -> Comparison:
    try:
        return parse_comparison(value)
    except ExpressionError as error:
        fail(str(error).replace("{", "{{").replace("}", "}}"))


def _as_symbol(value: Any) -> str:
    if not isinstance(value, str) or not NAME_RE.fullmatch(value):
        fail("expected a name of letters, digits and '_' starting with a letter, got {got}")
    if value.lower() in RESERVED_NAMES or value.lower().startswith("w_") or value.startswith(
            "_"):
        fail("{got} is reserved by the generated Fortran (or starts with w_)")
    if value in FUNCTIONS or value in CONSTANTS:
        fail("{got} is the name of a function or constant of expressions")
    if len(value) > AUTO_NAME_LENGTH:
        fail(f"must be at most {AUTO_NAME_LENGTH} characters (AUTO's names), got {{got}}")
    return value


def _as_bounds(value: Any) -> Bounds | None:
    if value is None:
        return None
    if value == "positive":
        return POSITIVE
    if value == "non-negative":
        return NON_NEGATIVE
    if isinstance(value, list) and len(value) == 2 and all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
            for v in value) and value[0] < value[1]:
        return Bounds(lower=float(value[0]), upper=float(value[1]))
    fail("expected `positive`, `non-negative` or [lower, upper] with lower < upper, "
          "got {value}")


def _as_model_name(value: Any) -> str:
    if not isinstance(value, str) or not NAME_RE.fullmatch(value) or len(value) > 40:
        fail("expected a name of letters, digits and '_' starting with a letter, at most 40 "
              "characters, got {got}")
    return value


Expr = Annotated[Any, BeforeValidator(_as_expression)]
Symbol = Annotated[str, BeforeValidator(_as_symbol)]


class DofEntry(Strict):
    """A degree of freedom q_i (second order): its rate is ``d<name>`` unless ``rate`` says."""

    name: Symbol = Field(description="Name (state order = list order).")
    stiffness: Symbol = Field(description="Parameter of its linear structural stiffness K_i "
                              "(the term K_i q_i a stiffness law replaces).")
    unit: Text = Field("1", description="Unit of the dof (rad for angles).")
    description: Text = Field("", description="What it is.")
    amplitude: Positive = Field(1.0, description="Typical amplitude in its unit: scales "
                                "AUTO's state and every amplitude threshold.")
    rate: Symbol | None = Field(None, description="Name of its rate (default d<name>).")


class StateEntry(Strict):
    """A first-order state x_j: its rate x_j' is given under ``rates``."""

    name: Symbol = Field(description="Name (state order = list order, after the dofs' rates).")
    unit: Text = Field("1", description="Unit of the state.")
    description: Text = Field("", description="What it is.")
    amplitude: Positive = Field(1.0, description="Typical size in its unit: scales AUTO's "
                                "state.")


class ParameterEntry(Strict):
    """A parameter: travels to AUTO through PAR."""

    name: Symbol
    value: Number = Field(description="Datum value (SI units).")
    unit: Text = "1"
    description: Text = ""
    bounds: Annotated[Any, BeforeValidator(_as_bounds)] = Field(
        None, description="`positive`, `non-negative` or [lower, upper]; a study value "
        "outside is refused.")
    integer: Boolean = False
    aliases: tuple[Symbol, ...] = ()


class ConstraintEntry(Strict):
    """A condition on several parameters, e.g. ``I_y - I_d > 0``."""

    expression: Annotated[Any, BeforeValidator(_as_comparison)]
    reason: Text = ""


class PathEntry(Strict):
    """A path normal to the spin axis: components y and z as linear combinations of the
    states with constant factors (e.g. ``-psi``)."""

    y: Expr
    z: Expr


class ModeGroupEntry(Strict):
    name: Symbol
    dofs: tuple[Symbol, ...]
    path: PathEntry


class ModelFile(Strict):
    """A model file (see the module doc)."""

    name: Annotated[str, BeforeValidator(_as_model_name)]
    description: Text = ""
    dofs: tuple[DofEntry, ...] = Field((), max_length=MAX_DOFS)
    states: tuple[StateEntry, ...] = Field((), max_length=MAX_DOFS)
    parameters: tuple[ParameterEntry, ...] = Field(min_length=1)
    definitions: dict[str, Expr] = Field(default_factory=dict)
    mass: tuple[tuple[Expr, ...], ...] | tuple[Expr, ...] | None = None
    forces: dict[str, Expr] = Field(default_factory=dict)
    rates: dict[str, Expr] = Field(default_factory=dict)
    time_scale: Positive | None = None
    hub: PathEntry | None = None
    mode_groups: tuple[ModeGroupEntry, ...] = ()
    constraints: tuple[ConstraintEntry, ...] = ()
    symmetric: Boolean | None = None
    linear: Boolean | None = None
    provisional: Boolean = False
    notes: Text = ""


@dataclass(frozen=True)
class FileEquations:
    """The (M, G, F) of a model file as sympy, from its checked expressions (see
    :data:`~.declaration.Equations`)."""

    definitions: tuple[tuple[str, Expression], ...]
    mass: tuple[tuple[Expression, ...], ...]
    forces: tuple[Expression, ...]
    rate_names: tuple[tuple[str, str], ...]  # (dof, the name of its rate)
    rates: tuple[Expression, ...] = ()  # of the first-order states, in their order

    def __call__(self, q: dict, v: dict, p: dict, x: dict):
        import sympy as sp

        from .expressions import to_sympy

        symbols = {**p, **q, **{rate: v[dof] for dof, rate in self.rate_names}, **x}
        for name, expression in self.definitions:
            symbols[name] = to_sympy(expression, symbols)
        n = len(self.forces)
        mass = sp.Matrix(n, n, [to_sympy(e, symbols) for row in self.mass for e in row])
        forces = sp.Matrix(n, 1, [to_sympy(e, symbols) for e in self.forces])
        rates = sp.Matrix(len(self.rates), 1, [to_sympy(e, symbols) for e in self.rates])
        return mass, forces, rates


def read_model_file(path: Path, label: str | None = None) -> Family:
    """The family a model file declares; StudyError listing every problem otherwise."""
    label = str(path) if label is None else label
    return model_from_text(read_text(path, label, "model").replace("\r\n", "\n"), label)


def read_builtin(path: Path) -> Family:
    """The family of one of whirl's own model files (``models/builtin``): read with libyaml
    and without the line tracking that only messages about a user's file need (a run reads
    one at start-up); the same checks, any problem a bug of whirl's."""
    import yaml

    text = path.read_text(encoding="utf-8")
    declared = ModelFile.model_validate(yaml.load(text, Loader=yaml.CSafeLoader))
    problems = _Checker(declared, builtin=True).problems()
    if problems:
        raise ValueError(f"{path}: {problems}")
    return _family(declared, text)


def model_from_text(text: str, label: str, builtin: bool = False) -> Family:
    """The family the model file ``text`` declares (messages name it ``label``)."""
    tree = Tree(compose(text, label, "model"))
    try:
        declared = ModelFile.model_validate(tree.data)
    except ValidationError as error:
        problems = [translate(e, tree, ModelFile) for e in error.errors(include_url=False)]
        raise StudyError(report(tree.problems + problems, tree, label)) from None
    problems = tree.problems + _Checker(declared, builtin).problems()
    if problems:
        raise StudyError(report(problems, tree, label))
    return _family(declared, text)


# ------------------------------------------------------------------------------ meaning
class _Checker:
    """The checks that span keys: names, references, shapes and the datum."""

    def __init__(self, model: ModelFile, builtin: bool = False) -> None:
        self.model = model
        self.builtin = builtin
        self.found: list[tuple[tuple, str]] = []

    def problems(self) -> list[tuple[tuple, str]]:
        self._names()
        if not self.found:
            self._references()
        if not self.found:
            self._datum()
        return self.found

    def _add(self, loc: tuple, reason: str) -> None:
        self.found.append((loc, reason))

    # -------------------------------------------------------------- names
    def _declared(self) -> list[tuple[tuple, str]]:
        model = self.model
        names = []
        for i, d in enumerate(model.dofs):
            names.append((("dofs", i, "name"), d.name))
            names.append((("dofs", i, "rate" if d.rate else "name"), _rate(d)))
        names += [(("states", i, "name"), x.name) for i, x in enumerate(model.states)]
        for i, p in enumerate(model.parameters):
            names.append((("parameters", i, "name"), p.name))
            names += [(("parameters", i, "aliases", k), a) for k, a in enumerate(p.aliases)]
        names += [(("definitions", n), n) for n in model.definitions]
        return names

    def _names(self) -> None:
        model = self.model
        if not model.dofs and not model.states:
            self._add(("dofs",), "a model needs at least one dof (or a first-order state under "
                                 "`states`)")
        seen: dict[str, str] = {}
        for loc, name in self._declared():
            if name.lower() in seen:
                self._add(loc, f"{name!r} is declared twice (names must differ ignoring case; "
                               f"the first is {seen[name.lower()]!r})")
            seen.setdefault(name.lower(), name)
            if loc[0] == "definitions":
                try:
                    _as_symbol(name)
                except Exception:  # noqa: BLE001 - the schema's reason, reworded here
                    self._add(loc, f"{name!r} is not a usable name (letters, digits, '_', at "
                                   f"most {AUTO_NAME_LENGTH} characters, not reserved)")
        for i, d in enumerate(model.dofs):
            if len(f"max_{_rate(d)}") > AUTO_NAME_LENGTH:
                self._add(("dofs", i, "name"), f"the rate name {_rate(d)!r} is too long for "
                          f"AUTO (at most {AUTO_NAME_LENGTH - 4} characters)")
        for i, x in enumerate(model.states):
            if len(f"max_{x.name}") > AUTO_NAME_LENGTH:
                self._add(("states", i, "name"), f"{x.name!r} is too long for AUTO (a state "
                          f"name has at most {AUTO_NAME_LENGTH - 4} characters)")
        reserved = _law_names(model)
        for i, p in enumerate(model.parameters):
            for k, name in enumerate((p.name, *p.aliases)):
                loc = ("parameters", i, "name") if k == 0 else ("parameters", i, "aliases", k - 1)
                if name in THESIS_NAMES:
                    self._add(loc, f"{name!r} is reserved for a study's law coefficients")
                elif name in reserved:
                    self._add(loc, f"{name!r} is the name of a stiffness law's coefficient "
                                   f"({reserved[name]})")
        parameters = {p.name for p in model.parameters}
        for i, d in enumerate(model.dofs):  # dofs may share one (an isotropic spring)
            if d.stiffness not in parameters:
                self._add(("dofs", i, "stiffness"), f"no parameter {d.stiffness!r} is declared")
        from . import FAMILIES

        if model.name in FAMILIES and not self.builtin:
            self._add(("name",), f"{model.name!r} is the name of a built-in model")

    # -------------------------------------------------------------- references
    def _references(self) -> None:
        model = self.model
        parameters = {p.name for p in model.parameters}
        states = set(_state_names(model))
        known = parameters | states
        state_free = set(parameters)
        for name, expression in model.definitions.items():
            loc = ("definitions", name)
            if name in expression.names:
                self._add(loc, f"{name!r} refers to itself")
            later = sorted(expression.names & (set(model.definitions) - known - {name}))
            unknown = sorted(expression.names - known - set(model.definitions))
            if later:
                self._add(loc, f"uses {', '.join(later)}, defined below it (a definition may "
                               "use only those above it)")
            if unknown:
                self._add(loc, _unknown(unknown))
            if expression.names <= state_free:
                state_free.add(name)
            known.add(name)
        self._mass(known, state_free)
        dofs = [d.name for d in model.dofs]
        self._one_each("forces", model.forces, dofs, ("dof", "dofs", "force for dof"), known)
        self._one_each("rates", model.rates, [x.name for x in model.states],
                       ("first-order state", "states", "rate for state"), known)
        if model.hub is not None:
            self._path(("hub",), model.hub, states)
        for i, group in enumerate(model.mode_groups):
            unknown = [d for d in group.dofs if d not in dofs]
            if unknown:
                self._add(("mode_groups", i, "dofs"), f"no dof {', '.join(unknown)}")
            self._path(("mode_groups", i, "path"), group.path, states)
        grouped = sorted(d for g in model.mode_groups for d in g.dofs)
        if model.mode_groups and grouped != sorted(dofs):
            self._add(("mode_groups",), "the mode groups must hold every dof exactly once")
        for i, constraint in enumerate(model.constraints):
            unknown = sorted(constraint.expression.names - parameters)
            if unknown:
                self._add(("constraints", i, "expression"),
                          f"{_unknown(unknown)} (a constraint compares parameters)")

    def _one_each(self, key: str, expressions: dict, names: list[str],
                  words: tuple[str, str, str], known: set[str]) -> None:
        """One expression under ``key`` per name of ``names`` (forces per dof, rates per
        first-order state), each of known names only. ``words``: what a name is, what they
        are, and what one lacks (e.g. "dof", "dofs", "force for dof")."""
        what, plural, lacking = words
        for name, expression in expressions.items():
            if name not in names:
                self._add((key, name), f"no {what} {name!r} ({plural}: "
                                       f"{', '.join(names) or 'none'})")
            unknown = sorted(expression.names - known)
            if unknown:
                self._add((key, name), _unknown(unknown))
        missing = [n for n in names if n not in expressions]
        if missing:
            self._add((key,), f"no {lacking} {', '.join(missing)} (write 0 if none)")

    def _mass(self, known: set[str], state_free: set[str]) -> None:
        n = len(self.model.dofs)
        if self.model.mass is None or not n:
            if n:
                self._add(("mass",), f"missing: the {n} x {n} mass matrix of the dofs")
            elif self.model.mass:
                self._add(("mass",), "a model without dofs has no mass matrix")
            return
        rows = _mass_rows(self.model)
        if rows is None:
            count = len(self.model.mass)
            self._add(("mass",), f"expected {n} x {n} entries (a list of {n} rows of {n}) or "
                                 f"the {n} diagonal entries, got {count} items of other lengths")
            return
        for i, row in enumerate(rows):
            for j, expression in enumerate(row):
                loc = _mass_loc(self.model, i, j)
                unknown = sorted(expression.names - known)
                if unknown:
                    self._add(loc, _unknown(unknown))
                elif not expression.names <= state_free:
                    through = sorted(expression.names - state_free)
                    self._add(loc, f"the mass matrix may not depend on the states (through "
                                   f"{', '.join(through)})")

    def _path(self, loc: tuple, path: PathEntry, states: set[str]) -> None:
        for key in ("y", "z"):
            expression = getattr(path, key)
            others = sorted(expression.names - states)
            if others:
                self._add(loc + (key,), f"a path combines states with constant factors; "
                                        f"{', '.join(others)} is not a state")
            elif not _is_linear_combination(expression, sorted(states)):
                self._add(loc + (key,), "must be linear in the states (e.g. -psi or 0.5*theta)")

    # -------------------------------------------------------------- datum
    def _datum(self) -> None:
        model = self.model
        values = {}
        for i, p in enumerate(model.parameters):
            bounds = _parameter_bounds(p)
            if not bounds.contains(p.value):
                self._add(("parameters", i, "value"), f"{p.value:g} is outside its bounds "
                                                      f"{bounds.text(p.unit)}")
            values[p.name] = p.value
        zero = dict.fromkeys(_state_names(model), 0.0)
        try:
            point = _definitions_at(model, {**values, **zero})
        except _AtDatum as error:
            self._add(error.loc, error.reason)
            return
        rows = _mass_rows(model)
        mass = []
        for i, row in enumerate(rows):
            mass.append([])
            for j, expression in enumerate(row):
                loc = _mass_loc(model, i, j)
                try:
                    mass[i].append(evaluate(expression, point))
                except ArithmeticError as error:
                    self._add(loc, f"cannot be computed at the datum ({error})")
                    return
        for i in range(len(mass)):
            for j in range(i):
                if not math.isclose(mass[i][j], mass[j][i], rel_tol=1e-12, abs_tol=1e-300):
                    self._add(("mass", i, j), f"the mass matrix must be symmetric: entry "
                              f"({i}, {j}) is {mass[i][j]:g} at the datum, ({j}, {i}) "
                              f"{mass[j][i]:g}")
        if not self.found and mass and not _positive_definite(mass):
            self._add(("mass",), "the mass matrix is singular or not positive definite at "
                                 "the datum")
        for key, expressions in (("forces", model.forces), ("rates", model.rates)):
            for name, expression in expressions.items():
                try:
                    value = evaluate(expression, point)
                except ArithmeticError as error:
                    self._add((key, name), f"cannot be computed at the datum with every "
                                           f"state 0 ({error})")
                    continue
                if not math.isfinite(value):
                    self._add((key, name), "is not finite at the datum with every state 0")
        for i, constraint in enumerate(model.constraints):
            if not constraint.expression.holds(values):
                self._add(("constraints", i, "expression"), "does not hold at the datum")


class _AtDatum(Exception):
    def __init__(self, loc: tuple, reason: str) -> None:
        super().__init__(reason)
        self.loc, self.reason = loc, reason


def _definitions_at(model: ModelFile, values: dict[str, float]) -> dict[str, float]:
    """``values`` with every definition computed (ArithmeticError as :class:`_AtDatum`)."""
    point = dict(values)
    for name, expression in model.definitions.items():
        try:
            point[name] = evaluate(expression, point)
        except ArithmeticError as error:
            raise _AtDatum(("definitions", name),
                           f"cannot be computed at the datum with every state 0 ({error})"
                           ) from None
    return point


def _unknown(names: list[str]) -> str:
    return (f"unknown name {', '.join(map(repr, names))} (not a dof, rate, parameter or "
            "definition)")


def _rate(dof: DofEntry) -> str:
    return dof.rate or f"d{dof.name}"


def _state_names(model: ModelFile) -> list[str]:
    """Every state in state order: the dofs, their rates, the first-order states."""
    return ([d.name for d in model.dofs] + [_rate(d) for d in model.dofs]
            + [x.name for x in model.states])


def _state_scales(model: ModelFile) -> list[float]:
    """A typical size of each state (in state order): a rate's is its dof's amplitude."""
    dofs = [d.amplitude for d in model.dofs]
    return dofs + dofs + [x.amplitude for x in model.states]


def _law_names(model: ModelFile) -> dict[str, str]:
    """Parameter names the stiffness laws give their coefficients on this model's dofs."""
    names = {}
    for dof in model.dofs:
        for law in LAWS.values():
            keys = [c.key for c in law.coefficients]
            for key in keys:
                names[law.parameter_name(key, dof.name)] = f"{law.name} law on {dof.name}"
            if law.stiffness_key is not None:
                names[law.parameter_name(law.stiffness_key, dof.name)] = \
                    f"{law.name} law on {dof.name}"
        names[f"piece_{dof.name}"] = f"exact laws on {dof.name}"
    return names


def _mass_rows(model: ModelFile) -> list[list[Expression]] | None:
    """The mass matrix as rows (a diagonal given as a list filled with zeros; none without
    dofs); None if its shape is wrong."""
    n = len(model.dofs)
    if not n:
        return []
    if model.mass is None or len(model.mass) != n:
        return None
    if all(isinstance(row, tuple) for row in model.mass):
        return [list(row) for row in model.mass] if all(len(r) == n for r in model.mass) \
            else None
    if any(isinstance(row, tuple) for row in model.mass):
        return None
    zero = parse(0)
    return [[e if i == j else zero for j in range(n)] for i, e in enumerate(model.mass)]


def _mass_loc(model: ModelFile, i: int, j: int) -> tuple:
    """Where entry (i, j) of the mass matrix stands in the file (a diagonal list: item i)."""
    return ("mass", i, j) if isinstance(model.mass[0], tuple) else ("mass", i)


def _is_linear_combination(expression: Expression, states: list[str]) -> bool:
    base = {s: 0.0 for s in states}
    try:
        if evaluate(expression, base) != 0.0:
            return False
        slopes = {s: evaluate(expression, {**base, s: 1.0}) for s in states}
        probe = {s: 0.3 + 0.1 * k for k, s in enumerate(states)}
        value = evaluate(expression, probe)
    except ArithmeticError:
        return False
    return math.isclose(value, sum(slopes[s] * probe[s] for s in states), rel_tol=1e-9,
                        abs_tol=1e-12)


def _positive_definite(matrix: list[list[float]]) -> bool:
    """Cholesky in plain Python: True if the symmetric ``matrix`` is well positive definite."""
    n = len(matrix)
    lower = [[0.0] * n for _ in range(n)]
    scale = max(abs(matrix[i][i]) for i in range(n)) or 1.0
    for i in range(n):
        for j in range(i + 1):
            total = matrix[i][j] - sum(lower[i][k] * lower[j][k] for k in range(j))
            if i == j:
                if not total > 1e-12 * scale:
                    return False
                lower[i][i] = math.sqrt(total)
            else:
                lower[i][j] = total / lower[j][j]
    return True


def _parameter_bounds(entry: ParameterEntry) -> Bounds:
    bounds = entry.bounds or Bounds()
    return Bounds(bounds.lower, bounds.upper, bounds.lower_open, bounds.upper_open,
                  entry.integer)


# ------------------------------------------------------------------------------ the family
def _family(model: ModelFile, text: str) -> Family:
    dofs = tuple(Dof(d.name, _rate(d), d.unit, d.description, d.amplitude, d.stiffness)
                 for d in model.dofs)
    parameters = tuple(Parameter(p.name, p.value, p.unit, p.description, p.aliases,
                                 _parameter_bounds(p)) for p in model.parameters)
    rows = _mass_rows(model)
    assert rows is not None
    equations = FileEquations(tuple(model.definitions.items()), tuple(map(tuple, rows)),
                              tuple(model.forces[d.name] for d in model.dofs),
                              tuple((d.name, _rate(d)) for d in model.dofs),
                              tuple(model.rates[x.name] for x in model.states))
    states = _state_names(model)
    constraints = tuple(Constraint(tuple(sorted(c.expression.names)), c.expression.holds,
                                   c.reason or f"{c.expression.text} must hold")
                        for c in model.constraints)
    datum = {p.name: p.value for p in model.parameters}
    # probed only for what the file leaves out (the built-ins state both: start-up)
    probes = _probes(model, datum) if None in (model.symmetric, model.linear) else (None, None)
    return Family(
        name=model.name,
        description=model.description or f"model file {model.name}",
        dofs=dofs,
        parameters=parameters,
        equations=equations,
        time_scale=model.time_scale or _time_scale(model, datum),
        hub=_combination_pair(model.hub, states),
        mode_groups=tuple(ModeGroup(g.name, g.dofs, _combination_pair(g.path, states))
                          for g in model.mode_groups),
        constraints=constraints,
        symmetric=model.symmetric if model.symmetric is not None else probes[0],
        linear=model.linear if model.linear is not None else probes[1],
        provisional=model.provisional,
        notes=model.notes,
        first_order=tuple(FirstOrderState(x.name, x.unit, x.description, x.amplitude)
                          for x in model.states),
        key=content_key(model),
        source=text,
    )


def content_key(model: ModelFile) -> str:
    """sha256 of what the file declares, not how it is written: comments, spacing, key order
    and keys at their default (written out or left out) do not change it, nor does a key
    the format gains later."""
    def plain(value: Any) -> Any:
        if isinstance(value, Expression):
            return value.canonical
        if isinstance(value, Comparison):
            return [value.left.canonical, value.symbol, value.right.canonical]
        if isinstance(value, Bounds):
            return [value.lower, value.upper, value.lower_open, value.upper_open,
                    value.integer]
        if isinstance(value, dict):
            return {k: plain(v) for k, v in value.items()}
        if isinstance(value, list | tuple):
            return [plain(v) for v in value]
        if isinstance(value, BaseModel):
            return {k: plain(getattr(value, k)) for k, field in type(value).model_fields.items()
                    if field.is_required()
                    or getattr(value, k) != field.get_default(call_default_factory=True)}
        return value

    text = json.dumps(plain(model), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def _combination_pair(path: PathEntry | None, states: list[str]):
    if path is None:
        return ((), ())
    pair = []
    for expression in (path.y, path.z):
        base = {s: 0.0 for s in states}
        terms = []
        for k, s in enumerate(states):
            factor = evaluate(expression, {**base, s: 1.0})
            if factor:
                terms.append((k, factor))
        pair.append(tuple(terms))
    return tuple(pair)


def _forces_at(model: ModelFile, datum: dict, state: dict[str, float]) -> list[float]:
    """The forces G per dof, then the rates F per first-order state, at ``state``."""
    point = _definitions_at(model, {**datum, **state})
    return ([evaluate(model.forces[d.name], point) for d in model.dofs]
            + [evaluate(model.rates[x.name], point) for x in model.states])


def _probes(model: ModelFile, datum: dict) -> tuple[bool, bool]:
    """(odd, linear): whether the forces and rates are odd in the states and linear in them,
    probed at the datum at two states of a few typical sizes."""
    names, scale = _state_names(model), _state_scales(model)

    def state(factor: float, shift: int) -> dict[str, float]:
        return {n: factor * s * (1 + 0.13 * ((k + shift) % 5)) for k, (n, s) in
                enumerate(zip(names, scale, strict=True))}

    try:
        zero = _forces_at(model, datum, dict.fromkeys(names, 0.0))
        a, b = state(PROBES[0], 0), state(PROBES[1], 2)
        fa, fb = _forces_at(model, datum, a), _forces_at(model, datum, b)
        fneg = _forces_at(model, datum, {n: -x for n, x in a.items()})
        fsum = _forces_at(model, datum, {n: a[n] + b[n] for n in names})
    except (ArithmeticError, _AtDatum):
        return False, False
    size = max([abs(x) for x in fa + fb] + [1e-300])

    def close(x: list[float], y: list[float]) -> bool:
        return all(abs(p - q) <= 1e-9 * size for p, q in zip(x, y, strict=True))

    odd = close(fneg, [-x for x in fa]) and close(zero, [0.0] * len(zero))
    linear = close([s - z for s, z in zip(fsum, zero, strict=True)],
                   [x + y - 2 * z for x, y, z in zip(fa, fb, zero, strict=True)])
    return odd, linear


def _time_scale(model: ModelFile, datum: dict) -> float:
    """A reference frequency [rad/s]: the geometric mean of the moduli of the linear model's
    eigenvalues at the datum with every state 0 (finite differences of the forces and
    rates), to two significant figures; 1 where none is non-zero."""
    import numpy as np

    names, scale = _state_names(model), _state_scales(model)
    n, size = len(model.dofs), len(names)
    zero = dict.fromkeys(names, 0.0)
    try:
        point = _definitions_at(model, {**datum, **zero})
        rows = _mass_rows(model)
        assert rows is not None
        mass = np.array([[evaluate(e, point) for e in row] for row in rows]).reshape(n, n)
        slopes = np.zeros((size - n, size))
        for k, name in enumerate(names):
            step = 1e-6 * scale[k]
            up = _forces_at(model, datum, {**zero, name: step})
            down = _forces_at(model, datum, {**zero, name: -step})
            slopes[:, k] = (np.array(up) - np.array(down)) / (2 * step)
    except (ArithmeticError, _AtDatum):
        return 1.0
    slopes[:n, :n] -= np.diag([datum[d.stiffness] for d in model.dofs])
    system = np.zeros((size, size))
    system[:n, n:2 * n] = np.eye(n)
    if n:
        system[n:2 * n] = np.linalg.solve(mass, slopes[:n])
    system[2 * n:] = slopes[n:]
    moduli = np.abs(np.linalg.eigvals(system))
    moduli = moduli[np.isfinite(moduli) & (moduli > 1e-9)]
    if moduli.size == 0:
        return 1.0
    value = float(np.exp(np.mean(np.log(moduli))))
    return float(f"{value:.2g}")
