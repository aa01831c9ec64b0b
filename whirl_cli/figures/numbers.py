"""The thesis's numbers beside whirl's: a sheet's ``thesis:`` entries (each the thesis's value
and the special point of a study's result that is whirl's), read into rows of the index's
table (:func:`comparisons`) with their relative difference."""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import WhirlError
from ..results import ContinuationKind, LocateStatus, PointType, SpecialPoint, StudyResult
from .index import Comparison

if TYPE_CHECKING:
    from .sheet import Sheet, ThesisNumber

POINTS = tuple(t.name for t in PointType if t.is_special and t > 0)
"""Names of the point types a ``thesis:`` entry can compare (:class:`PointType`)."""


def relative_difference(whirl: float, value: float | None,
                        between: tuple[float, float] | None) -> float | None:
    """(whirl - thesis) / |thesis|: to ``value``, or to the nearer end of the range
    ``between`` (0 inside it); None without a thesis value or when it is 0."""
    if between is not None:
        low, high = between
        if low <= whirl <= high:
            return 0.0
        value = low if whirl < low else high
    if value is None or value == 0:
        return None
    return (whirl - value) / abs(value)


def whirl_point(result: StudyResult, number: ThesisNumber) -> SpecialPoint:
    """whirl's point of ``number``: of its type, on its continuation (unset: every
    one-parameter one) and branch (unset: any), located or bracketed and not an artefact,
    the one nearest :attr:`ThesisNumber.target` (the first of equals)."""
    kind = PointType[number.point]
    continuations = [c for c in result.continuations
                     if c.name == number.continuation
                     or (number.continuation is None and c.kind == ContinuationKind.ONE_PARAMETER)]
    if not continuations:
        raise WhirlError(f"no continuation {number.continuation!r}" if number.continuation
                         else "no one-parameter continuation")
    points = [p for c in continuations for p in c.special_points
              if p.point_type == kind and p.status != LocateStatus.REJECTED and not p.artefact
              and number.branch in (None, p.branch)]
    if not points:
        on = f" on branch {number.branch}" if number.branch else ""
        raise WhirlError(f"no {kind.name} point{on}")
    return min(points, key=lambda p: abs(float(p.parameters[0]) - number.target))


def comparison(figure: str, number: ThesisNumber, read: Callable[[], StudyResult]
               ) -> Comparison:
    """One row of the table: ``number`` beside whirl's value in the result ``read`` returns
    (a row with its problem if there is no result, whirl has no such point or stores it in
    another unit)."""
    row = Comparison(figure, number.name, number.value, number.between, number.unit,
                     number.point)
    try:
        result = read()
        point = whirl_point(result, number)
    except WhirlError as error:
        return row._replace(problem=str(error))
    unit = point.parameter_units[0] if point.parameter_units else number.unit
    if unit.strip() != number.unit.strip():
        return row._replace(problem=f"whirl stores {point.parameter_names[0]} in {unit}, "
                                    f"not {number.unit}")
    value = float(point.parameters[0])
    difference = relative_difference(value, number.value, number.between)
    return row._replace(whirl=value, difference=difference,
                        where=f"{result.study_name}: {point.branch}")


def comparisons(sheet: Sheet, read: Callable[[Path], StudyResult]) -> list[Comparison]:
    """The rows of ``sheet``'s ``thesis:`` entries, whirl's values from ``read`` (a study path
    -> its result; a WhirlError there is the row's problem)."""
    return [comparison(sheet.figure, number, partial(read, sheet.thesis_study(number)))
            for number in sheet.thesis]
