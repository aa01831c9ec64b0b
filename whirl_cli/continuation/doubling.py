"""Period-doubled families: from every period-doubling (PD) point of a periodic family, AUTO's
branch switching (ISW=-1 at the PD label; AUTO doubles the period) onto the family of orbits of
twice the period, continued fold by fold to its ends as the families of :mod:`.periodic` are;
and from their own PD points in turn, up to :data:`MAX_DOUBLINGS` levels (a cascade).

The two directions along a doubled family from its PD point are the same orbits half a period
apart, so each is continued one way only.
"""

from __future__ import annotations

from ..results import Branch, BranchKind, Origin, PointType, SpecialPoint
from .engine import Engine, Numerics, RunSpec
from .periodic import FamilySide, collect, continue_families, end_of, periodic_constants

#: Levels of a period-doubling cascade followed (period 2, 4, 8 times the first family's).
MAX_DOUBLINGS = 3


def doubled_families(engine: Engine, name: str, parameter: str, bounds: tuple[float, float],
                     numerics: Numerics, families: list[Branch], points: list[SpecialPoint],
                     equilibria: list[Branch], parameters: dict[str, float]
                     ) -> tuple[list[Branch], list[SpecialPoint]]:
    """The period-doubled family of every PD point of ``families`` (branch
    ``<family>_pd<k>``, k counting that family's PD points), and of theirs, with their special
    points. ``points``: the special points found so far (the equilibria's Hopf points end a
    family that shrinks onto one)."""
    model = engine.model
    width = bounds[1] - bounds[0]
    hopfs = [p for p in points if p.point_type == PointType.HB]
    kept: list[Branch] = []
    found: list[SpecialPoint] = []
    level, current = families, [p for p in points if p.point_type == PointType.PD]
    for _ in range(MAX_DOUBLINGS):
        starts = _starts(engine, name, parameter, bounds, numerics, level, current)
        if not starts:
            break
        continue_families(engine, starts, hopfs, width)
        ended = [end_of(f, model, hopfs, bounds, numerics, equilibria, parameters) for f in starts]
        level, current = collect(engine, name, bounds, parameters, hopfs,
                                  [(side.branch, side.blowups()) for side in ended],
                                  skip_first=True)
        kept += level
        found += current
        current = [p for p in current if p.point_type == PointType.PD]
    return kept, found


def _starts(engine: Engine, name: str, parameter: str, bounds: tuple[float, float],
            numerics: Numerics, families: list[Branch], points: list[SpecialPoint]
            ) -> list[FamilySide]:
    """One family to continue from each of the PD ``points`` on one of ``families``."""
    by_name = {b.name: b for b in families}
    starts: list[FamilySide] = []
    count: dict[str, int] = {}
    for point in points:
        branch = by_name.get(point.branch)
        if branch is None:
            continue
        count[branch.name] = count.get(branch.name, 0) + 1
        family = f"{branch.name}_pd{count[branch.name]}"
        period = 2 * point.period
        constants = periodic_constants(engine.model, numerics, parameter, bounds,
                                       period * engine.model.time_scale)
        constants.update(ISW=-1, STOP=["LP1"])
        label = int(branch.label[point.index])
        spec = RunSpec(f"{name}/{family}.0", constants, BranchKind.PERIODIC,
                       Origin.at(point), (parameter,),
                       restart=(engine.run_with_label(branch.runs, label), label))
        starts.append(FamilySide(family, period, spec, []))
    return starts
