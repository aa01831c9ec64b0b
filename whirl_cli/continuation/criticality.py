"""Criticality of Hopf points: a provisional one from the first Lyapunov coefficient
(:mod:`whirl_cli.analysis.normal_form`), then the side the periodic family lies on, which has
the last word.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..analysis.normal_form import criticality_of, hopf_lyapunov_coefficient
from ..models import Model
from ..results import Branch, Criticality, LocateStatus, Origin, PointType, SpecialPoint
from .branches import joined_notes
from .periodic import hopf_at


def with_criticality(points: list[SpecialPoint], families: list[Branch],
                      branches: list[Branch], width: float, scale: np.ndarray
                      ) -> list[SpecialPoint]:
    """Hopf points labelled supercritical or subcritical from the periodic family at them:
    supercritical when the family lies on the side where the Hopf pair is unstable."""
    equilibria = {b.name: b for b in branches}
    hopfs = [p for p in points if p.point_type == PointType.HB]
    sides: dict[int, float] = {}
    for family in families:
        if len(family) < 3:
            continue
        for row, step in ((0, 1), (len(family) - 1, -1)):
            k = hopf_at(family, row, hopfs, width, scale) if row else next(
                (i for i, h in enumerate(hopfs) if family.origin == Origin.at(h)), None)
            if k is not None and k not in sides:
                sides[k] = _side(family.parameters[::step, 0], hopfs[k].parameters[0], width)
    labelled = []
    for point in points:
        if point.point_type == PointType.HB:
            k = next(i for i, h in enumerate(hopfs) if h is point)
            growth = _hopf_growth_direction(equilibria[point.branch], point)
            side = sides.get(k, 0.0)
            if side and growth:
                from_family = (Criticality.SUPERCRITICAL if side == growth
                               else Criticality.SUBCRITICAL)
                if point.criticality and point.criticality != from_family:
                    point = replace(point, note=joined_notes(
                        point.note, f"first Lyapunov coefficient says {point.criticality}"))
                point = replace(point, criticality=from_family)
        labelled.append(point)
    return labelled


#: A family has left its Hopf point's parameter value once it is this fraction of the range
#: away: a family that grows at a fixed value first (a Hopf point of an equilibrium where the
#: right-hand side is locally linear, e.g. just outside a freeplay gap) lies on the side it
#: then turns to.
SIDE_MARGIN = 1e-4


def _side(values: np.ndarray, hopf: float, width: float) -> float:
    """The side of ``hopf`` (-1, +1) the family's parameter ``values`` (from its Hopf end)
    first leave it to by SIDE_MARGIN of ``width``; 0 if they never do."""
    away = np.flatnonzero(np.abs(values - hopf) > SIDE_MARGIN * width)
    return float(np.sign(values[away[0]] - hopf)) if len(away) else 0.0


def with_lyapunov(model: Model, parameter: str, parameters: dict[str, float],
                  points: list[SpecialPoint]) -> list[SpecialPoint]:
    """Hopf points of equilibria with their first Lyapunov coefficient and, from its sign, a
    provisional criticality (a periodic family, when computed, has the last word: see
    :func:`with_criticality`)."""
    labelled = []
    for point in points:
        if point.point_type == PointType.HB:
            values = model.parameter_vector({**parameters, parameter: point.parameters[0]})
            try:
                l1 = hopf_lyapunov_coefficient(model, point.state, values)
            except (ValueError, np.linalg.LinAlgError):
                l1 = float("nan")
            point = replace(point, lyapunov=l1,
                            criticality=criticality_of(l1, 2 * np.pi / point.period))
        labelled.append(point)
    return labelled


def _hopf_growth_direction(branch: Branch, hopf: SpecialPoint) -> float:
    """Sign of d(Re lambda)/dp of the critical pair at a Hopf point, from the eigenvalues AUTO
    printed at the neighbouring points of the equilibrium branch; 0 (unknown) where AUTO
    printed none there."""
    k = hopf.index
    if k == 0 or k + 1 >= len(branch):
        return 0.0
    omega = 2 * np.pi / hopf.period

    def critical(row: int) -> float:
        values = branch.eigenvalues[row]
        return float(values[np.argmin(np.abs(np.abs(values.imag) - omega))].real)

    slope = (critical(k + 1) - critical(k - 1)) / (branch.parameters[k + 1, 0]
                                                   - branch.parameters[k - 1, 0])
    return float(np.sign(slope)) if np.isfinite(slope) else 0.0



def locus_lyapunov(model: Model, locus: Branch, row: int, pair: tuple[str, str],
                   parameters: dict[str, float]) -> Criticality:
    """The criticality the first Lyapunov coefficient gives at ``row`` of a Hopf ``locus``
    in the parameter ``pair`` (unknown where it vanishes to round-off or cannot be
    computed)."""
    values = model.parameter_vector({**parameters, pair[0]: float(locus.parameters[row, 0]),
                                     pair[1]: float(locus.parameters[row, 1])})
    try:
        l1 = hopf_lyapunov_coefficient(model, locus.state_max[row], values)
    except (ValueError, np.linalg.LinAlgError):
        l1 = float("nan")
    return criticality_of(l1, 2 * np.pi / float(locus.period[row]))


def bautin_verdict(*sides: Criticality) -> str:
    """Why a GH (Bautin) point is not one, given the verdicts of the first Lyapunov
    coefficient at the locus rows beside it (two, or one at an end of the locus); "" if it
    may be (the sign changes, or one side is unknown while the other is not, or one side
    only and l1 does not vanish there)."""
    if all(side == Criticality.UNKNOWN for side in sides):
        where = "on both sides" if len(sides) > 1 else "beside it"
        return (f"the first Lyapunov coefficient vanishes {where} (identically zero "
                "without a nonlinear term at the equilibrium): every Hopf point here is "
                "degenerate, not a Bautin point")
    if len(sides) > 1 and len(set(sides)) == 1:
        return (f"the first Lyapunov coefficient does not change sign ({sides[0]} on both "
                "sides): not a Bautin point")
    return ""


def with_bautin_verdict(model: Model, locus: Branch, point: SpecialPoint,
                        pair: tuple[str, str], parameters: dict[str, float]) -> SpecialPoint:
    """A GH point of a Hopf ``locus`` rejected, with a note saying why (:func:`bautin_verdict`
    of the first Lyapunov coefficient at the locus's rows beside it), unless it changes
    sign there."""
    rows = [row for row in (point.index - 1, point.index + 1) if 0 <= row < len(locus)]
    if point.point_type != PointType.GH or not rows:
        return point
    note = bautin_verdict(*(locus_lyapunov(model, locus, row, pair, parameters)
                            for row in rows))
    if not note:
        return point
    return replace(point, status=LocateStatus.REJECTED, note=joined_notes(point.note, note))
