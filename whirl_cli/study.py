"""Study files: YAML in, a frozen and validated :class:`Study` out.

:func:`load_study` (a file) and :func:`validate_text` (a string) are the validating entry points.
They report every problem at once, as ``<file>:<line>: <key.path>: <reason>`` lines in a
:class:`~whirl_cli.errors.StudyError`, and never let a traceback escape for bad input.

How a file is read:

1. bytes: at most :data:`MAX_BYTES`, UTF-8;
2. YAML, composed with a SafeLoader subclass into nodes (for line numbers): anchors, aliases,
   tags beyond the core ones (str, int, float, bool, null, seq, map) and nesting deeper than
   :data:`MAX_DEPTH` are refused. Two YAML 1.1 surprises are switched off: only ``true`` and
   ``false`` are booleans (``yes``, ``on`` stay strings) and ``1e-6`` is a number; dates stay
   strings and ``<<`` is a plain key;
3. plain Python data from the nodes, scalars built by the safe constructors; duplicate keys are
   reported;
4. structure: the pydantic models below (``extra="forbid"``), their errors translated into
   the reasons that tests/unit/test_study.py spells out;
5. meaning, on the raw data so that it adds to the structural problems: parameter names known
   to the model variant, ``K2``/``K3`` only under ``nonlinearity``, ``dof`` a degree of freedom
   of the model, unique continuation names, ``start`` inside ``range``.

Validation also fills the model-dependent defaults: ``nonlinearity.dof`` (the family's default),
``continuations[].parameter`` and ``linear.sweeps[].parameter`` become canonical names
(``K_theta`` -> ``K1``), and ``continuations[].start`` gets the parameter's study value when the
file leaves it out. ``Study.model_validate`` applies these fills too, but only the two entry
points check parameter names and ranges against the model.
"""

from __future__ import annotations

import hashlib
import math
import operator
import os
import re
import types
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Annotated, Any, Literal, NoReturn, Union, get_args, get_origin

import yaml
from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PrivateAttr,
    ValidationError,
    model_validator,
)
from pydantic.fields import FieldInfo
from pydantic_core import PydanticCustomError
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from .errors import StudyError
from .models import FAMILIES, Model, get_model

__all__ = [
    "MAX_BYTES",
    "AutoSettings",
    "Linear",
    "LinearSpec",
    "LinearSweepSpec",
    "OneParameterContinuation",
    "Polynomial",
    "Study",
    "load_study",
    "schema_reference",
    "validate_text",
]

#: Largest study file accepted, in bytes (1 MiB).
MAX_BYTES = 1 << 20
#: Deepest nesting of YAML lists and mappings accepted (a study needs 5).
MAX_DEPTH = 32
NAME_MAX = 64
#: Largest integer AUTO-07p reads into its (32-bit) INTEGER constants (NMX, NTST, ITNW).
FORTRAN_INT_MAX = 2**31 - 1
#: Most values in ``orbits_at``: AUTO reads at most 2048 characters per constants line (UZR).
ORBITS_MAX = 64
_NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")
_NAME_REASON = (
    "expected letters, digits, '_', '.', '-' (starting with a letter or digit), got {got}"
)
#: Parameters of the stiffness law, set under ``nonlinearity`` rather than ``parameters``.
_LAW_PARAMETERS = ("K2", "K3")

Loc = tuple[str | int, ...]
Problem = tuple[Loc, str]

# --------------------------------------------------------------------------- YAML loading
_CORE = "tag:yaml.org,2002:"
_STR, _INT, _FLOAT, _BOOL, _NULL = (_CORE + t for t in ("str", "int", "float", "bool", "null"))
_SEQ, _MAP = _CORE + "seq", _CORE + "map"
_SCALAR_TAGS = frozenset({_STR, _INT, _FLOAT, _BOOL, _NULL})
_TAGS_BY_EVENT = {
    yaml.ScalarEvent: _SCALAR_TAGS,
    yaml.SequenceStartEvent: frozenset({_SEQ}),
    yaml.MappingStartEvent: frozenset({_MAP}),
}


def _parse(text: str) -> tuple[Node | None, list[tuple[int, str]]]:
    """The root node and the (line, reason) problems recorded while composing it."""
    loader = _Loader(text)
    try:
        return loader.get_single_node(), loader.problems
    finally:
        loader.dispose()


def _short_tag(tag: str) -> str:
    """``tag:yaml.org,2002:int`` -> ``!!int``."""
    return "!!" + tag.removeprefix(_CORE) if tag.startswith(_CORE) else tag


class _TooDeep(Exception):
    """Raised by _Loader at the first node nested deeper than MAX_DEPTH."""


class _Loader(yaml.SafeLoader):
    """SafeLoader resolving only str, int, float (``1e-6`` too), bool (true/false) and null.

    While composing it records anchors, aliases and non-core tags as (line, reason) in
    ``problems`` (an alias becomes a null node) and stops below MAX_DEPTH levels of nesting.
    """

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self.problems: list[tuple[int, str]] = []
        self._depth = 0

    def compose_node(self, parent: Node | None, index: Any) -> Node:
        event = self.peek_event()
        line = event.start_mark.line + 1
        if isinstance(event, yaml.AliasEvent) or event.anchor is not None:
            self.problems.append((line, "YAML anchors and aliases are not allowed in study files"))
            event.anchor = None
        tag = getattr(event, "tag", None)
        if tag is not None and tag not in _TAGS_BY_EVENT.get(type(event), ()):
            reason = f"YAML tag {_short_tag(tag)!r} is not allowed in study files"
            self.problems.append((line, reason))
        if isinstance(event, yaml.AliasEvent):
            self.get_event()
            return ScalarNode(_NULL, "", event.start_mark, event.end_mark)
        if self._depth >= MAX_DEPTH:
            raise _TooDeep(line)
        self._depth += 1
        try:
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


_Loader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag in (_INT, _NULL)]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_Loader.add_implicit_resolver(_BOOL, re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), "tTfF")
_Loader.add_implicit_resolver(
    _FLOAT,
    re.compile(
        r"""^(?:[-+]?(?:[0-9][0-9_]*\.[0-9_]*|\.[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)?
        |[-+]?[0-9][0-9_]*[eE][-+]?[0-9]+
        |[-+]?\.(?:inf|Inf|INF)
        |\.(?:nan|NaN|NAN))$""",
        re.X,
    ),
    "-+0123456789.",
)


# --------------------------------------------------------------------------- value checks
def _fail(reason: str) -> NoReturn:
    """Reject a value; ``{got}`` in ``reason`` becomes the value as written in the YAML."""
    raise PydanticCustomError("whirl", "{reason}", {"reason": reason})


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _finite(value: Any) -> float | None:
    """``value`` as a float if it is a finite number, else None."""
    return float(value) if _is_number(value) and math.isfinite(value) else None


def _as_string(value: Any) -> str:
    if not isinstance(value, str):
        _fail("expected a string, got {got}")
    return value


def _as_number(value: Any) -> float:
    if not _is_number(value):
        _fail("expected a number, got {got}")
    if not math.isfinite(value):
        _fail("expected a finite number, got {got}")
    return float(value)


def _as_integer(value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        _fail("expected an integer, got {got}")
    return value


def _as_boolean(value: Any) -> bool:
    if not isinstance(value, bool):
        _fail("expected true or false, got {got}")
    return value


def _as_name(value: Any) -> str:
    if not _NAME_RE.fullmatch(_as_string(value)):
        _fail(_NAME_REASON)
    if len(value) > NAME_MAX:
        _fail(f"must be at most {NAME_MAX} characters, got {len(value)}")
    return value


def _as_range(value: Any) -> tuple[float, float]:
    bounds = [_finite(v) for v in value] if isinstance(value, list | tuple) else []
    if len(bounds) != 2 or None in bounds or not bounds[0] < bounds[1]:
        _fail("expected [lower, upper] with lower < upper, got {value}")
    lower, upper = bounds
    if not (math.isfinite(upper - lower) and math.isfinite(lower - (upper - lower))
            and math.isfinite(upper + (upper - lower))):  # AUTO's bounds lie 5 % beyond
        _fail("the range is too wide: its width overflows double precision, got {value}")
    return lower, upper


def _at_most_orbits(values: tuple) -> tuple:
    if len(values) > ORBITS_MAX:
        _fail(f"at most {ORBITS_MAX} values, got {len(values)}")
    return values


def _as_model_family(value: str) -> str:
    if value not in FAMILIES:
        _fail(f"unknown model {{got}} (known: {', '.join(FAMILIES)})")
    return value


def _bound(symbol: str, limit: float) -> AfterValidator:
    """A check that the value is ``symbol`` (>=, >, <=) ``limit``."""
    compare: Callable[[Any, Any], bool] = {
        ">=": operator.ge,
        ">": operator.gt,
        "<=": operator.le,
    }[symbol]

    def check(value: Any) -> Any:
        if not compare(value, limit):
            _fail(f"must be {symbol} {limit}, got {{got}}")
        return value

    return AfterValidator(check)


Text = Annotated[str, BeforeValidator(_as_string)]
Name = Annotated[str, BeforeValidator(_as_name)]
Number = Annotated[float, BeforeValidator(_as_number)]
Integer = Annotated[int, BeforeValidator(_as_integer)]
Boolean = Annotated[bool, BeforeValidator(_as_boolean)]
Range = Annotated[tuple[float, float], BeforeValidator(_as_range)]
Positive = Annotated[Number, _bound(">", 0)]
ModelFamily = Annotated[Text, AfterValidator(_as_model_family)]


# --------------------------------------------------------------------------- the schema
class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


_TYPE_DOC = (
    "Stiffness law: `linear` (linear springs; the polynomial law with K2 = K3 = 0) or "
    "`polynomial` (restoring moment K1 x + K2 x^3 + K3 x^5 on `dof`, x in rad)."
)
_DOF_DOC = (
    "Degree of freedom the law acts on (classical: `theta` pitch, `psi` yaw); unset: the "
    "model's default (classical: `theta`)."
)


class Linear(_Strict):
    """Linear springs: the polynomial law with K2 = K3 = 0 (one AUTO executable for both)."""

    type: Literal["linear"] = Field(description=_TYPE_DOC)
    dof: Text | None = Field(None, description=_DOF_DOC)


class Polynomial(_Strict):
    """Restoring moment K1 x + K2 x^3 + K3 x^5 on one degree of freedom."""

    type: Literal["polynomial"] = Field(description=_TYPE_DOC)
    dof: Text | None = Field(None, description=_DOF_DOC)
    K2: Number = Field(0.0, description="Cubic stiffness coefficient, N m/rad^3 (polynomial only).")
    K3: Number = Field(
        0.0, description="Quintic stiffness coefficient, N m/rad^5 (polynomial only)."
    )


class OneParameterContinuation(_Strict):
    """Equilibria in one parameter, with the branches that hang off them.

    After validation ``parameter`` is the canonical name and ``start`` is filled.
    """

    name: Name = Field(
        description="Run name, unique within the study (same characters as the study name)."
    )
    type: Literal["one-parameter"] = Field(
        description="`one-parameter`: equilibria in one parameter (AUTO-07p continuation)."
    )
    parameter: Text = Field(
        description="Continuation parameter, by name or alias, in its SI unit (stored as the "
        "canonical name: `K_theta` -> `K1`)."
    )
    start: Number | None = Field(
        None,
        description="Starting value, in the parameter's unit; must lie within `range`. Unset: "
        "the study value (`parameters`, else the model's datum).",
    )
    range: Range = Field(
        description="[lower, upper] bounds of the parameter, in its unit; AUTO stops at either."
    )
    periodic: Boolean = Field(
        False, description="Continue periodic orbits from every Hopf point (main and secondary)."
    )
    branch_points: Boolean = Field(
        True, description="Switch at branch points (pitchforks) to follow secondary equilibria."
    )
    orbits_at: Annotated[tuple[Number, ...], AfterValidator(_at_most_orbits)] = Field(
        (),
        description="Parameter values (in its unit) at which every branch stores a labelled "
        "solution: orbit profiles for phase-plane plots (AUTO UZR).",
    )

    def start_value(self, study: Study) -> float:
        """``start``, or the study value of the parameter when unset (models built by hand)."""
        if self.start is not None:
            return self.start
        variant = study.variant()
        name = variant.canonical(self.parameter)
        return study.parameter_values().get(name, variant.defaults()[name])


LocusKind = Literal["hopf", "branch_point", "fold", "fold_of_cycles"]


class TwoParameterContinuation(_Strict):
    """Loci of Hopf points, branch points, folds and folds of cycles in two parameters, the
    stability boundary they draw and the unsafe (overhang) region.

    After validation ``parameters`` are canonical names and ``start`` and ``slices`` are filled;
    ``bounds(model)`` gives ``range`` by canonical names.
    """

    name: Name = Field(
        description="Run name, unique within the study (same characters as the study name)."
    )
    type: Literal["two-parameter"] = Field(
        description="`two-parameter`: loci of special points in two parameters."
    )
    parameters: tuple[Text, Text] = Field(
        description="[first, second]: the first is continued along each slice of the second; "
        "both are free on the loci (names or aliases, stored canonical)."
    )
    range: dict[str, Range] = Field(
        description="{first: [lower, upper], second: [lower, upper]}: the region, in the "
        "parameters' units; loci stop at its edges."
    )
    start: Number | None = Field(
        None,
        description="Starting value of the first parameter for the one-parameter runs; unset: "
        "its study value.",
    )
    slices: tuple[Number, ...] = Field(
        (),
        description="Values of the second parameter at which one-parameter runs find the "
        "special points the loci start from, and at which unsafe intervals are reported; "
        "unset: its study value.",
    )
    loci: tuple[LocusKind, ...] = Field(
        ("hopf", "branch_point", "fold", "fold_of_cycles"),
        description="Which loci to continue: `hopf`, `branch_point` (pitchfork), `fold` (of "
        "equilibria), `fold_of_cycles` (needs the periodic branches, computed for it).",
    )
    method: Literal["loci", "slices"] = Field(
        "loci",
        description="How the unsafe region is drawn: `loci` (between the Hopf and fold-of-cycles "
        "loci, and between the pitchfork and fold loci) or `slices` (the thesis' method: from "
        "one-parameter runs with periodic branches at every slice).",
    )
    resolution: Annotated[Integer, _bound(">=", 3), _bound("<=", 2001)] = Field(
        101, description="Rows across the second parameter's range for the unsafe polygons."
    )

    def bounds(self, model: Model) -> dict[str, tuple[float, float]]:
        """``range`` keyed by canonical parameter names."""
        return {model.canonical(key): tuple(value) for key, value in self.range.items()}


PlotKind = Literal["bifurcation", "linear", "projections", "period", "phase", "boundary"]
Continuation = Annotated[OneParameterContinuation | TwoParameterContinuation,
                        Field(discriminator="type")]


class LinearSweepSpec(_Strict):
    """Eigenvalues along one parameter, on an even grid."""

    parameter: Text = Field(
        description="Swept parameter, by name or alias (stored as the canonical name)."
    )
    range: Range = Field(description="[lower, upper] of the sweep, in the parameter's unit.")
    points: Annotated[Integer, _bound(">=", 2), _bound("<=", 100000)] = Field(
        201, description="Number of equally spaced values, 2 to 100000."
    )


class LinearGridSpec(_Strict):
    """Linear stability over a grid of two parameters."""

    x: LinearSweepSpec = Field(description="First grid axis: parameter, range, points.")
    y: LinearSweepSpec = Field(description="Second grid axis: parameter, range, points.")


class LinearSpec(_Strict):
    """Linear (eigenvalue) analysis, done with numpy, without AUTO."""

    sweeps: tuple[LinearSweepSpec, ...] = Field(
        (), description="Eigenvalue sweeps (damping ratio, frequency, whirl direction)."
    )
    grid: LinearGridSpec | None = Field(
        None,
        description="Max real part of the eigenvalues of y = 0 over a grid, with its zero "
        "contour split into flutter and divergence parts; unset: none.",
    )


class AutoSettings(_Strict):
    """AUTO-07p settings under readable names; unset ones use whirl's defaults."""

    max_steps: Annotated[Integer, _bound(">=", 1), _bound("<=", FORTRAN_INT_MAX)] | None = Field(
        None, description="Maximum continuation steps per run (AUTO NMX), >= 1."
    )
    step_initial: Positive | None = Field(
        None, description="Initial step (AUTO DS), fraction of the continuation range width, > 0."
    )
    step_min: Positive | None = Field(
        None, description="Smallest step (AUTO DSMIN), fraction of the range width, > 0."
    )
    step_max: Positive | None = Field(
        None, description="Largest step (AUTO DSMAX), fraction of the range width, > 0."
    )
    mesh_intervals: Annotated[
        Integer, _bound(">=", 2), _bound("<=", FORTRAN_INT_MAX)] | None = Field(
        None, description="Mesh intervals for periodic orbits (AUTO NTST), >= 2."
    )
    collocation_points: Annotated[Integer, _bound(">=", 2), _bound("<=", 7)] | None = Field(
        None, description="Collocation points per mesh interval (AUTO NCOL), 2 to 7."
    )
    newton_max_iterations: Annotated[
        Integer, _bound(">=", 1), _bound("<=", FORTRAN_INT_MAX)] | None = Field(
        None, description="Maximum Newton iterations per step (AUTO ITNW), >= 1."
    )
    tolerance: Positive | None = Field(
        None, description="Newton convergence tolerance, dimensionless (AUTO EPSL = EPSU), > 0."
    )
    timeout: Positive | None = Field(None, description="Wall-clock limit per AUTO run, s, > 0.")
    max_amplitude: Positive | None = Field(
        None, description="Amplitude at which branches are stopped, rad, > 0."
    )


class Study(_Strict):
    """One study file, validated. ``source``, ``sha256`` and ``path`` are not YAML keys."""

    name: Name = Field(
        description="Study name: letters, digits, `_`, `.`, `-`, starting with a letter or "
        f"digit; at most {NAME_MAX} characters."
    )
    description: Text = Field("", description="Free text, kept with the results.")
    model: ModelFamily = Field(description="Model family (`whirl models` lists them).")
    parameters: dict[str, Number] = Field(
        default_factory=dict,
        description="Overrides of the model's datum parameter values, by name or alias, in SI "
        "units (angles in rad; `whirl models` lists units). K2 and K3 go under `nonlinearity`.",
    )
    nonlinearity: Linear | Polynomial = Field(
        default=Linear(type="linear"),
        discriminator="type",
        description="Structural stiffness law on one degree of freedom.",
    )
    continuations: tuple[Continuation, ...] = Field(
        (), description="AUTO-07p continuation runs, in order."
    )
    linear: LinearSpec | None = Field(
        None, description="Linear (eigenvalue) analysis without AUTO; unset: none."
    )
    plots: tuple[PlotKind, ...] = Field(
        ("bifurcation",), description="Figures drawn after the runs."
    )
    cross_check: Boolean = Field(
        False,
        description="Check stable periodic orbits and equilibria by time simulation (scipy) and "
        "store the outcome with the results.",
    )
    auto: AutoSettings = Field(
        default_factory=AutoSettings, description="AUTO-07p numerical settings."
    )

    _source: str = PrivateAttr("")
    _sha256: str = PrivateAttr("")
    _path: str = PrivateAttr("")

    @model_validator(mode="before")
    @classmethod
    def _fill_model_defaults(cls, data: Any) -> Any:
        return _resolved(data) if isinstance(data, dict) else data

    @property
    def source(self) -> str:
        """The YAML text the study was read from."""
        return self._source

    @property
    def sha256(self) -> str:
        """sha256 (hex) of the UTF-8 YAML text."""
        return self._sha256

    @property
    def path(self) -> str:
        """The path the study was loaded from, as given (or the name given to validate_text)."""
        return self._path

    def variant(self) -> Model:
        """The model variant: every study uses the polynomial law (linear is K2 = K3 = 0)."""
        return get_model(self.model, "polynomial", self.nonlinearity.dof)

    def parameter_values(self) -> dict[str, float]:
        """Canonical name -> value for every override, plus K2 and K3 of the nonlinearity."""
        variant = self.variant()
        values = {variant.canonical(k): v for k, v in self.parameters.items()}
        for name in _LAW_PARAMETERS:
            values[name] = getattr(self.nonlinearity, name, 0.0)
        return values


# --------------------------------------------------------------------------- model defaults
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
    elif isinstance(block, Linear | Polynomial) and block.dof is None:
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


# --------------------------------------------------------------------------- entry points
def load_study(path: str | os.PathLike[str], label: str | None = None) -> Study:
    """Read, check and return the study at ``path``; StudyError lists every problem, each
    line starting with ``label`` (default: the file's name)."""
    path = Path(path)
    label = path.name if label is None else label
    return _validate(_read_text(path, label), label, str(path))


def validate_text(text: str, filename: str = "<study>") -> Study:
    """Check the study YAML ``text``; messages name it ``filename``."""
    return _validate(text, filename, filename)


def _read_text(path: Path, label: str) -> str:
    """The file's text: at most MAX_BYTES of UTF-8 (errors name the file ``label``)."""
    try:
        with path.open("rb") as stream:
            raw = stream.read(MAX_BYTES + 1)
            size = max(len(raw), os.fstat(stream.fileno()).st_size)
    except OSError as error:
        reason = f"cannot read the study file ({error.strerror or error})"
        raise StudyError(f"{label}: {reason}") from None
    if len(raw) > MAX_BYTES:
        raise StudyError(_too_large(label, size))
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as error:
        reason = f"not UTF-8 text (byte 0x{raw[error.start]:02x} at offset {error.start})"
        raise StudyError(f"{label}: {reason}") from None


def _too_large(name: str, size: int) -> str:
    return f"{name}: the study file is too large ({size} bytes; the limit is {MAX_BYTES})"


def _validate(text: str, name: str, path: str) -> Study:
    try:
        encoded = text.encode("utf-8")
    except UnicodeEncodeError as error:
        code, offset = ord(text[error.start]), error.start
        reason = f"not UTF-8 text (character U+{code:04X} at offset {offset})"
        raise StudyError(f"{name}: {reason}") from None
    if len(encoded) > MAX_BYTES:
        raise StudyError(_too_large(name, len(encoded)))
    tree = _Tree(_compose(text, name))
    study, problems = _check(tree)
    if problems:
        raise StudyError(_report(problems, tree, name))
    study._source, study._sha256, study._path = text, hashlib.sha256(encoded).hexdigest(), path
    return study


def _check(tree: _Tree) -> tuple[Study | None, list[Problem]]:
    """The study (None if its structure is invalid) and every problem found."""
    problems = []
    try:
        study = Study.model_validate(tree.data)
    except ValidationError as error:
        study = None
        problems = [_translate(e, tree) for e in error.errors(include_url=False)]
    problems += _meaning_problems(tree.data)
    return study, tree.problems + [p for p in problems if p[0] not in tree.unreadable]


def _report(problems: list[Problem], tree: _Tree, name: str) -> str:
    lines = sorted((tree.line(loc), _dotted(loc), reason) for loc, reason in problems)
    return "\n".join(f"{name}:{line}: {path}: {reason}" for line, path, reason in lines)


def _dotted(loc: Loc) -> str:
    """``('continuations', 0, 'range')`` -> ``continuations[0].range``."""
    text = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in loc)
    return text.removeprefix(".")


# --------------------------------------------------------------------------- YAML to data
def _compose(text: str, name: str) -> MappingNode:
    """The root node of ``text``; StudyError for problems that concern the whole file."""
    try:
        root, whole_file = _parse(text)
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        where = f"{name}:{mark.line + 1}" if mark else name
        raise StudyError(f"{where}: YAML syntax error: {error.problem or error.context}") from None
    except yaml.reader.ReaderError as error:
        line = text.count("\n", 0, error.position) + 1
        reason = str(error).splitlines()[0]
        raise StudyError(f"{name}:{line}: YAML syntax error: {reason}") from None
    except yaml.YAMLError as error:
        raise StudyError(f"{name}: YAML syntax error: {error}") from None
    except _TooDeep as error:
        reason = f"YAML nesting deeper than {MAX_DEPTH} levels is not allowed in study files"
        raise StudyError(f"{name}:{error.args[0]}: {reason}") from None
    if whole_file:
        raise StudyError("\n".join(f"{name}:{line}: {reason}" for line, reason in whole_file))
    if root is None or (root.tag == _NULL and root.value == ""):
        raise StudyError(f"{name}: the study file is empty")
    if not isinstance(root, MappingNode):
        line = root.start_mark.line + 1
        got = _shown(root)
        raise StudyError(f"{name}:{line}: a study must be a YAML mapping of keys, got {got}")
    return root


class _Tree:
    """Python data built from the composed nodes, with the node and line of every key path."""

    def __init__(self, root: MappingNode) -> None:
        self.nodes: dict[Loc, Node] = {}
        self.lines: dict[Loc, int] = {(): root.start_mark.line + 1}
        self.problems: list[Problem] = []
        self.unreadable: set[Loc] = set()
        self._constructor = _Loader("")
        self.data = self._build(root, ())

    def line(self, loc: Loc) -> int:
        """Line of ``loc``, or of its nearest parent present in the file (missing keys)."""
        while loc not in self.lines:
            loc = loc[:-1]
        return self.lines[loc]

    def _build(self, node: Node, loc: Loc) -> Any:
        self.nodes[loc] = node
        if isinstance(node, MappingNode):
            return self._build_mapping(node, loc)
        if isinstance(node, SequenceNode):
            return [self._build_item(item, loc + (i,)) for i, item in enumerate(node.value)]
        try:
            return self._constructor.construct_object(node)
        except (ValueError, KeyError, yaml.YAMLError):
            self.problems.append((loc, f"cannot read {node.value!r} as {_short_tag(node.tag)}"))
            self.unreadable.add(loc)
            return None

    def _build_item(self, node: Node, loc: Loc) -> Any:
        self.lines[loc] = node.start_mark.line + 1
        return self._build(node, loc)

    def _build_mapping(self, node: MappingNode, loc: Loc) -> dict:
        data: dict[str, Any] = {}
        for key_node, value_node in node.value:
            line = key_node.start_mark.line + 1
            if not isinstance(key_node, ScalarNode):
                self.lines.setdefault(loc + ("?",), line)
                self.problems.append((loc + ("?",), f"keys must be text, got {_shown(key_node)}"))
                continue
            key = key_node.value
            if key in data:
                self.problems.append((loc + (key,), f"duplicate key {key!r}"))
            self.lines[loc + (key,)] = line
            data[key] = self._build(value_node, loc + (key,))
        return data

    def shown(self, loc: Loc) -> str:
        node = self.nodes.get(loc)
        return _shown(node) if node is not None else "nothing"

    def flow(self, loc: Loc) -> str:
        node = self.nodes.get(loc)
        return _flow(node) if node is not None else "nothing"


def _shown(node: Node) -> str:
    """A value as written: numbers verbatim, strings quoted, ``a list``/``a mapping``."""
    if isinstance(node, MappingNode):
        return "a mapping"
    if isinstance(node, SequenceNode):
        return "a list"
    if node.tag == _BOOL:
        return node.value.lower()
    if node.tag == _NULL:
        return "null"
    if node.tag in (_INT, _FLOAT):
        return node.value
    return repr(node.value)


def _flow(node: Node, depth: int = 0) -> str:
    """A value as written, lists spelled out: ``[0.5, -0.3]``."""
    if not isinstance(node, SequenceNode):
        return _shown(node)
    if depth > 2:
        return "[...]"
    items = [_flow(item, depth + 1) for item in node.value[:6]]
    return "[" + ", ".join(items[:5] + ["..."] * (len(items) > 5)) + "]"


# --------------------------------------------------------------------------- pydantic errors
_MAPPING_ERRORS = {"dict_type", "model_type", "model_attributes_type"}
_LIST_ERRORS = {"tuple_type", "list_type"}


def _translate(error: Any, tree: _Tree) -> Problem:
    """One pydantic error as (key path, reason)."""
    loc, owner, annotation = _walk(error["loc"])
    kind = error["type"]
    if kind == "whirl":
        template = error["ctx"]["reason"]
        return loc, template.format(got=tree.shown(loc), value=tree.flow(loc))
    if kind == "missing":
        return loc, "required key is missing"
    if kind == "extra_forbidden":
        return loc, f"unknown key (allowed: {', '.join(owner.model_fields)})"
    if kind in ("union_tag_invalid", "union_tag_not_found"):
        loc += (error["ctx"]["discriminator"].strip("'"),)
        if loc not in tree.nodes:
            return loc, "required key is missing"
        return loc, _choice_reason([_tag(m) for m in _union_members(annotation)], tree.shown(loc))
    if kind == "literal_error":
        return loc, _choice_reason(get_args(annotation), tree.shown(loc))
    if kind in _MAPPING_ERRORS:
        return loc, f"expected a mapping, got {tree.shown(loc)}"
    if kind in _LIST_ERRORS:
        return loc, f"expected a list, got {tree.shown(loc)}"
    return loc, error["msg"]


def _choice_reason(options: Any, got: str) -> str:
    return f"expected one of {', '.join(map(str, options))}, got {got}"


def _walk(loc: tuple) -> tuple[Loc, type[BaseModel], Any]:
    """A pydantic loc as (YAML key path, model owning its last key, annotation at its end).

    Union tags in the loc (``nonlinearity.polynomial.K2``) are not YAML keys and are dropped.
    """
    path: list[str | int] = []
    owner: type[BaseModel] = Study
    annotation: Any = Study
    for part in loc:
        annotation = _strip(annotation)
        members = _union_members(annotation)
        if members:
            annotation = next((m for m in members if _tag(m) == part), None)
            continue
        path.append(part)
        if isinstance(annotation, type) and issubclass(annotation, BaseModel):
            owner = annotation
            field = annotation.model_fields.get(str(part))
            annotation = field.annotation if field else None
        else:
            args = get_args(annotation)
            annotation = args[0] if args[-1:] == (Ellipsis,) else (args[-1] if args else None)
    return tuple(path), owner, _strip(annotation)


def _strip(annotation: Any) -> Any:
    """``annotation`` without Annotated metadata and without ``| None``."""
    while True:
        if get_origin(annotation) is Annotated:
            annotation = get_args(annotation)[0]
        elif _is_union(annotation) and type(None) in get_args(annotation):
            rest = [a for a in get_args(annotation) if a is not type(None)]
            annotation = rest[0] if len(rest) == 1 else Union[tuple(rest)]  # noqa: UP007
        else:
            return annotation


def _is_union(annotation: Any) -> bool:
    return get_origin(annotation) in (Union, types.UnionType)


def _union_members(annotation: Any) -> list[type[BaseModel]]:
    """The models of a discriminated union, else []."""
    return list(get_args(annotation)) if _is_union(annotation) else []


def _tag(model: type[BaseModel]) -> str:
    return get_args(model.model_fields["type"].annotation)[0]


# --------------------------------------------------------------------------- meaning
def _meaning_problems(data: dict) -> list[Problem]:
    """Checks against the model variant, on the raw data; malformed parts are skipped."""
    family = data.get("model")
    if not isinstance(family, str) or family not in FAMILIES:
        return []
    block = data.get("nonlinearity")
    dof = block.get("dof") if isinstance(block, dict) else None
    dofs = FAMILIES[family][1]
    if isinstance(dof, str) and dof not in dofs:
        return [(("nonlinearity", "dof"), _choice_reason(dofs, repr(dof)))]
    variant = _variant_of(data)
    if variant is None:
        return []
    values = _study_values(data, variant)
    problems = _override_problems(data.get("parameters"), variant, family)
    for name in _LAW_PARAMETERS if isinstance(block, dict) else ():
        if name in block:
            problems += _bound_problems(("nonlinearity", name), name, block[name], variant)
    items = data.get("continuations")
    problems += _continuation_problems(items, variant, family, values)
    linear = data.get("linear")
    sweeps = linear.get("sweeps") if isinstance(linear, dict) else None
    for i, sweep in _dict_items(sweeps):
        problems += _sweep_problems(("linear", "sweeps", i), sweep, variant, family)
    grid = linear.get("grid") if isinstance(linear, dict) else None
    for axis in ("x", "y"):
        spec = grid.get(axis) if isinstance(grid, dict) else None
        if isinstance(spec, dict):
            problems += _sweep_problems(("linear", "grid", axis), spec, variant, family)
    return problems


def _sweep_problems(loc: Loc, spec: dict, variant: Model, family: str) -> list[Problem]:
    """The parameter and range of a linear sweep or grid axis."""
    name = spec.get("parameter")
    found = _parameter_problems(loc + ("parameter",), name, variant, family)
    if found or not isinstance(name, str):
        return found
    return _range_problems(loc + ("range",), variant.canonical(name), spec.get("range"),
                           variant, "swept")


def _dict_items(items: Any) -> Iterator[tuple[int, dict]]:
    """(index, item) for the mapping items of a list; nothing if ``items`` is no list."""
    if isinstance(items, list):
        yield from ((i, item) for i, item in enumerate(items) if isinstance(item, dict))


def _parameter_problems(loc: Loc, name: Any, variant: Model, family: str) -> list[Problem]:
    if not isinstance(name, str) or name in variant.known_parameter_names():
        return []
    known = ", ".join(variant.known_parameter_names())
    return [(loc, f"unknown parameter {name!r} for model {family} (known: {known})")]


def _override_problems(parameters: Any, variant: Model, family: str) -> list[Problem]:
    problems: list[Problem] = []
    spelled: dict[str, str] = {}  # canonical name -> the key that gave it first
    for name, value in parameters.items() if isinstance(parameters, dict) else ():
        loc = ("parameters", name)
        found = _parameter_problems(loc, name, variant, family)
        if not found and variant.canonical(name) in _LAW_PARAMETERS:
            found = [(loc, f"set {name} under nonlinearity (type: polynomial)")]
        if not found:
            canonical = variant.canonical(name)
            if canonical in spelled:
                found = [(loc, _twice(name, spelled[canonical], canonical))]
            spelled.setdefault(canonical, name)
            found = found or _bound_problems(loc, canonical, value, variant)
        problems += found
    return problems


def _twice(name: str, other: str, canonical: str) -> str:
    """Why a parameter given under two spellings is refused."""
    same = f"both name {canonical}" if canonical not in (name, other) else \
        f"{(other if name == canonical else name)!r} is an alias of {canonical}"
    return f"{name!r} and {other!r} are the same parameter ({same}); give it once"


def _bound_problems(loc: Loc, canonical: str, value: Any, variant: Model) -> list[Problem]:
    """A value outside the parameter's physical bounds (malformed values are reported as
    structural problems)."""
    number = _finite(value)
    parameter = variant.parameter(canonical)
    if number is None or parameter.bounds.contains(number):
        return []
    return [(loc, f"{canonical} must be {parameter.bounds.text(parameter.unit)}, got "
             f"{value!r}")]


def _range_problems(loc: Loc, canonical: str, bounds: Any, variant: Model,
                    swept: str) -> list[Problem]:
    """A continuation or sweep range reaching outside the parameter's physical bounds, or a
    parameter that takes whole numbers only (which cannot be continued or swept)."""
    parameter = variant.parameter(canonical)
    if parameter.bounds.integer:
        return [(loc, f"{canonical} takes whole numbers only ({parameter.bounds.text()}) and "
                 f"cannot be {swept}")]
    ends = [_finite(b) for b in bounds] if isinstance(bounds, list) and len(bounds) == 2 else []
    outside = [e for e in ends if e is not None and not parameter.bounds.contains(e)]
    if not outside:
        return []
    return [(loc, f"the range reaches {outside[0]!r}, outside the bounds of {canonical} "
             f"({parameter.bounds.text(parameter.unit)})")]


def _continuation_problems(
    items: Any, variant: Model, family: str, values: dict[str, float]
) -> list[Problem]:
    problems: list[Problem] = []
    names: set[str] = set()
    for i, item in _dict_items(items):
        loc = ("continuations", i)
        name, parameter = item.get("name"), item.get("parameter")
        if isinstance(name, str) and name in names:
            problems.append((loc + ("name",), f"duplicate continuation name {name!r}"))
        if isinstance(name, str):
            names.add(name)
        if item.get("type") == "two-parameter":
            problems += _pair_problems(loc, item, variant, family, values)
            continue
        found = _parameter_problems(loc + ("parameter",), parameter, variant, family)
        if not found and isinstance(parameter, str):
            canonical = variant.canonical(parameter)
            found = _range_problems(loc + ("range",), canonical, item.get("range"), variant,
                                    "continued")
            found = found or _start_problems(loc, item, values[canonical])
            found += _orbits_problems(loc, item)
        problems += found
    return problems


def _orbits_problems(loc: Loc, item: dict) -> list[Problem]:
    """``orbits_at`` values outside the continuation's range."""
    bounds, orbits = item.get("range"), item.get("orbits_at")
    if not (isinstance(bounds, list) and len(bounds) == 2 and isinstance(orbits, list)):
        return []
    lower, upper = (_finite(b) for b in bounds)
    if lower is None or upper is None or not lower < upper:
        return []
    return [(loc + ("orbits_at", k), f"{number!r} is outside the range [{lower!r}, {upper!r}]")
            for k, number in enumerate(map(_finite, orbits))
            if number is not None and not lower <= number <= upper]


def _pair_problems(loc: Loc, item: dict, variant: Model, family: str,
                   values: dict[str, float]) -> list[Problem]:
    """Parameters, range keys, start and slices of a two-parameter continuation."""
    pair = item.get("parameters")
    if not isinstance(pair, list) or len(pair) != 2:
        return []
    problems: list[Problem] = []
    for k, name in enumerate(pair):
        problems += _parameter_problems(loc + ("parameters", k), name, variant, family)
    if problems or not all(isinstance(p, str) for p in pair):
        return problems
    first, second = (variant.canonical(p) for p in pair)
    if first == second:
        return [(loc + ("parameters",), f"expected two different parameters, got {pair!r}")]
    bounds = item.get("range")
    if not isinstance(bounds, dict):
        return problems
    canonical: dict[str, str] = {}
    for key in (k for k in bounds if isinstance(k, str)):
        name = variant.canonical(key) if key in variant.known_parameter_names() else key
        if name in canonical:
            return [(loc + ("range", key), _twice(key, canonical[name], name))]
        canonical[name] = key
    if set(canonical) != {first, second}:
        return [(loc + ("range",), f"expected the keys {first}, {second}, got "
                 f"{', '.join(map(str, bounds)) or 'none'}")]
    for name in (first, second):
        problems += _range_problems(loc + ("range", canonical[name]), name,
                                    bounds[canonical[name]], variant, "continued")
    if problems:
        return problems
    start_item = {"range": bounds[canonical[first]], "start": item.get("start")}
    problems += _start_problems(loc, start_item, values[first])
    limits = bounds[canonical[second]]
    slices = item.get("slices")
    if isinstance(limits, list) and len(limits) == 2 and isinstance(slices, list):
        lower, upper = (_finite(b) for b in limits)
        for k, value in enumerate(slices):
            number = _finite(value)
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
    lower, upper = (_finite(b) for b in bounds)
    written = item.get("start") is not None
    start = _finite(item["start"]) if written else study_value
    if lower is None or upper is None or start is None or not lower < upper:
        return []  # reported as a structural problem
    if lower <= start <= upper:
        return []
    key = "start" if written else "range"
    return [(loc + (key,), f"start {start!r} is outside the range [{lower!r}, {upper!r}]")]


# --------------------------------------------------------------------------- documentation
def schema_reference() -> str:
    """Markdown table of every study key: path, type, default, description."""
    rows: dict[str, list[str]] = {}
    for path, field in _fields(Study, ""):
        row = [_type_text(field.annotation), _default_text(field), field.description or ""]
        if path in rows and rows[path][0] != row[0]:
            rows[path][0] += " or " + row[0]
        rows.setdefault(path, row)
    lines = ["| Key | Type | Default | Description |", "| --- | --- | --- | --- |"]
    lines += [f"| `{path}` | {' | '.join(row)} |" for path, row in rows.items()]
    return "\n".join(lines) + "\n"


def _fields(model: type[BaseModel], prefix: str) -> Iterator[tuple[str, FieldInfo]]:
    """(key path, field) for ``model`` and the models nested in it, depth first."""
    for name, field in model.model_fields.items():
        path = prefix + name
        yield path, field
        annotation = _strip(field.annotation)
        suffix = ""
        if get_origin(annotation) is tuple and get_args(annotation)[-1:] == (Ellipsis,):
            annotation, suffix = _strip(get_args(annotation)[0]), "[]"
        for member in _union_members(annotation) or [annotation]:
            if isinstance(member, type) and issubclass(member, BaseModel):
                yield from _fields(member, f"{path}{suffix}.")


def _type_text(annotation: Any) -> str:
    annotation = _strip(annotation)
    origin, args = get_origin(annotation), get_args(annotation)
    simple = {bool: "true/false", int: "integer", float: "number", str: "string"}
    if annotation in simple:
        return simple[annotation]
    if origin is Literal:
        return " or ".join(f"`{a}`" for a in args)
    if origin is tuple and args[-1:] == (Ellipsis,):
        inner = _strip(args[0])
        if isinstance(inner, type) and issubclass(inner, BaseModel):
            return "list of mappings"
        return f"list of {_type_text(inner)}"
    if origin is tuple:
        return "[" + ", ".join(_type_text(a) for a in args) + "]"
    if origin is dict:
        return f"mapping of name: {_type_text(args[1])}"
    return "mapping"


def _default_text(field: FieldInfo) -> str:
    if field.is_required():
        return "required"
    value = field.get_default(call_default_factory=True)
    return "unset" if value is None else f"`{_yaml_flow(value)}`"


def _yaml_flow(value: Any) -> str:
    """A default as YAML flow text."""
    if isinstance(value, BaseModel):
        value = value.model_dump(exclude_defaults=True)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return value or '""'
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_yaml_flow(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_yaml_flow(v)}" for k, v in value.items()) + "}"
    return repr(value)
