"""Families of cycles branching off at branch points of cycles (BPC): from every BPC of a
periodic family, AUTO's branch switching (ISW=-1 at the BPC label) onto the family that
crosses it there, continued fold by fold (:mod:`.periodic`) until it is back at a branch
point of cycles of the family it left (its start, or another: at a pitchfork of a symmetric
model's symmetric cycles the asymmetric family often joins two of them).

A branch point a switched family reached is not switched at again (its family is that one),
nor one in its family's period blow-up (a period over BLOWUP_FACTOR times the family's
shortest: a family snaking towards a homoclinic orbit has many, on families that snake too).
Of a symmetric model, a family leaving a symmetric cycle (its orbit its own mirror image:
a symmetry-breaking pitchfork) has a mirror image, the other side of the pitchfork: mapped
(:mod:`.mirror`, branch ``<family>m``), not computed.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..analysis.global_bifurcations import BLOWUP_FACTOR
from ..models import Model
from ..results import Branch, BranchKind, LocateStatus, Origin, PointType, SpecialPoint
from .branches import head
from .engine import Engine, Numerics, RunSpec
from .mirror import is_odd, mirrored_branch, mirrored_point
from .periodic import FamilySide, collect, continue_families, end_of, periodic_constants

#: A point of a switched family is at a branch point of cycles if it agrees with it to this
#: fraction of the range in the parameter, relatively in the period and in AUTO's units
#: (relatively or absolutely) in the orbit's maxima and minima.
AT_BRANCH_POINT = 1e-3


def at_branch_point(branch: Branch, row: int, point: SpecialPoint, source: Branch,
                    width: float, scale: np.ndarray) -> bool:
    """True if the orbit at ``row`` of ``branch`` is the orbit at the branch point ``point``
    of family ``source`` (``scale``: the model's state scale)."""
    k = point.index
    return bool(abs(branch.parameters[row, 0] - point.parameters[0]) <= AT_BRANCH_POINT * width
                and abs(branch.period[row] - point.period) <= AT_BRANCH_POINT * point.period
                and np.allclose(branch.state_max[row] / scale, source.state_max[k] / scale,
                                rtol=AT_BRANCH_POINT, atol=AT_BRANCH_POINT)
                and np.allclose(branch.state_min[row] / scale, source.state_min[k] / scale,
                                rtol=AT_BRANCH_POINT, atol=AT_BRANCH_POINT))


def symmetric_orbit(branch: Branch, row: int, scale: np.ndarray) -> bool:
    """True if the orbit at ``row`` is its own mirror image (maxima the negated minima)."""
    return bool(np.allclose(branch.state_max[row] / scale, -branch.state_min[row] / scale,
                            rtol=AT_BRANCH_POINT, atol=AT_BRANCH_POINT))


def switched_families(engine: Engine, name: str, parameter: str, bounds: tuple[float, float],
                      numerics: Numerics, families: list[Branch], points: list[SpecialPoint],
                      equilibria: list[Branch], parameters: dict[str, float]
                      ) -> tuple[list[Branch], list[SpecialPoint]]:
    """The family switched onto at every BPC of ``families`` (branch ``<family>_bp<k>``, k
    counting that family's BPC points), with its special points, and its mirror image where
    it breaks a symmetric cycle's symmetry. ``points``: the special points found so far (the
    equilibria's Hopf points end a family that shrinks onto one)."""
    model = engine.model
    width = bounds[1] - bounds[0]
    scale = np.asarray(model.state_scale, dtype=float)
    hopfs = [p for p in points if p.point_type == PointType.HB]
    kept: list[Branch] = []
    found: list[SpecialPoint] = []
    sources = _sources(families)
    for family in families:
        if family.name in sources:
            continue
        branch_points = [p for p in points if p.branch == family.name
                         and p.point_type == PointType.BPC
                         and p.status != LocateStatus.REJECTED]
        reached: set[int] = set()
        shortest = float(np.nanmin(family.period)) if len(family) else np.inf
        for k, point in enumerate(branch_points, 1):
            if k - 1 in reached or point.period > BLOWUP_FACTOR * shortest:
                continue  # reached from another, or in the family's period blow-up
            side = _start(engine, name, parameter, bounds, numerics, family, point,
                          f"{family.name}_bp{k}", tuple(branch_points))
            continue_families(engine, [side], hopfs, width)
            ended = end_of(side, model, hopfs, bounds, numerics, equilibria, parameters)
            switched = _cut(ended.branch, family, branch_points, width, scale)
            reached |= {j for j, other in enumerate(branch_points)
                        if any(at_branch_point(switched, row, other, family, width, scale)
                               for row in range(len(switched)))}
            if not _left(switched, family, width, scale):
                continue  # the switch failed: AUTO went on along the family itself
            branches, new = collect(engine, name, bounds, parameters, hopfs,
                                    [(switched, ended.blowups() if switched is ended.branch
                                      else [])], skip_first=True)
            switched = branches[0]
            new = [p for p in new if p.index < len(switched) - 1
                   or p.point_type != PointType.BPC]  # its end: the family's own BPC
            kept.append(switched)
            found += new
            if _breaks_symmetry(model, family, point, parameters, scale):
                image = mirrored_branch(switched, f"{switched.name}m", switched.origin,
                                        switched.end)
                kept.append(image)
                found += [mirrored_point(p, image) for p in new]
    for family in families:  # a mapped family's switched families: its source's, mapped
        if family.name in sources:
            prefix = f"{sources[family.name]}_bp"
            for branch in [b for b in kept if b.name.startswith(prefix)]:
                image = mirrored_branch(branch, family.name + branch.name[len(prefix) - 3:],
                                        replace(branch.origin, branch=family.name), branch.end)
                kept.append(image)
                found += [mirrored_point(p, image) for p in found if p.branch == branch.name]
    return kept, found


def _sources(families: list[Branch]) -> dict[str, str]:
    """{name: source name} of every one of ``families`` mapped from an earlier one (holding
    its runs: a restart from one of their labels would give the source's orbit)."""
    return {b.name: a.name for k, b in enumerate(families) for a in families[:k][::-1]
            if b.runs == a.runs}


def _cut(branch: Branch, family: Branch, branch_points: list[SpecialPoint], width: float,
         scale: np.ndarray) -> Branch:
    """``branch`` up to the first row, once it has left its start, at one of ``family``'s
    ``branch_points`` (AUTO passes through a pitchfork's other end without stopping)."""
    away = [row for row in range(1, len(branch))
            if not at_branch_point(branch, row, _point_at(branch, 0), branch, width, scale)]
    for row in range(away[0] if away else len(branch), len(branch)):
        for other in branch_points:
            if at_branch_point(branch, row, other, family, width, scale):
                end = (f"back on {family.name} at its BPC at {branch.parameter_names[0]} = "
                       f"{other.parameters[0]:.6g}")
                return replace(head(branch, row + 1), end=end) if row + 1 < len(branch) \
                    else replace(branch, end=end)
    return branch


def _point_at(branch: Branch, row: int) -> SpecialPoint:
    """A point standing for the orbit at ``row`` of ``branch``."""
    return SpecialPoint(branch.name, row, 0, branch.parameter_names, branch.parameters[row],
                        branch.state_max[row], float(branch.period[row]), False)


#: A switched family that lies on the family it left, to this relative tolerance, at this
#: share of its points is that family continued again (a failed switch).
ON_FAMILY, ON_SHARE = 1e-2, 0.9


def _left(switched: Branch, family: Branch, width: float, scale: np.ndarray) -> bool:
    """True if ``switched`` leaves ``family`` (a failed switch goes on along the family)."""
    if len(switched) < 3:
        return False
    on = [_on(switched, row, family, width, scale) for row in range(len(switched))]
    return sum(on) < ON_SHARE * len(switched)


def _on(branch: Branch, row: int, family: Branch, width: float, scale: np.ndarray) -> bool:
    """True if the orbit at ``row`` of ``branch`` lies on ``family`` (between two of its
    neighbouring points, linearly interpolated, to :data:`ON_FAMILY`)."""
    x = branch.parameters[row, 0]
    mine = np.concatenate([[branch.period[row]], branch.state_max[row] / scale,
                           branch.state_min[row] / scale])
    xs = family.parameters[:, 0]
    inside = (np.minimum(xs[:-1], xs[1:]) <= x) & (x <= np.maximum(xs[:-1], xs[1:]))
    for k in np.flatnonzero(inside):
        w = 0.0 if xs[k + 1] == xs[k] else (x - xs[k]) / (xs[k + 1] - xs[k])
        theirs = [np.concatenate([[family.period[j]], family.state_max[j] / scale,
                                  family.state_min[j] / scale]) for j in (k, k + 1)]
        if np.allclose(mine, (1 - w) * theirs[0] + w * theirs[1], rtol=ON_FAMILY,
                       atol=ON_FAMILY):
            return True
    return False


def _breaks_symmetry(model: Model, family: Branch, point: SpecialPoint,
                     parameters: dict[str, float], scale: np.ndarray) -> bool:
    """True if ``point`` is a symmetric cycle of a symmetric model (its branch point a
    symmetry-breaking pitchfork, whose two sides are each other's mirror images)."""
    if not model.symmetric or not symmetric_orbit(family, point.index, scale):
        return False
    values = model.parameter_vector({**parameters,
                                     point.parameter_names[0]: float(point.parameters[0])})
    return is_odd(model, values, [point.state])


def _start(engine: Engine, name: str, parameter: str, bounds: tuple[float, float],
           numerics: Numerics, family: Branch, point: SpecialPoint, switched: str,
           branch_points: tuple[SpecialPoint, ...]) -> FamilySide:
    """The family ``switched`` to continue from the BPC ``point`` on ``family``, ending back
    at one of its ``branch_points``."""
    constants = periodic_constants(engine.model, numerics, parameter, bounds,
                                   point.period * engine.model.time_scale)
    constants.update(ISW=-1, STOP=["LP1"])
    label = int(family.label[point.index])
    spec = RunSpec(f"{name}/{switched}.0", constants, BranchKind.PERIODIC, Origin.at(point),
                   (parameter,), restart=(engine.run_with_label(family.runs, label), label))
    width = bounds[1] - bounds[0]
    scale = np.asarray(engine.model.state_scale, dtype=float)

    def back(piece: Branch, row: int) -> str:
        """The end at ``row`` of ``piece``: back at a branch point of the family, or a
        piece that only retraces the family (a failed switch: no use going on)."""
        for other in branch_points:
            if at_branch_point(piece, row, other, family, width, scale):
                return (f"back on {family.name} at its BPC at {parameter} = "
                        f"{other.parameters[0]:.6g}")
        return f"retraces {family.name}" if len(piece) >= 3 and not _left(
            piece, family, width, scale) else ""

    return FamilySide(switched, point.period, spec, [], stop=back)
