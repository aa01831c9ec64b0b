"""Period-doubled families: from every period-doubling (PD) point of a periodic family, AUTO's
branch switching (ISW=-1 at the PD label; AUTO doubles the period) onto the family of orbits of
twice the period, continued fold by fold to its ends as the families of :mod:`.periodic` are;
and from their own PD points in turn, up to :data:`MAX_DOUBLINGS` levels (a cascade).

The two directions along a doubled family from its PD point are the same orbits half a period
apart, so each is continued one way only. Of a symmetric model, the doubled family at a PD
point that mirrors another (on the mirror image of its family) is the mirror image of that
one's (the equations are invariant, and the doubled family at a PD point is unique): mapped
(:mod:`.mirror`), not computed again.
"""

from __future__ import annotations

from ..results import Branch, BranchKind, Origin, PointType, SpecialPoint
from .engine import Engine, Numerics, RunSpec
from .mirror import mirror_points, mirrored_branch, mirrored_point
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
        named = _named(level, current)
        if not named:
            break
        by_name = {b.name: b for b in level}
        images = mirror_points(model, [p for p, _ in named], by_name, width, parameters)
        mapped = _mapped(level)
        starts = [_start(engine, name, parameter, bounds, numerics, by_name[point.branch],
                         point, family)
                  for k, (point, family) in enumerate(named)
                  if k not in images and point.branch not in mapped]
        continue_families(engine, starts, hopfs, width)
        ended = [end_of(f, model, hopfs, bounds, numerics, equilibria, parameters) for f in starts]
        computed, current = collect(engine, name, bounds, parameters, hopfs,
                                    [(side.branch, side.blowups()) for side in ended],
                                    skip_first=True)
        level, current = _with_images(named, images, computed, current)
        kept += level
        found += current
        current = [p for p in current if p.point_type == PointType.PD]
    return kept, found


def _mapped(families: list[Branch]) -> set[str]:
    """The names of ``families`` mapped from another (holding its runs: a restart from one of
    their labels would give the other's orbit, so their PD points are only ever mapped)."""
    return {b.name for k, b in enumerate(families) if any(b.runs == a.runs
                                                          for a in families[:k])}


def _named(families: list[Branch], points: list[SpecialPoint]
           ) -> list[tuple[SpecialPoint, str]]:
    """(PD point, name of its doubled family) of every one of ``points`` on ``families``."""
    names = {b.name for b in families}
    count: dict[str, int] = {}
    named = []
    for point in points:
        if point.branch in names:
            count[point.branch] = count.get(point.branch, 0) + 1
            named.append((point, f"{point.branch}_pd{count[point.branch]}"))
    return named


def _with_images(named: list[tuple[SpecialPoint, str]], images: dict[int, int],
                 computed: list[Branch], points: list[SpecialPoint]
                 ) -> tuple[list[Branch], list[SpecialPoint]]:
    """The doubled families in the order of their PD points, with their special points: those
    ``computed`` (with their ``points``), and for every mirrored point k the mirror image of
    the family at point ``images[k]`` (with its points' images)."""
    by_name = {b.name: b for b in computed}
    level: list[Branch] = []
    found: list[SpecialPoint] = []
    for k, (point, family) in enumerate(named):
        source = by_name.get(named[images[k]][1] if k in images else family)
        if source is None:
            continue
        branch = source if k not in images else \
            mirrored_branch(source, family, Origin.at(point), source.end)
        level.append(branch)
        found += [p if branch is source else mirrored_point(p, branch)
                  for p in points if p.branch == source.name]
    return level, found


def _start(engine: Engine, name: str, parameter: str, bounds: tuple[float, float],
           numerics: Numerics, branch: Branch, point: SpecialPoint, family: str) -> FamilySide:
    """The doubled family ``family`` to continue from the PD ``point`` on ``branch``."""
    period = 2 * point.period
    constants = periodic_constants(engine.model, numerics, parameter, bounds,
                                   period * engine.model.time_scale)
    constants.update(ISW=-1, STOP=["LP1"])
    label = int(branch.label[point.index])
    spec = RunSpec(f"{name}/{family}.0", constants, BranchKind.PERIODIC, Origin.at(point),
                   (parameter,), restart=(engine.run_with_label(branch.runs, label), label))
    return FamilySide(family, period, spec, [])
