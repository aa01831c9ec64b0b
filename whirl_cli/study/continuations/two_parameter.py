"""The ``two-parameter`` continuation type: loci of special points in two parameters, the
stability boundary and the unsafe region (its recipe:
:func:`whirl_cli.continuation.recipes.continue_two_parameter`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Any, Literal

from pydantic import BeforeValidator, Field

from ...documents.values import (
    SEEDS_TEXT,
    Integer,
    Number,
    Range,
    Strict,
    Text,
    as_number,
    as_seeds,
    bound,
    fail,
    is_number,
)
from ...kinds import ContinuationKind
from ...kinds import LocusKind as Locus
from ..resolve import Names, resolved_pair
from . import ContinuationSpec, ContinuationType

if TYPE_CHECKING:
    from ...models import Model

LocusKind = Literal["hopf", "branch_point", "fold", "fold_of_cycles", "torus"]


class Slice(Strict):
    """A slice of a two-parameter continuation: a value of its second parameter, and how
    figures name it."""

    value: Number = Field(description="Value of the second parameter, in its unit.")
    label: Text = Field("", description="Name of the slice in figures (e.g. `case 2`); "
                        "unset: `case <k>`, its position from 1.")


def _as_slice(value: Any) -> Any:
    """A slice given as a bare number is ``{value: number}``."""
    if isinstance(value, dict):
        return value
    if not is_number(value):
        fail("expected a finite number or a mapping {{value, label}}, got {got}")
    return {"value": as_number(value)}


SliceEntry = Annotated[Slice, BeforeValidator(_as_slice)]


class TwoParameterContinuation(ContinuationSpec):
    """Loci of Hopf points, branch points, folds and folds of cycles in two parameters, the
    stability boundary they draw and the unsafe (overhang) region.

    After validation ``parameters`` are canonical names and ``start`` and ``slices`` are filled;
    ``bounds(model)`` gives ``range`` by canonical names.
    """

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
    seeds: Annotated[Any, BeforeValidator(as_seeds)] = Field((), description=SEEDS_TEXT)
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
    resolution: Annotated[Integer, bound(">=", 3), bound("<=", 2001)] = Field(
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


def _recipe(stage, spec: TwoParameterContinuation):
    from ...continuation.recipes import continue_two_parameter

    return continue_two_parameter(stage, spec)


def _cost(spec: TwoParameterContinuation, study) -> int:
    """A one-parameter run per slice, then its loci per slice (loci of folds of cycles are
    periodic problems: the most expensive by far)."""
    return len(spec.slices) * (3 + 2 * len(spec.loci)
                               + 6 * (Locus.FOLD_OF_CYCLES in spec.loci))


def _problems(loc, item: dict, names: Names, family: str, values: dict[str, float]) -> list:
    from ..checks import pair_problems

    return pair_problems(loc, item, names, family, values)


TWO_PARAMETER = ContinuationType(ContinuationKind.TWO_PARAMETER, 20, TwoParameterContinuation,
                                 _recipe, _cost, resolved_pair, _problems)
