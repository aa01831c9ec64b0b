"""Operations on branches: their first rows, two runs joined into one, the orbit amplitude, the
special points on them; and notes joined (shared by the recipes).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..models import Model
from ..results import Branch, LocateStatus, PointType, SpecialPoint

#: The per-point columns of a :class:`Branch` (one row per point); ``torus_angle`` is one
#: only on torus loci (None elsewhere).
COLUMNS = ("parameters", "state_max", "state_min", "l2_norm", "period", "stable", "point_type",
           "label", "eigenvalues", "stability_known", "torus_angle")


def _columns(*branches: Branch) -> tuple[str, ...]:
    """The :data:`COLUMNS` every one of ``branches`` holds (not None)."""
    return tuple(key for key in COLUMNS if all(getattr(b, key) is not None for b in branches))


def head(branch: Branch, rows: int) -> Branch:
    """The first ``rows`` points of ``branch`` (with the orbits stored on them)."""
    return replace(branch, **{key: getattr(branch, key)[:rows] for key in _columns(branch)},
                   orbits=tuple(o for o in branch.orbits if o.index < rows))


def reverse(branch: Branch) -> Branch:
    """``branch`` with its points in the opposite order (its orbits re-indexed)."""
    last = len(branch) - 1
    return replace(branch, **{key: getattr(branch, key)[::-1] for key in _columns(branch)},
                   orbits=tuple(replace(o, index=last - o.index) for o in branch.orbits[::-1]))


def join(first: Branch, second: Branch, name: str) -> Branch:
    """One branch from two consecutive runs (the second restarted at the first's last point,
    which it repeats); it ends as the second does. A column only one of them holds (a torus
    angle) is dropped."""
    shift = len(first)
    stacked = {key: np.concatenate([getattr(first, key), getattr(second, key)[1:]])
               for key in _columns(first, second)}
    stacked.update({key: None for key in ("torus_angle",) if key not in stacked})
    moved = tuple(replace(o, index=o.index + shift - 1) for o in second.orbits if o.index > 0)
    return replace(first, name=name, status=second.status, message=second.message,
                   end=second.end, runs=first.runs + second.runs,
                   orbits=first.orbits + moved, **stacked)


def amplitude(branch: Branch, model: Model) -> np.ndarray:
    """(N,) the largest half peak-to-peak value of any state over each orbit, in AUTO's
    non-dimensional units (the PVLS ``amplitude`` output); 0 on equilibria."""
    scale = np.asarray(model.state_scale, dtype=float)
    return ((branch.state_max - branch.state_min) / (2 * scale)).max(axis=1)


def special_points(branch: Branch, skip_first: bool = False) -> list[SpecialPoint]:
    """The bifurcations on ``branch`` (HB, BP, LP, LPC, PD, TR, codim-2 ...)."""
    found = []
    for index in range(len(branch)):
        kind = PointType(int(branch.point_type[index]))
        if not kind.is_special or (skip_first and index == 0):
            continue
        found.append(SpecialPoint(
            branch=branch.name, index=index, point_type=int(kind),
            parameter_names=branch.parameter_names, parameters=branch.parameters[index].copy(),
            parameter_units=branch.parameter_units,
            state=branch.state_max[index].copy(), period=float(branch.period[index]),
            stable=bool(branch.stable[index]), label=int(branch.label[index]),
            **_verdict(branch, index, kind)))
    return found


def _verdict(branch: Branch, index: int, kind: PointType) -> dict:
    """What the Floquet multipliers say of a point of a periodic ``branch`` AUTO labelled
    as a torus point or a branch point of cycles (fields of its :class:`SpecialPoint`)."""
    if not branch.is_periodic:
        return {}
    if kind == PointType.TR:
        return _torus(branch, index)
    if kind == PointType.BPC:
        return _branch_point_of_cycles(branch, index)
    return {}


#: How far from the unit circle (in modulus) the multiplier pair of a torus point may be, and
#: the second multiplier of a branch point of cycles from +1.
TORUS_TOLERANCE = 0.05


def neimark_sacker_angle(multipliers: np.ndarray) -> float:
    """The angle in (0, pi) rad of the complex conjugate pair of Floquet ``multipliers`` on
    the unit circle, exp(+-i angle), at a torus (Neimark-Sacker) point; NaN if no complex
    pair lies within :data:`TORUS_TOLERANCE` of it (or the multipliers are unknown). A second
    frequency of the torus is angle / (2 pi T) for a cycle of period T."""
    values = np.asarray(multipliers, dtype=complex)
    upper = values[np.isfinite(values) & (values.imag > 1e-9 * np.maximum(1, abs(values)))]
    if not upper.size:
        return float("nan")
    nearest = upper[np.argmin(np.abs(np.abs(upper) - 1.0))]
    if abs(abs(nearest) - 1.0) > TORUS_TOLERANCE:
        return float("nan")
    return float(np.angle(nearest))


def _torus(branch: Branch, index: int) -> dict:
    """A TR point's ``torus_angle``; if its multipliers (known) have no pair on the unit
    circle, the status rejected and a ``note`` saying why."""
    multipliers = branch.eigenvalues[index]
    angle = neimark_sacker_angle(multipliers)
    if not np.isfinite(multipliers).any() or np.isfinite(angle):
        return {"torus_angle": angle}
    return {"torus_angle": angle, "status": LocateStatus.REJECTED,
            "note": "no complex pair of Floquet multipliers on the unit circle: AUTO's torus "
                    "test function changed sign without a Neimark-Sacker pair (not a torus "
                    "bifurcation)"}


def _branch_point_of_cycles(branch: Branch, index: int) -> dict:
    """A BPC point's status rejected and a ``note`` if its multipliers (known) have a single
    one within :data:`TORUS_TOLERANCE` of +1: at a branch point of cycles a second real
    multiplier passes through +1 beside the cycle's trivial one."""
    multipliers = branch.eigenvalues[index]
    known = multipliers[np.isfinite(multipliers)]
    if not known.size or np.sum(np.abs(known - 1.0) <= TORUS_TOLERANCE) >= 2:
        return {}
    return {"status": LocateStatus.REJECTED,
            "note": "a single Floquet multiplier at +1 (the cycle's own): AUTO's branch-point "
                    "test function changed sign without a second one passing +1 (no family "
                    "of cycles crosses here)"}


def last_good_label(branch: Branch, before: int | None = None) -> int | None:
    """The last row (before row ``before``, if given) of ``branch`` with a label that is no
    MX point: where a run that failed can be restarted from; None if there is none."""
    rows = [k for k in np.flatnonzero(branch.label[:before])
            if branch.point_type[k] != PointType.MX]
    return int(rows[-1]) if rows else None


def typical_amplitudes(model: Model) -> np.ndarray:
    """(n,) :attr:`~whirl_cli.models.Model.typical_amplitudes` (rad for the classical
    model, where it is 1)."""
    return np.array(model.typical_amplitudes, dtype=float)


def same_point(a: SpecialPoint, b: SpecialPoint, width: float,
                amplitudes: np.ndarray) -> bool:
    """Within 1e-5 of the range in the parameter and 1e-5 typical amplitudes (``amplitudes``:
    :func:`typical_amplitudes`) or 1e-4 relative in every state."""
    return (abs(a.parameters[0] - b.parameters[0]) <= 1e-5 * width
            and np.allclose(a.state / amplitudes, b.state / amplitudes, atol=1e-5, rtol=1e-4))


def joined_notes(*notes: str) -> str:
    """The non-empty notes, joined by ``; ``."""
    return "; ".join(n for n in notes if n)

