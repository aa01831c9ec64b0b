"""The registry of continuation types: one :class:`ContinuationType` per study ``type``,
declared in a module of this package beside its spec (a new type is a new module here and
its recipe).

Everything that lists or dispatches continuation types reads it: the study schema's union of
continuation specs, the model-dependent defaults (:mod:`whirl_cli.study.resolve`), the meaning
checks (:mod:`whirl_cli.study.checks`), the pipeline and the cost estimate of ``whirl sweep``.
The modules are light: they import their recipe, checks and AUTO code inside functions.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import TYPE_CHECKING, Any, NamedTuple

from pydantic import Field

from ...documents.values import Name, Strict

if TYPE_CHECKING:
    from ...results import Boundary, ContinuationResult

RUN_NAME_DOC = (
    "Run name, unique within the study (same characters as the study name); not another "
    "continuation's name followed by `.` (its AUTO runs are named `<name>.<run>`), nor, with "
    "a freeplay law, a one-parameter continuation's name followed by `_eps<k>` (its "
    "repetitions at smaller smoothing).")


class ContinuationSpec(Strict):
    """What every continuation of a study has: a name (its ``type`` is its spec's own)."""

    name: Name = Field(description=RUN_NAME_DOC)

    @property
    def slice_labels(self) -> tuple[str, ...]:
        """The labels of its slices, in order (none: a continuation without slices)."""
        return ()


class ContinuationType(NamedTuple):
    """One continuation type, the study's ``type: <name>``.

    ``rank``: its place in the schema's union (and so in messages naming the types).
    ``spec``: the schema of its study block (a :class:`ContinuationSpec` whose ``type`` is
    ``Literal[name]``). ``recipe(stage, spec)``: runs it on the engine of ``stage`` (a
    :class:`whirl_cli.continuation.recipes.Stage`), returns its result and its boundary
    (None: none).
    ``cost(spec, study)``: its rough relative cost, in one-parameter runs without periodic
    families (``whirl sweep`` starts the costly studies first). ``resolved(item, names,
    values)``: its raw study mapping with canonical parameter names and the defaults the
    study values give (``values`` None: names only). ``problems(loc, item, names, family,
    values)``: its meaning checks, (key path, reason) pairs. ``repeated``: a smoothed law
    repeats it as ``<name>_eps<k>`` (those names are taken). (Named tuples, not dataclasses:
    the study schema builds them at import.)"""

    name: str
    rank: int
    spec: type[ContinuationSpec]
    recipe: Callable[..., tuple[ContinuationResult, Boundary | None]]
    cost: Callable[[Any, Any], int]
    resolved: Callable[..., dict]
    problems: Callable[..., list]
    repeated: bool = False


@cache
def registry() -> dict[str, ContinuationType]:
    """Every type declared in this package's modules, by name, in rank order."""
    from ...registries import by_rank, declared

    return by_rank(declared(__name__, __path__, ContinuationType, "continuation type"))


def get(name: Any) -> ContinuationType | None:
    """The type named ``name`` (None: no such type)."""
    return registry().get(name) if isinstance(name, str) else None


def of(spec: ContinuationSpec) -> ContinuationType:
    """The type of a validated continuation ``spec``."""
    return registry()[spec.type]


def first() -> ContinuationType:
    """The first type: the one a raw mapping without a known ``type`` is read as."""
    return next(iter(registry().values()))


def specs() -> tuple[type[ContinuationSpec], ...]:
    """The spec of every type, in rank order."""
    return tuple(kind.spec for kind in registry().values())
