"""Period blow-up at the end of a periodic family: homoclinic or heteroclinic approach.

When the period of a family grows without bound while the parameter converges to p*, the orbit
spends longer and longer near one or more saddle equilibria. From the family's last points and
its last stored orbit profile this module

* tells a blow-up from a family that only changes frequency: the period has grown to the
  family's end (not on a Hopf point: the caller does not ask then) and the longest orbit spends
  at least :data:`LINGER_SHARE` of its period near saddles;
* names the equilibria the orbit lingers near: one saddle -> homoclinic, a +/- pair of saddles
  (symmetric model) -> heteroclinic;
* estimates p* with the saddle scaling law T = C - ln|p - p*| / lambda_u (lambda_u: the saddle's
  unstable eigenvalue, 1/s) and with the simpler fit T = A / |p* - p| + B, each by a scan of p*
  (the other coefficients are linear) over the last points with T > 2 T_ref; or, where the
  parameter turns there (snaking near a saddle-focus; the family is continued until it has
  turned :data:`BRACKET_TURNS` times), brackets p* by the last two turns and estimates it by
  Aitken's delta-squared extrapolation of the last three;
* returns a special point of type HOMOCLINIC or HETEROCLINIC with status "bracketed": the
  estimate, the bracket [last computed value, estimate] and the relative rms fit residual.

T_ref, the reference period, is the period of the family's start: its Hopf point's, or that of
the orbit it was started from.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..models import Model
from ..results import (
    Branch,
    BranchKind,
    LocateStatus,
    Orbit,
    PointType,
    RunStatus,
    SpecialPoint,
)

#: A family is in blow-up when its period exceeds this multiple of the reference period.
BLOWUP_FACTOR = 3.0
#: ... or when AUTO could not continue it (MX) after its period exceeded this multiple, with
#: its orbit lingering near a saddle: near a saddle whose unstable eigenvalue lambda_u is small
#: against the orbit's frequency the period grows only as -ln|p - p*| / lambda_u, and AUTO's
#: tolerances end the family before BLOWUP_FACTOR (the gimballed hub's heteroclinic approach at
#: K_psi = 0.037: lambda_u = 3.2 1/s, MX at 2.5 times the Hopf period, 1e-7 of the range
#: from p*).
STALL_FACTOR = 2.0
#: An orbit lingers near an equilibrium it passes within this fraction of its own size.
LINGER_FRACTION = 0.05
#: ... and a period has blown up only if the orbit spends at least this share of it that near
#: saddles (the share tends to 1 as the period grows without bound; an orbit whose period has
#: grown because the family has reached another, slower mode spends none).
LINGER_SHARE = 0.25
#: The period has grown to the family's end if its last point's is at least this share of the
#: family's longest.
END_SHARE = 0.9


@dataclass(frozen=True)
class BlowupFit:
    """Estimates of the parameter p* where the period becomes infinite."""

    log_estimate: float  # from T = C - ln|p - p*| / lambda_u
    hyperbolic_estimate: float  # from T = A / |p* - p| + B
    residual: float  # relative rms residual of the log fit (NaN for a snaking approach)
    n_points: int
    bracket: tuple[float, float]  # interval holding p*


def in_blowup(family: Branch, reference_period: float, factor: float = BLOWUP_FACTOR) -> bool:
    """True if the family's period has grown beyond ``factor`` times the reference period."""
    periods = family.period[np.isfinite(family.period)]
    return bool(len(periods)) and periods.max() > factor * reference_period


def stalled(family: Branch, reference_period: float) -> bool:
    """True if AUTO could not continue the family (MX) after its period had grown beyond
    STALL_FACTOR times the reference period: a blow-up if its orbit lingers near a saddle."""
    return family.status == RunStatus.MX and in_blowup(family, reference_period, STALL_FACTOR)


#: A family in blow-up is continued (fold by fold) until its parameter has turned this often
#: there: the extremes of a snaking approach alternate around p*, so the last two bracket it.
BRACKET_TURNS = 5


def blowup_turns(parameter: np.ndarray, period: np.ndarray, reference_period: float) -> int:
    """How often the parameter reverses direction where the period exceeds twice the Hopf
    period (the turns of a snaking approach to a global bifurcation)."""
    return len(_turning_rows(parameter, period, reference_period))


def _turning_rows(parameter: np.ndarray, period: np.ndarray, reference_period: float) -> np.ndarray:
    """Rows where the parameter reverses direction, within the blow-up stretch (the last
    stretch with the period above twice the reference period)."""
    stretch = _stretch(period, reference_period)
    p = parameter[stretch]
    steps = np.diff(p)
    moving = np.flatnonzero(steps != 0)
    if len(moving) < 2:
        return np.empty(0, dtype=int)
    signs = np.sign(steps[moving])
    flips = np.flatnonzero(signs[1:] != signs[:-1])
    return stretch.start + moving[flips] + 1


def _stretch(period: np.ndarray, reference_period: float) -> slice:
    """The last stretch of rows with the period above twice the reference period."""
    above = np.isfinite(period) & (period > 2 * reference_period)
    if not above.any():
        return slice(0, 0)
    end = int(np.flatnonzero(above)[-1]) + 1
    start = end
    while start > 0 and above[start - 1]:
        start -= 1
    return slice(start, end)


def _extrapolated(extremes: np.ndarray) -> float:
    """The limit of the alternating, decaying extremes of a snaking approach by Aitken's
    delta-squared (exact for p* + A q^k (-1)^k); NaN if they do not alternate and decay."""
    if len(extremes) < 3:
        return float("nan")
    first, second = np.diff(extremes[-3:])
    if first * second >= 0 or abs(second) >= abs(first):
        return float("nan")
    return float(extremes[-1] - second**2 / (second - first))


def snaking_estimate(extremes: np.ndarray) -> tuple[float, tuple[float, float]]:
    """(p*, (low, high)) of a snaking approach from the parameter at its last turns (at least
    two): bracketed by the last two, estimated by Aitken's delta-squared of the last three
    (:func:`_extrapolated`), or the bracket's middle where that falls outside it."""
    low, high = sorted(float(x) for x in extremes[-2:])
    estimate = _extrapolated(np.asarray(extremes[-3:], dtype=float))
    if not low <= estimate <= high:
        estimate = 0.5 * (low + high)
    return estimate, (low, high)


def _tail(period: np.ndarray, reference_period: float) -> slice:
    """The last at most 15 points of :func:`_stretch`."""
    stretch = _stretch(period, reference_period)
    return slice(max(stretch.start, stretch.stop - 15), stretch.stop)


def _best_distance(p: np.ndarray, t: np.ndarray, basis, side: float, reach: float
                   ) -> tuple[float, float]:
    """(p*, relative rms residual) for T = a * basis(|p* - p|) + b, scanning p* beyond the
    points on ``side``; a and b are solved linearly for every candidate."""
    edge = p.max() if side > 0 else p.min()
    best = (float("nan"), float("inf"))
    for distance in np.geomspace(1e-14, reach, 600):
        star = edge + side * distance
        design = np.column_stack([basis(np.abs(star - p)), np.ones_like(p)])
        coefficients, *_ = np.linalg.lstsq(design / t[:, None], np.ones_like(t), rcond=None)
        residual = float(np.sqrt(np.mean((design @ coefficients / t - 1) ** 2)))
        if residual < best[1] and coefficients[0] > 0:
            best = (float(star), residual)
    return best


def fit_blowup(parameter: np.ndarray, period: np.ndarray, unstable_rate: float | None,
               reference_period: float, width: float) -> BlowupFit | None:
    """Fit the period growth at the end of a family (periods in s, ``unstable_rate`` in 1/s).

    p* is searched within ``0.1 * width`` beyond the fitted points, on either side.
    """
    tail = _tail(period, reference_period)
    p, t = parameter[tail], period[tail]
    if len(p) < 4:
        return None
    turns = _turning_rows(parameter, period, reference_period)
    if len(turns):  # the parameter oscillates: a snaking approach (saddle-focus)
        extremes = parameter[turns]
        if len(extremes) == 1:  # one turn (AUTO stopped early): the last point stands in
            extremes = np.append(extremes, parameter[_stretch(period, reference_period).stop - 1])
        estimate, (low, high) = snaking_estimate(extremes)
        stretch = _stretch(period, reference_period)
        return BlowupFit(estimate, estimate, float("nan"), stretch.stop - stretch.start,
                         (low, high))
    reach = max(2 * np.ptp(p), 1e-9 * width)
    rate = unstable_rate if unstable_rate and unstable_rate > 0 else 1.0

    def logarithmic(d):
        return -np.log(d) / rate

    def hyperbolic(d):
        return 1.0 / d

    side = 1.0 if p[-1] > p[0] else -1.0  # the parameter heads towards p*
    log_star, residual = _best_distance(p, t, logarithmic, side, reach)
    hyper_star, _ = _best_distance(p, t, hyperbolic, side, reach)
    return BlowupFit(log_star, hyper_star, residual, len(p),
                     tuple(sorted((float(p[-1]), log_star))))


def equilibria_at(value: float, equilibria: list[Branch], amplitudes: np.ndarray | float = 1.0
                  ) -> list[np.ndarray]:
    """States (SI) of every computed equilibrium at parameter ``value``, by interpolation;
    states within 1e-6 ``amplitudes`` (each state's typical amplitude) count once."""
    found = []
    for branch in equilibria:
        if branch.kind != BranchKind.EQUILIBRIUM or len(branch) < 2:
            continue
        p = branch.parameters[:, 0]
        for k in np.flatnonzero((p[:-1] - value) * (p[1:] - value) <= 0):
            if p[k + 1] == p[k]:
                continue
            w = (value - p[k]) / (p[k + 1] - p[k])
            state = (1 - w) * branch.state_max[k] + w * branch.state_max[k + 1]
            if not any(np.allclose(state / amplitudes, s / amplitudes, atol=1e-6)
                       for s in found):
                found.append(state)
    return found


def _distances(model: Model, orbit_states: np.ndarray, state: np.ndarray) -> np.ndarray:
    """Distance of each orbit point from ``state`` as a fraction of the orbit's size (AUTO's
    non-dimensional states)."""
    scale = np.asarray(model.state_scale)
    points = orbit_states / scale
    return np.linalg.norm(points - state / scale, axis=1) / np.ptp(points, axis=0).max()


def lingering(model: Model, orbit_states: np.ndarray, candidates: list[np.ndarray]
              ) -> list[np.ndarray]:
    """The candidate equilibria the orbit passes within LINGER_FRACTION of its size."""
    return [state for state in candidates
            if _distances(model, orbit_states, state).min() < LINGER_FRACTION]


def time_share(model: Model, orbit: Orbit, states: list[np.ndarray]) -> float:
    """The share of the orbit's period it spends within LINGER_FRACTION of its size of any of
    ``states``."""
    if not states:
        return 0.0
    near = np.any([_distances(model, orbit.states, s) < LINGER_FRACTION for s in states],
                  axis=0)
    time = np.asarray(orbit.time, dtype=float)
    inside = np.diff(time)[near[:-1] & near[1:]].sum() \
        + 0.5 * np.diff(time)[near[:-1] ^ near[1:]].sum()
    return float(inside / (time[-1] - time[0]))


def grows_to_end(family: Branch) -> bool:
    """True if the family's period has grown to its end (its last point's period is at least
    END_SHARE of its longest)."""
    periods = family.period[np.isfinite(family.period)]
    return bool(len(periods)) and periods[-1] >= END_SHARE * periods.max()


def unstable_rate(model: Model, params: np.ndarray, state: np.ndarray) -> float:
    """Largest real positive eigenvalue of the equilibrium (0 if none), 1/s."""
    eigenvalues = np.linalg.eigvals(model.jacobian_numpy(state, params))
    real = eigenvalues[np.abs(eigenvalues.imag) < 1e-9 * np.maximum(1, np.abs(eigenvalues))]
    return float(max(real.real.max(initial=0.0), 0.0))


def analyse(family: Branch, model: Model, parameters: dict[str, float],
            equilibria: list[Branch], reference_period: float, width: float
            ) -> SpecialPoint | None:
    """The global bifurcation a blowing-up family approaches, as a bracketed special point, or
    None. Blowing up: its period has grown beyond BLOWUP_FACTOR times ``reference_period`` (or
    beyond STALL_FACTOR where AUTO stopped it, :func:`stalled`) and up to its end, and its
    longest orbit spends at least LINGER_SHARE of its period near saddles. A family that ends
    on a Hopf point is none: the caller does not ask."""
    grown = in_blowup(family, reference_period) or stalled(family, reference_period)
    if not grown or not grows_to_end(family) or not family.orbits:
        return None
    name = family.parameter_names[0]
    last = int(np.nanargmax(family.period))
    value = float(family.parameters[last, 0])
    params = model.parameter_vector({**parameters, name: value})
    orbit = max(family.orbits, key=lambda o: o.period)
    amplitudes = np.array(model.typical_amplitudes)
    near = lingering(model, orbit.states, equilibria_at(value, equilibria, amplitudes))
    saddles = [(s, unstable_rate(model, params, s)) for s in near]
    saddles = [(s, rate) for s, rate in saddles if rate > 0]
    share = time_share(model, orbit, [s for s, _ in saddles])
    if share < LINGER_SHARE:
        return None
    if len(saddles) >= 2:
        kind, what = PointType.HETEROCLINIC, "heteroclinic"
    else:
        kind, what = PointType.HOMOCLINIC, "homoclinic"
    rate = max(r for _, r in saddles)
    fit = fit_blowup(family.parameters[:, 0], family.period, rate, reference_period, width)
    estimate = fit.log_estimate if fit else value
    bracket = np.array(fit.bracket if fit else (value, value))
    described = ", ".join("(" + ", ".join(f"{x:.4g}" for x in s[:2]) + ")" for s, _ in saddles)
    note = (f"period blow-up ({what} approach): orbit lingers near saddle(s) {described} "
            f"({share:.0%} of its period); lambda_u = {rate:.4g} 1/s")
    if fit and np.isnan(fit.residual):
        note += (f"; the parameter oscillates (snaking, saddle-focus): p* ~ {estimate:.8g} "
                 f"between the last folds {bracket[0]:.8g} and {bracket[1]:.8g}")
    elif fit:
        note += (f"; p* = {fit.log_estimate:.8g} (T = C - ln|p - p*|/lambda_u), "
                 f"{fit.hyperbolic_estimate:.8g} (T = A/|p* - p| + B); "
                 f"relative rms residual {fit.residual:.2g} over {fit.n_points} points")
    return SpecialPoint(
        branch=family.name, index=last, point_type=int(kind),
        parameter_names=family.parameter_names, parameters=np.array([estimate]),
        parameter_units=family.parameter_units,
        state=np.asarray(saddles[0][0], dtype=float), period=float(family.period[last]),
        stable=False, status=LocateStatus.BRACKETED, note=note, bracket=bracket,
        residual=fit.residual if fit else float("nan"))
