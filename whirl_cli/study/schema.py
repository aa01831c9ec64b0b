"""The study schema: the pydantic models of a study file.

Every model forbids unknown keys and is frozen. The value checks are those of
:mod:`whirl_cli.documents.values`, the continuation specs those of the registered types
(:mod:`whirl_cli.study.continuations`). :class:`Study` fills the model-dependent defaults
before it validates (:mod:`whirl_cli.study.resolve`).
"""

from __future__ import annotations

import functools
import hashlib
import operator
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    Field,
    PrivateAttr,
    create_model,
    model_validator,
)

from ..continuation.numerics import Numerics
from ..documents.values import (
    FORTRAN_INT_MAX,
    NAME_MAX,
    Boolean,
    Integer,
    Name,
    Number,
    Positive,
    Range,
    Step,
    Strict,
    Text,
    as_state,
    bound,
    fail,
)
from ..kinds import Spacing
from ..models import FAMILIES, Model, is_known, is_model_file
from ..models.laws import LAWS, POLYNOMIAL, Coefficient, Law
from ..plots.kinds import plot_kinds
from . import continuations
from .continuations.one_parameter import OneParameterContinuation  # noqa: F401 - re-exported
from .continuations.two_parameter import Slice, TwoParameterContinuation  # noqa: F401
from .resolve import Names, names_of, resolved


def _as_model_family(value: str) -> str:
    if not is_known(value):
        if is_model_file(value):
            fail("no model file {got}")
        fail(f"unknown model {{got}} (built-in: {', '.join(FAMILIES)}; or a model file "
             "path ending in .yaml)")
    return value


ModelFamily = Annotated[Text, AfterValidator(_as_model_family)]

_LINEAR_DOC = "linear springs; the polynomial law with K2 = K3 = 0"
_DOF_DOC = (
    "Degree of freedom the law acts on (classical: `theta` pitch, `psi` yaw); a dof has at most "
    "one law. Unset (a single law only): the model's first dof (classical: `theta`)."
)


def _type_doc() -> str:
    """The ``type`` key described: ``linear`` and every law of :data:`LAWS`."""
    kinds = [f"`linear` ({_LINEAR_DOC})"] + [f"`{law.name}` ({law.study_doc})"
                                           for law in LAWS.values()]
    return f"Stiffness law: {', '.join(kinds[:-1])} or {kinds[-1]}."


class Linear(Strict):
    """Linear springs: the polynomial law with K2 = K3 = 0 (one AUTO executable for both)."""

    type: Literal["linear"] = Field(description=_type_doc())
    dof: Text | None = Field(None, description=_DOF_DOC)


def _coefficient_field(law: Law, coefficient: Coefficient) -> tuple[Any, Any]:
    """(type, field) of a law coefficient's key in a study's law block."""
    doc = (f"{coefficient.doc}; leaves the study as "
           f"`{law.parameter_name(coefficient.key, '<dof>')}`.")
    if coefficient.required:
        return Number, Field(description=doc)
    if coefficient.unset:
        return Number | None, Field(None, description=f"{doc} Unset: {coefficient.unset}.")
    return Number, Field(coefficient.default, description=doc)


def _law_block(law: Law) -> type[Strict]:
    """The schema of a study's block of ``law``: ``type``, ``dof``, the coefficients a study
    must give, the law's own key for the dof's stiffness (if it has one), the others."""
    stiffness = {} if law.stiffness_key is None else {
        law.stiffness_key: (Number | None, Field(None, description=law.stiffness_doc))}
    fields = {"type": (Literal[law.name], Field(description=_type_doc())),
              "dof": (Text | None, Field(None, description=_DOF_DOC)),
              **{c.key: _coefficient_field(law, c) for c in law.coefficients if c.required},
              **stiffness,
              **{c.key: _coefficient_field(law, c) for c in law.coefficients
                 if not c.required}}
    return create_model(law.name.capitalize(), __base__=Strict, __module__=__name__,
                        __doc__=law.description, **fields)


#: The schema of a study's block of each law of :data:`LAWS`, by ``type``.
LAW_BLOCKS: dict[str, type[Strict]] = {name: _law_block(law) for name, law in LAWS.items()}
Polynomial = LAW_BLOCKS[POLYNOMIAL.name]

LawBlock = Annotated[functools.reduce(operator.or_, LAW_BLOCKS.values(), Linear),
                     Field(discriminator="type")]


def _as_laws(value: Any) -> Any:
    """One law mapping counts as a list of one (its errors are reported at the mapping)."""
    if isinstance(value, dict | BaseModel):
        return (value,)
    if not isinstance(value, list | tuple):
        fail("expected a mapping (one law) or a list of mappings (one law per dof), got {got}")
    return value


Laws = Annotated[tuple[LawBlock, ...], BeforeValidator(_as_laws)]


PlotKind = Literal[plot_kinds()]
#: A study's continuation block: the spec of each registered type, by ``type``.
Continuation = Annotated[functools.reduce(operator.or_, continuations.specs()),
                         Field(discriminator="type")]


class LinearAxisSpec(Strict):
    """One parameter sampled over a range, evenly or with a constant ratio: a grid axis."""

    parameter: Text = Field(
        description="Swept parameter, by name or alias (stored as the canonical name)."
    )
    range: Range = Field(description="[lower, upper] of the sweep, in the parameter's unit.")
    points: Annotated[Integer, bound(">=", 2), bound("<=", 100000)] = Field(
        201, description="Number of values, from `lower` to `upper`, 2 to 100000."
    )
    spacing: Literal[tuple(Spacing)] = Field(
        Spacing.LINEAR, description="`linear`: equally spaced values; `log`: a constant "
        "ratio between neighbours, lower (upper/lower)^(k/(points - 1)), for a parameter "
        "spanning decades (the range > 0; its plots draw the axis log).")

    @model_validator(mode="after")
    def _log_range_positive(self) -> LinearAxisSpec:
        """A log spacing samples a positive range only."""
        if self.spacing == Spacing.LOG and not self.range[0] > 0:
            fail(f"with spacing: log the range must be > 0, got {self.range[0]!r}", ("range",))
        return self


class LinearSweepSpec(LinearAxisSpec):
    """Eigenvalues along one parameter, on an even grid (of its values, or of multiples of
    its datum)."""

    range: Range = Field(description="[lower, upper] of the sweep, in the parameter's unit "
                         "(with `multiples: true`, in multiples of its datum, both > 0).")
    multiples: Boolean = Field(
        False, description="`range` is in multiples of the parameter's datum (the model's "
        "value, `whirl models`), e.g. [0.25, 4]; the sweep is stored in absolute values with "
        "the datum beside them. The datum must be non-zero.")


class LinearGridSpec(Strict):
    """Linear stability over a grid of two parameters."""

    x: LinearAxisSpec = Field(description="First grid axis: parameter, range, points, "
                              "spacing.")
    y: LinearAxisSpec = Field(description="Second grid axis: another parameter, range, "
                              "points, spacing.")


class LinearSpec(Strict):
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


class SimulationSpec(Strict):
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
    initial: Annotated[dict[str, float], BeforeValidator(as_state)] = Field(
        description="Initial state, state name -> value (angles in deg, rates in deg/s, other "
        "states in their unit; unnamed states 0), as the `seeds` of a continuation.")
    duration: Positive = Field(description="Simulated time, s, > 0.")
    samples: Annotated[Integer, bound(">=", 2), bound("<=", SAMPLES_MAX)] = Field(
        2001, description=f"Output points, equally spaced from 0 to `duration`, 2 to "
        f"{SAMPLES_MAX}.")
    law: Literal["smoothed", "exact"] = Field(
        "smoothed", description="`smoothed`: the model as AUTO continues it (scipy LSODA); "
        "`exact`: the unsmoothed piecewise law, integrated piece by piece (only with a "
        "freeplay law).")


#: (smaller, larger) pairs of AUTO step settings, checked in this order.
_STEP_ORDER = (("step_min", "step_max"), ("step_initial", "step_max"), ("step_min", "step_initial"))


class AutoSettings(Strict):
    """AUTO-07p settings under readable names; unset ones use whirl's defaults."""

    max_steps: Annotated[Integer, bound(">=", 1), bound("<=", FORTRAN_INT_MAX)] | None = Field(
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
        Integer, bound(">=", 2), bound("<=", FORTRAN_INT_MAX)] | None = Field(
        None, description="Mesh intervals for periodic orbits (AUTO NTST), >= 2."
    )
    collocation_points: Annotated[Integer, bound(">=", 2), bound("<=", 7)] | None = Field(
        None, description="Collocation points per mesh interval (AUTO NCOL), 2 to 7."
    )
    newton_max_iterations: Annotated[
        Integer, bound(">=", 1), bound("<=", FORTRAN_INT_MAX)] | None = Field(
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
                fail(*problem)
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


class Study(Strict):
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
        return resolved(data) if isinstance(data, dict) else data

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
    def laws(self) -> tuple[Any, ...]:
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
