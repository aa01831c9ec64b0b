"""The study schema: value checks and the pydantic models of a study file.

Every model forbids unknown keys and is frozen. A value check rejects a value with the reason a
message shows (``{got}`` becomes the value as written in the YAML, see
:mod:`whirl_cli.study.messages`); the Annotated types (``Name``, ``Number``, ``Range``, ...)
attach the checks to the fields. :class:`Study` fills the model-dependent defaults before it
validates (:mod:`whirl_cli.study.resolve`).
"""

from __future__ import annotations

import hashlib
import math
import operator
import re
from collections.abc import Callable
from typing import Annotated, Any, Literal, NoReturn

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PrivateAttr,
    model_validator,
)
from pydantic_core import PydanticCustomError

from ..continuation.numerics import Numerics
from ..kinds import PLOT_KINDS
from ..models import FAMILIES, Model, is_known, is_model_file
from .resolve import Names, _is_number, _resolved, names_of

NAME_MAX = 64
#: Largest integer AUTO-07p reads into its (32-bit) INTEGER constants (NMX, NTST, ITNW).
FORTRAN_INT_MAX = 2**31 - 1
#: Most values in ``orbits_at``: AUTO reads at most 2048 characters per constants line (UZR).
ORBITS_MAX = 64
#: The default initial state of ``explore``: the first dof displaced by this (deg for angles).
EXPLORE_OFFSET = 2.0
#: Whirl periods an ``explore`` simulation discards before it classifies (classify_model's 15
#: left a weakly attracting cycle of hardening case 2 still growing, its frequency 5 % off).
EXPLORE_TRANSIENT = 60.0
_NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")
_NAME_REASON = (
    "expected letters, digits, '_', '.', '-' (starting with a letter or digit), got {got}"
)


def _fail(reason: str, at: tuple[str | int, ...] = ()) -> NoReturn:
    """Reject a value; ``{got}`` in ``reason`` becomes the value as written in the YAML.
    ``at``: the key path, below the checked value, of the part at fault (a list item, a
    mapping's key), where the message is reported."""
    raise PydanticCustomError("whirl", "{reason}", {"reason": reason, "at": at})


def _as_string(value: Any) -> str:
    if not isinstance(value, str):
        _fail("expected a string, got {got}")
    return value


def _as_number(value: Any) -> float:
    return _number(value, ())


def _number(value: Any, at: tuple[str | int, ...]) -> float:
    """``value`` as a finite float; else the reason, reported at ``at`` below the value."""
    if not _is_number(value):
        _fail("expected a number, got {got}", at)
    if not math.isfinite(value):
        _fail("expected a finite number, got {got}", at)
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
    if not isinstance(value, list | tuple) or len(value) != 2:
        _fail("expected [lower, upper], two numbers, got {value}")
    lower, upper = (_number(v, (k,)) for k, v in enumerate(value))
    if not lower < upper:
        _fail("expected [lower, upper] with lower < upper, got {value}")
    if not (math.isfinite(upper - lower) and math.isfinite(lower - (upper - lower))
            and math.isfinite(upper + (upper - lower))):  # AUTO's bounds lie 5 % beyond
        _fail("the range is too wide: its width overflows double precision, got {value}")
    return lower, upper


def _state(value: Any, at: tuple[str | int, ...], example: str) -> dict[str, float]:
    """A mapping state name -> finite number (a seed, an initial state), each value checked at
    its key; ``example``: the mapping's shape, for the message."""
    if not isinstance(value, dict) or not all(isinstance(k, str) for k in value):
        _fail(f"expected a mapping state -> number, e.g. {example}, got {{got}}", at)
    return {k: _number(v, (*at, k)) for k, v in value.items()}


def _as_seeds(value: Any) -> str | tuple[dict[str, float], ...]:
    """``auto``, or a list of mappings state name -> finite number."""
    if value == "auto":
        return value
    if not isinstance(value, list):
        _fail("expected `auto` or a list of mappings state -> number, e.g. [{{theta: 4}}], "
              "got {got}")
    return tuple(_state(seed, (k,), "{{theta: 4}}") for k, seed in enumerate(value))


#: The description of ``seeds`` (one- and two-parameter continuations share the key).
SEEDS_TEXT = (
    "Initial states simulated at `start` until they settle; every distinct limit cycle found "
    "is continued both ways (cycles no Hopf point leads to). A list of mappings state name -> "
    "value (angles in deg, rates in deg/s, other states in their unit; unnamed states 0), or "
    "`auto`: each nonlinear dof displaced alone by 2, 4 and 8 times its law's size (freeplay: "
    "delta) or 0.05, 0.2 and 0.5 typical amplitudes. Two-parameter: simulated at `start` on "
    "every slice; the folds of cycles of the families found are loci starts (e.g. freeplay "
    "LCOs, which no Hopf point leads to).")


def _as_state(value: Any) -> dict[str, float]:
    """A mapping state name -> finite number (the names are checked against the model)."""
    return _state(value, (), "{{theta: 2}}")


def _at_most_orbits(values: tuple) -> tuple:
    if len(values) > ORBITS_MAX:
        _fail(f"at most {ORBITS_MAX} values, got {len(values)}")
    return values


def _as_model_family(value: str) -> str:
    if not is_known(value):
        if is_model_file(value):
            _fail("no model file {got}")
        _fail(f"unknown model {{got}} (built-in: {', '.join(FAMILIES)}; or a model file "
              "path ending in .yaml)")
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
#: An AUTO step, a fraction of the continuation range's width.
Step = Annotated[Positive, _bound("<=", 1)]
ModelFamily = Annotated[Text, AfterValidator(_as_model_family)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


_TYPE_DOC = (
    "Stiffness law: `linear` (linear springs; the polynomial law with K2 = K3 = 0), "
    "`polynomial` (restoring force K x + K2 x^3 + K3 x^5 on `dof`, K the dof's linear "
    "stiffness, e.g. K_theta; x in the dof's unit, rad for angles) or `freeplay` (whirl's "
    "law: a deadband of half-gap `delta`, stiffness `K_in` inside and `K_out` outside, "
    "smoothed over `epsilon` by ln cosh)."
)
_DOF_DOC = (
    "Degree of freedom the law acts on (classical: `theta` pitch, `psi` yaw); a dof has at most "
    "one law. Unset (a single law only): the model's first dof (classical: `theta`)."
)


class Linear(_Strict):
    """Linear springs: the polynomial law with K2 = K3 = 0 (one AUTO executable for both)."""

    type: Literal["linear"] = Field(description=_TYPE_DOC)
    dof: Text | None = Field(None, description=_DOF_DOC)


class Polynomial(_Strict):
    """Restoring force K x + K2 x^3 + K3 x^5 on one degree of freedom."""

    type: Literal["polynomial"] = Field(description=_TYPE_DOC)
    dof: Text | None = Field(None, description=_DOF_DOC)
    K2: Number = Field(0.0, description="Cubic coefficient, force per unit^3 (classical: "
                       "N m/rad^3); leaves the study as `K2_<dof>`.")
    K3: Number = Field(0.0, description="Quintic coefficient, force per unit^5 (classical: "
                       "N m/rad^5); leaves the study as `K3_<dof>`.")


class Freeplay(_Strict):
    """whirl's freeplay law on one degree of freedom (see :mod:`whirl_cli.models.laws.freeplay`).

    After validation ``epsilon`` is filled (delta/100 when the study gives none); ``K_out``
    unset leaves the dof's stiffness at its datum."""

    type: Literal["freeplay"] = Field(description=_TYPE_DOC)
    dof: Text | None = Field(None, description=_DOF_DOC)
    delta: Number = Field(description="Half-gap of the deadband, in the dof's unit (rad for "
                          "angles), > 0; leaves the study as `delta_<dof>`.")
    K_out: Number | None = Field(
        None, description="Stiffness outside the gap, force per unit (classical: N m/rad), "
        "> `K_in`: it is the dof's linear stiffness parameter (`K_theta` on pitch; also "
        "`K_out_<dof>`), so results, continuations and the linear model name it so; "
        "`parameters` may not set it beside the law. Unset: that parameter's datum.")
    K_in: Number = Field(0.0, description="Stiffness inside the gap, force per unit, >= 0; "
                         "leaves the study as `K_in_<dof>`.")
    epsilon: Number | None = Field(
        None, description="Smoothing width, in the dof's unit, > 0 and < `delta` (the "
        "smoothed law's largest error, (K_out - K_in) epsilon ln2 / 2, is at x = +-delta); "
        "leaves the study as `epsilon_<dof>`. Unset: delta/100.")


LawBlock = Annotated[Linear | Polynomial | Freeplay, Field(discriminator="type")]


def _as_laws(value: Any) -> Any:
    """One law mapping counts as a list of one (its errors are reported at the mapping)."""
    if isinstance(value, dict | BaseModel):
        return (value,)
    if not isinstance(value, list | tuple):
        _fail("expected a mapping (one law) or a list of mappings (one law per dof), got {got}")
    return value


Laws = Annotated[tuple[LawBlock, ...], BeforeValidator(_as_laws)]


_RUN_NAME_DOC = (
    "Run name, unique within the study (same characters as the study name); not another "
    "continuation's name followed by `.` (its AUTO runs are named `<name>.<run>`), nor, with "
    "a freeplay law, a one-parameter continuation's name followed by `_eps<k>` (its "
    "repetitions at smaller smoothing).")


class OneParameterContinuation(_Strict):
    """Equilibria in one parameter, with the branches that hang off them.

    After validation ``parameter`` is the canonical name and ``start`` is filled.
    """

    name: Name = Field(description=_RUN_NAME_DOC)
    type: Literal["one-parameter"] = Field(
        description="`one-parameter`: equilibria in one parameter (AUTO-07p continuation)."
    )
    parameter: Text = Field(
        description="Continuation parameter, by name or alias, in its SI unit (stored as the "
        "canonical name: `K1` -> `K_theta`)."
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
    spread_equilibria: Boolean = Field(
        False, description="Also seek equilibria at `start` by Newton's method from a spread of "
        "starts (each dof alone and all together at 13 amplitudes from 0.01 to 1 typical "
        "amplitude, both signs); each one on no computed branch starts a branch both ways "
        "(equilibria no branch point reaches, e.g. freeplay's offset ones)."
    )
    start_state: Annotated[dict[str, float] | None, BeforeValidator(_as_state)] = Field(
        None,
        description="Where Newton's method seeks the starting equilibrium at `start` when the "
        "zero state is not one: state name -> value (angles in deg, rates in deg/s, other "
        "states in their unit; unnamed states 0). Unset: from the zero state.",
    )
    orbits_at: Annotated[tuple[Number, ...], AfterValidator(_at_most_orbits)] = Field(
        (),
        description="Parameter values (in its unit) at which every branch stores a labelled "
        "solution: orbit profiles for phase-plane plots (AUTO UZR).",
    )
    seeds: Annotated[Any, BeforeValidator(_as_seeds)] = Field((), description=SEEDS_TEXT)

    explore: Annotated[tuple[Number, ...], AfterValidator(_at_most_orbits)] = Field(
        (),
        description="Parameter values (in its unit), each within `range`, at which the "
        "settled motion is classified by time simulation after the AUTO runs: equilibrium, "
        "periodic, quasi-periodic, chaotic or diverged, with the largest Lyapunov exponent, "
        "frequencies and Poincaré section (for the `poincare`, `spectrum` and "
        f"`orbit_diagram` plots); at most {ORBITS_MAX} values.",
    )
    explore_initial: Annotated[dict[str, float] | None, BeforeValidator(_as_state)] = Field(
        None,
        description="Initial state of the `explore` simulations, state name -> value (angles "
        "in deg, rates in deg/s, other states in their unit; unnamed states 0), as the "
        f"`seeds`. Unset: the model's first dof at {EXPLORE_OFFSET:g} (deg for an angle).",
    )
    explore_transient: Positive = Field(
        EXPLORE_TRANSIENT,
        description="Periods of the least damped whirl mode (of the linearisation at the "
        "origin) simulated and discarded before the `explore` classification's window of 20 "
        "periods (40 where its Poincaré section and spectrum disagree), > 0 (a weakly "
        "attracting cycle needs many to settle; a trajectory at rest at a stable equilibrium "
        "ends it early).",
    )
    explore_section: Text | None = Field(
        None,
        description="State whose mean level, crossed upwards, is the Poincaré section of the "
        "`explore` classification (`whirl models` lists the states). Unset: the rate of the "
        "model's first dof (classical: `dtheta`): the section is at that dof's minima, the "
        "points of the brute-force orbit diagram.",
    )

    def start_value(self, study: Study) -> float:
        """``start``, or the study value of the parameter when unset (models built by hand)."""
        if self.start is not None:
            return self.start
        names = study.names()
        name = names.canonical(self.parameter)
        return study.parameter_values().get(name, names.defaults()[name])


LocusKind = Literal["hopf", "branch_point", "fold", "fold_of_cycles", "torus"]


class Slice(_Strict):
    """A slice of a two-parameter continuation: a value of its second parameter, and how
    figures name it."""

    value: Number = Field(description="Value of the second parameter, in its unit.")
    label: Text = Field("", description="Name of the slice in figures (e.g. `case 2`); "
                        "unset: `case <k>`, its position from 1.")


def _as_slice(value: Any) -> Any:
    """A slice given as a bare number is ``{value: number}``."""
    if isinstance(value, dict):
        return value
    if not _is_number(value):
        _fail("expected a finite number or a mapping {{value, label}}, got {got}")
    return {"value": _as_number(value)}


SliceEntry = Annotated[Slice, BeforeValidator(_as_slice)]


class TwoParameterContinuation(_Strict):
    """Loci of Hopf points, branch points, folds and folds of cycles in two parameters, the
    stability boundary they draw and the unsafe (overhang) region.

    After validation ``parameters`` are canonical names and ``start`` and ``slices`` are filled;
    ``bounds(model)`` gives ``range`` by canonical names.
    """

    name: Name = Field(description=_RUN_NAME_DOC)
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
    slices: tuple[SliceEntry, ...] = Field(
        (),
        json_schema_extra={"type_text": "list of number or {value, label}"},
        description="Values of the second parameter at which one-parameter runs find the "
        "special points the loci start from, and at which unsafe intervals are reported, each "
        "a number or `{value: number, label: text}` (`label` names it in figures); unset: its "
        "study value.",
    )
    seeds: Annotated[Any, BeforeValidator(_as_seeds)] = Field((), description=SEEDS_TEXT)
    loci: tuple[LocusKind, ...] = Field(
        ("hopf", "branch_point", "fold", "fold_of_cycles"),
        description="Which loci to continue: `hopf`, `branch_point` (pitchfork), `fold` (of "
        "equilibria), `fold_of_cycles` (needs the periodic branches, computed for it), "
        "`torus` (torus, Neimark-Sacker, bifurcations of cycles; needs the periodic branches "
        "too; drawn, not used for the unsafe region). Default: all but `torus`.",
    )
    snaking_folds: Literal["all", "outermost"] = Field(
        "outermost",
        description="Folds of cycles of a family snaking toward a homoclinic orbit (three or "
        "more of one family at one point of a slice, to 1e-3 of the ranges): `outermost` "
        "traces only the loci of the lowest- and highest-period ones, along which the others' "
        "lie (on the chapter-3 boundaries within 3e-3 of the ranges, the unsafe region the "
        "same; 20-30 % less AUTO time there); `all` the locus of each.",
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

    def bounds(self, names: Names | Model) -> dict[str, tuple[float, float]]:
        """``range`` keyed by canonical parameter names (``names``: the study's)."""
        return {names.canonical(key): tuple(value) for key, value in self.range.items()}

    @property
    def slice_values(self) -> tuple[float, ...]:
        """The values of the slices, in order."""
        return tuple(s.value for s in self.slices)

    @property
    def slice_labels(self) -> tuple[str, ...]:
        """The labels of the slices, in order ("" where the study gives none)."""
        return tuple(s.label for s in self.slices)


PlotKind = Literal[PLOT_KINDS]
Continuation = Annotated[OneParameterContinuation | TwoParameterContinuation,
                        Field(discriminator="type")]


class LinearAxisSpec(_Strict):
    """One parameter on an even grid of values: a grid axis."""

    parameter: Text = Field(
        description="Swept parameter, by name or alias (stored as the canonical name)."
    )
    range: Range = Field(description="[lower, upper] of the sweep, in the parameter's unit.")
    points: Annotated[Integer, _bound(">=", 2), _bound("<=", 100000)] = Field(
        201, description="Number of equally spaced values, 2 to 100000."
    )


class LinearSweepSpec(LinearAxisSpec):
    """Eigenvalues along one parameter, on an even grid (of its values, or of multiples of
    its datum)."""

    range: Range = Field(description="[lower, upper] of the sweep, in the parameter's unit "
                         "(with `multiples: true`, in multiples of its datum, both > 0).")
    multiples: Boolean = Field(
        False, description="`range` is in multiples of the parameter's datum (the model's "
        "value, `whirl models`), e.g. [0.25, 4]; the sweep is stored in absolute values with "
        "the datum beside them. The datum must be non-zero.")


class LinearGridSpec(_Strict):
    """Linear stability over a grid of two parameters."""

    x: LinearAxisSpec = Field(description="First grid axis: parameter, range, points.")
    y: LinearAxisSpec = Field(description="Second grid axis: another parameter, range, "
                              "points.")


class LinearSpec(_Strict):
    """Linear (eigenvalue) analysis, done with numpy, without AUTO."""

    sweeps: tuple[LinearSweepSpec, ...] = Field(
        (), description="Eigenvalue sweeps (damping ratio, frequency, whirl direction), one "
        "per parameter."
    )
    grid: LinearGridSpec | None = Field(
        None,
        description="Max real part of the eigenvalues of y = 0 over a grid, with its zero "
        "contour split into flutter and divergence parts; unset: none.",
    )


#: Most samples a simulation stores (8 states: 64 MB).
SAMPLES_MAX = 1_000_000


class SimulationSpec(_Strict):
    """A time simulation from a stated initial state (scipy, without AUTO).

    After validation ``name`` is filled (``sim_<k>``, its position from 1)."""

    name: Name | None = Field(
        None, description="Simulation name, unique within the study (same characters as the "
        "study name). Unset: `sim_<k>`, its position from 1.")
    parameters: dict[str, Number] = Field(
        default_factory=dict,
        description="Overrides for this simulation, by name or alias, in SI units, applied "
        "on top of the study's `parameters` (same rules: law coefficients go under "
        "`nonlinearity`).")
    initial: Annotated[dict[str, float], BeforeValidator(_as_state)] = Field(
        description="Initial state, state name -> value (angles in deg, rates in deg/s, other "
        "states in their unit; unnamed states 0), as the `seeds` of a continuation.")
    duration: Positive = Field(description="Simulated time, s, > 0.")
    samples: Annotated[Integer, _bound(">=", 2), _bound("<=", SAMPLES_MAX)] = Field(
        2001, description=f"Output points, equally spaced from 0 to `duration`, 2 to "
        f"{SAMPLES_MAX}.")
    law: Literal["smoothed", "exact"] = Field(
        "smoothed", description="`smoothed`: the model as AUTO continues it (scipy LSODA); "
        "`exact`: the unsmoothed piecewise law, integrated piece by piece (only with a "
        "freeplay law).")


#: (smaller, larger) pairs of AUTO step settings, checked in this order.
_STEP_ORDER = (("step_min", "step_max"), ("step_initial", "step_max"), ("step_min", "step_initial"))


class AutoSettings(_Strict):
    """AUTO-07p settings under readable names; unset ones use whirl's defaults."""

    max_steps: Annotated[Integer, _bound(">=", 1), _bound("<=", FORTRAN_INT_MAX)] | None = Field(
        None, description="Maximum continuation steps per run (AUTO NMX), >= 1; a branch "
        "that uses them up before its range ends fails the study."
    )
    step_initial: Step | None = Field(
        None, description="Initial step (AUTO DS), fraction of the continuation range width, "
        "> 0 and <= 1, from `step_min` to `step_max`."
    )
    step_min: Step | None = Field(
        None, description="Smallest step (AUTO DSMIN), fraction of the range width, > 0 and "
        "<= `step_max`."
    )
    step_max: Step | None = Field(
        None, description="Largest step (AUTO DSMAX), fraction of the range width, > 0 and "
        "<= 1."
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
        None, description="Amplitude at which branches are stopped, in units of each dof's "
        "typical amplitude (`whirl models` lists them; classical: 1 rad), > 0."
    )

    @model_validator(mode="after")
    def _steps_in_order(self) -> AutoSettings:
        """step_min <= step_initial <= step_max, an unset one at whirl's default."""
        for low, high in _STEP_ORDER:
            problem = _step_order_problem(self, low, high)
            if problem is not None:
                _fail(*problem)
        return self


def _step_order_problem(settings: AutoSettings, low: str, high: str
                        ) -> tuple[str, tuple[str]] | None:
    """Why the step ``low`` exceeds ``high`` (each as given, else whirl's default), and the
    key given to report it at; None if they are in order or both unset."""
    given = getattr(settings, low), getattr(settings, high)
    if given == (None, None):
        return None
    defaults = Numerics()
    lower, upper = (getattr(defaults, key) if value is None else value
                    for key, value in zip((low, high), given, strict=True))
    if lower <= upper:
        return None
    if given[0] is None:
        return f"must be >= {low} ({lower:g}, whirl's default), got {{got}}", (high,)
    note = ", whirl's default" if given[1] is None else ""
    return f"must be <= {high} ({upper:g}{note}), got {{got}}", (low,)


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
        "units (angles in rad; `whirl models` lists units and bounds). Law coefficients go under "
        "`nonlinearity`. With one law, `K1`, `K2`, `K3` name its dof's stiffness and coefficients "
        "(the thesis' names: `K1` = `K_theta` for a law on pitch).",
    )
    nonlinearity: Laws = Field(
        default=(Linear(type="linear"),),
        json_schema_extra={"type_text": "mapping, or list of mappings"},
        description="Structural stiffness laws: one mapping (one law), or a list of mappings, "
        "one law per dof. A law replaces its dof's stiffness term K x.",
    )
    continuations: tuple[Continuation, ...] = Field(
        (), description="AUTO-07p continuation runs, in order."
    )
    linear: LinearSpec | None = Field(
        None, description="Linear (eigenvalue) analysis without AUTO; unset: none."
    )
    simulations: tuple[SimulationSpec, ...] = Field(
        (), description="Time simulations from stated initial states (scipy, no AUTO: a study "
        "may hold only these), for the `time_history` and `hub_path` plots."
    )
    plots: tuple[PlotKind, ...] = Field(
        ("bifurcation",), description="Figures drawn after the runs."
    )
    plot_state: Text | None = Field(
        None,
        description="State the bifurcation diagrams draw (`bifurcation`, and the slices of "
        "`boundary`): a dof or a rate of the model (`whirl models` lists them, e.g. `psi`, "
        "`dq2`). Unset: the model's first dof (classical: `theta`).",
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
    #: the field values ``_source`` describes (a copy with others is described by its own text)
    _read: dict = PrivateAttr(default_factory=dict)

    @model_validator(mode="before")
    @classmethod
    def _fill_model_defaults(cls, data: Any) -> Any:
        return _resolved(data) if isinstance(data, dict) else data

    @property
    def source(self) -> str:
        """The YAML text of this study: the text it was read from, or, for a study whose
        values are not that text's (a ``model_copy(update=...)``, one built in code), its
        values written as YAML (what a result stores must describe what was computed)."""
        return self._source if self._as_read() else _yaml_text(self)

    @property
    def sha256(self) -> str:
        """sha256 (hex) of the UTF-8 YAML text :attr:`source`."""
        if self._as_read():
            return self._sha256
        return hashlib.sha256(self.source.encode("utf-8")).hexdigest()

    def _as_read(self) -> bool:
        """Whether every field holds the value read from :attr:`_source`."""
        fields, read = self.__dict__, self._read
        return bool(read) and fields.keys() == read.keys() and all(
            fields[key] is value or fields[key] == value for key, value in read.items())

    @property
    def path(self) -> str:
        """The path the study was loaded from, as given (or the name given to validate_text)."""
        return self._path

    @property
    def laws(self) -> tuple[Linear | Polynomial | Freeplay, ...]:
        """The law blocks (after validation every one names its dof)."""
        return self.nonlinearity

    def names(self) -> Names:
        """The parameter names this study may use (the variant's, and the thesis' K1, K2, K3
        for a single law's dof)."""
        names = names_of(self.model, [(law.dof, law) for law in self.laws])
        assert names is not None, "a validated study has valid laws"
        return names

    def variant(self) -> Model:
        """The model variant: the polynomial law on every dof (linear is K2 = K3 = 0) unless a
        study names another law."""
        return self.names().model

    def simulation_values(self, spec: SimulationSpec) -> dict[str, float]:
        """Canonical name -> value: the study's (:meth:`parameter_values`) with the
        simulation's own overrides on top."""
        return {**self.parameter_values(), **self.simulation_overrides(spec)}

    def simulation_overrides(self, spec: SimulationSpec) -> dict[str, float]:
        """The simulation's own overrides, by canonical name."""
        names = self.names()
        return {names.canonical(k): float(v) for k, v in spec.parameters.items()}

    def parameter_values(self) -> dict[str, float]:
        """Canonical name -> value for every override and every law coefficient."""
        names = self.names()
        values = {names.canonical(k): v for k, v in self.parameters.items()}
        for law in self.laws:
            for key, name in names.model.coefficient_names(law.dof).items():
                value = getattr(law, key, 0.0)
                if value is not None:  # None: freeplay's K_out unset (the dof's datum)
                    values[name] = float(value)
        return values


def _yaml_text(study: Study) -> str:
    """``study``'s values as study YAML (those at their defaults left out); it validates to
    the same values."""
    import yaml

    data = study.model_dump(mode="json", exclude_defaults=True)
    return yaml.safe_dump(data, sort_keys=False, allow_unicode=True)
