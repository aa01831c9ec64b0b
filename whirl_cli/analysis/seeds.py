"""Limit cycles not born at a Hopf point, found from simulation.

A seed is an initial state. :func:`settle` simulates it (LSODA on the model's smoothed
right-hand side) in chunks of :data:`CHUNK_PERIODS` reference periods and judges, after each,
what the motion does on its return map: the points where the dof that moves most (in typical
amplitudes) crosses the mean of its recent motion upwards, located on a cubic through the
samples (:func:`whirl_cli.analysis.motion.poincare_section`), every dof (and first-order
state) there in units of its size in the recent motion (at least 1e-2 of the largest, in
typical amplitudes: a dof that hardly moves is not judged on its round-off).

* "periodic": for the smallest lag k <= 8 (a cycle that crosses the section k times a
  period) the returns k apart, and the times between them, agree to ``tolerance`` over the
  last half of the chunk (:func:`judge`); the orbit is the motion over the last k returns,
  for AUTO to start from (see
  :func:`whirl_cli.continuation.periodic.orbit_families`);
* "equilibrium": every dof has stopped moving (peak to peak below ``tolerance`` of the seed);
* "diverged": a dof has left ``limit`` typical amplitudes;
* "unsettled": none of these. The return map's distances are followed as the motion goes on:
  while they shrink steadily (a cycle approached) the simulation goes on past ``max_periods``
  periods of the slowest oscillatory linear mode (:func:`reference_period`), up to
  :data:`OVERRUN` times that, as long as their rate says the tolerance is reached within it;
  the message says what the map did (shrinking at a rate too slow, or not converging).

Rates are not judged: the fast content of a stiff mode (a gimbal's) makes their values at the
section noisier than the motion's repetition, while the dofs at the section fix the orbit.

:func:`auto_seeds` makes the seeds of ``seeds: auto``; :func:`distinct` keeps one of the seeds
that settle on the same orbit. Time in s, states in SI units.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kinds import SeedKind
from ..models import Model
from ..results import Orbit
from ..units import display_unit
from .motion import poincare_section, section_geometry
from .simulate import integrate

#: Samples per reference period in the simulation (and the rows of a settled orbit + 1).
SAMPLES_PER_PERIOD = 200
ORBIT_ROWS = 801
#: Simulated in chunks of this many reference periods, ``max_periods`` in all unless the
#: return map converges (then up to OVERRUN times as many).
CHUNK_PERIODS = 50
OVERRUN = 4


@dataclass(frozen=True)
class Settled:
    """What a seed settled on: ``kind`` (periodic | equilibrium | diverged | unsettled),
    ``orbit`` (one period, periodic only), ``state`` (the last simulated state) and
    ``message`` (what was seen, e.g. the period and the return mismatch)."""

    kind: SeedKind
    seed: np.ndarray
    state: np.ndarray
    orbit: Orbit | None
    message: str


def reference_period(model: Model, params: np.ndarray) -> float:
    """2 pi / the lowest frequency of the oscillatory linear modes at the origin (s): the time
    scale of a seed's motion (the model's time scale where no mode oscillates). Not the
    fastest mode: a stiff one (a rigid gimbal's, 1.7e5 rad/s at K_beta = 1e6) would make the
    settling budget of :func:`settle` a fraction of one whirl period."""
    eigenvalues = np.linalg.eigvals(model.jacobian_numpy(np.zeros(model.n_states), params))
    oscillating = eigenvalues[eigenvalues.imag > 1e-9 * np.abs(eigenvalues).max()]
    if not oscillating.size:
        return 2 * np.pi / model.time_scale
    return 2 * np.pi / float(oscillating.imag.min())


def settle(model: Model, params: np.ndarray, seed: np.ndarray, max_periods: int = 600,
           tolerance: float = 1e-4, limit: float = 10.0) -> Settled:
    """Simulate ``seed`` until it settles (see the module doc); ``limit``: divergence bound
    in typical amplitudes of each dof (and first-order state)."""
    seed = np.asarray(seed, dtype=float)
    period = reference_period(model, params)
    dofs = list(model.positions)
    amplitudes = np.array(model.typical_amplitudes, dtype=float)[dofs]
    state, elapsed, budget = seed.copy(), 0.0, max_periods * period
    judged = Judged(0, np.nan, np.nan, 0.0)
    while elapsed < budget:
        t, y = integrate(model, params, state, CHUNK_PERIODS * period,
                         samples=CHUNK_PERIODS * SAMPLES_PER_PERIOD + 1)
        elapsed += t[-1]
        if not np.isfinite(y).all() or (np.abs(y[:, dofs]) > limit * amplitudes).any():
            return Settled(SeedKind.DIVERGED, seed, y[-1], None,
                           f"a dof beyond {limit:g} typical amplitudes after {elapsed:.3g} s")
        state = y[-1]
        recent = y[-10 * SAMPLES_PER_PERIOD:]
        size = np.ptp(recent[:, dofs], axis=0) / amplitudes
        if size.max() < tolerance * max(np.abs(seed[dofs] / amplitudes).max(), 1e-12):
            return Settled(SeedKind.EQUILIBRIUM, seed, state, None,
                           f"at rest after {elapsed:.3g} s")
        times, points = returns(t, y, dofs, amplitudes)
        judged = judge(times, points, tolerance)
        if judged.lag:
            orbit = _orbit(t, y, *_one_period(t, y, times[-1] - times[-1 - judged.lag]))
            crossings = f", {judged.lag} returns a period" if judged.lag > 1 else ""
            return Settled(SeedKind.PERIODIC, seed, state, orbit,
                           f"period {orbit.period:.6g} s{crossings}, returns repeat to "
                           f"{judged.distance:.1e} of the motion's size after {elapsed:.3g} s")
        if elapsed >= budget and elapsed + judged.needed(tolerance) <= \
                OVERRUN * max_periods * period:
            budget = elapsed + judged.needed(tolerance)
    return Settled(SeedKind.UNSETTLED, seed, state, None, judged.why(tolerance, elapsed, period))


@dataclass(frozen=True)
class Judged:
    """What a return map did (:func:`judge`): ``lag`` the returns a period of the cycle it
    repeats (0: none), ``distance`` the largest distance between returns that far apart over
    the last half of them (lag 1 where none repeats; units of the dofs' sizes), ``rate`` the
    factor by which those distances shrink per return where they shrink steadily (NaN where
    they do not) and ``step`` the mean time between returns (s)."""

    lag: int
    distance: float
    rate: float
    step: float

    def needed(self, tolerance: float) -> float:
        """Seconds more until the distances reach ``tolerance`` at their rate (inf if they
        do not shrink steadily)."""
        if not 0 < self.rate < 1 or not self.distance > 0:
            return np.inf
        return max(np.log(tolerance / self.distance) / np.log(self.rate), 1.0) * self.step

    def why(self, tolerance: float, elapsed: float, period: float) -> str:
        """Why the motion counts as unsettled after ``elapsed`` s."""
        spent = f"within {elapsed / period:.0f} periods ({elapsed:.3g} s)"
        if not np.isfinite(self.distance):
            return f"no repeating motion {spent}: too few returns to its section"
        if np.isfinite(self.needed(tolerance)):
            return (f"no repeating motion {spent}: its returns converge too slowly (their "
                    f"distance {self.distance:.1e} of the motion's size shrinks by "
                    f"{self.rate:.4g} a return; about {self.needed(tolerance):.3g} s more)")
        return (f"no repeating motion {spent}: its returns stay {self.distance:.1e} of the "
                "motion's size apart and do not converge")


def returns(t: np.ndarray, y: np.ndarray, dofs: list[int], amplitudes: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
    """(times (m,), points (m, len(dofs))): the return map of a simulation, where the dof that
    moves most in typical ``amplitudes`` crosses the mean of the last half of its motion
    upwards, the ``dofs`` there in units of their size over that half (at least 1e-2 of the
    largest, in typical amplitudes)."""
    late = y[len(y) // 2:, dofs]
    size = np.ptp(late, axis=0) / amplitudes
    index = dofs[int(np.argmax(size))]
    times, points = poincare_section(t, y, index, late[:, dofs.index(index)].mean())
    scale = np.maximum(size, 1e-2 * size.max()) * amplitudes
    return times, points[:, dofs] / np.maximum(scale, 1e-300)


def judge(times: np.ndarray, points: np.ndarray, tolerance: float) -> Judged:
    """The return map ``points`` (at ``times``; :func:`returns`) judged: a cycle repeats with
    lag k where :func:`whirl_cli.analysis.motion.section_geometry` finds its points repeating
    to ``tolerance`` over the last half of them, and the times between returns k apart agree
    to ``tolerance`` too; otherwise the steady rate at which its lag distances shrink."""
    if len(points) < 4:
        return Judged(0, np.nan, np.nan, 0.0)
    lag, _, distance, converging, rate = section_geometry(points, np.ones(points.shape[1]),
                                                          tolerance)
    step = float(np.mean(np.diff(times)))
    if lag:
        spans = (times[lag:] - times[:-lag])[(len(times) - lag) // 2:]
        if np.ptp(spans) <= tolerance * spans.mean():
            return Judged(lag, float(distance), np.nan, step)
    if converging:
        lags = np.max(np.abs(points[converging:] - points[:-converging]), axis=1)
        return Judged(0, float(lags[-1]), rate, step)
    return Judged(0, float(distance), np.nan, step)


def _one_period(t: np.ndarray, y: np.ndarray, period: float) -> tuple[float, float]:
    """(begin, end) of the orbit handed to AUTO: the last upward crossing of the first state
    through its mean over the last half, and the crossing nearest one ``period`` before it
    (both linearly interpolated): a fixed phase whatever dof the return map watches (AUTO's
    continuation from the orbit, its first steps, depends on where the orbit starts)."""
    x = y[:, 0] - y[len(y) // 2:, 0].mean()
    up = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    share = -x[up] / (x[up + 1] - x[up])
    crossings = t[up] + share * (t[up + 1] - t[up])
    if len(crossings) < 2:
        return float(t[-1] - period), float(t[-1])
    end = float(crossings[-1])
    return float(crossings[np.argmin(np.abs(crossings - (end - period)))]), end


def _orbit(t: np.ndarray, y: np.ndarray, begin: float, end: float) -> Orbit:
    """The simulated motion from ``begin`` to ``end`` (s) on :data:`ORBIT_ROWS` rows."""
    grid = np.linspace(begin, end, ORBIT_ROWS)
    states = np.column_stack([np.interp(grid, t, y[:, k]) for k in range(y.shape[1])])
    return Orbit(label=0, point_type=0, index=0, parameters=np.empty(0),
                 period=float(end - begin), time=grid - begin, states=states)


def auto_seeds(model: Model, values: dict[str, float]) -> list[np.ndarray]:
    """The seeds of ``seeds: auto``: each nonlinear dof displaced alone, at 2, 4 and 8 times
    its law's size (the outermost breakpoint of a piecewise law, e.g. freeplay's delta), or at
    0.05, 0.2 and 0.5 typical amplitudes for a smooth law; both signs unless the model is
    symmetric."""
    seeds = []
    signs = (1.0,) if model.symmetric else (1.0, -1.0)
    for k, (dof, law) in enumerate(zip(model.dofs, model.law_objects, strict=True)):
        if law.is_linear(model.law_values(dof.name, values)):
            continue
        if law.breakpoints is not None:
            size = max(abs(b) for b in model.breakpoints(k, values))
            offsets = (2 * size, 4 * size, 8 * size)
        else:
            offsets = tuple(f * dof.amplitude for f in (0.05, 0.2, 0.5))
        for sign in signs:
            for offset in offsets:
                seed = np.zeros(model.n_states)
                seed[k] = sign * offset
                seeds.append(seed)
    return seeds


def seed_state(model: Model, given: dict[str, float]) -> np.ndarray:
    """A seed as a study writes it (state name -> value, angles in deg and rates in deg/s,
    other states in their unit; unnamed states 0) as an SI state."""
    state = np.zeros(model.n_states)
    for k, s in enumerate(model.states):
        if s.name in given:
            factor, _ = display_unit(s.unit)
            state[k] = given[s.name] / factor
    return state


def distinct(found: list[Settled], tolerance: float = 1e-2) -> list[int]:
    """Indices of the periodic outcomes that settled on different orbits (the first of each):
    the same period and the same peak-to-peak size of every state to ``tolerance`` (seeds
    approach a weakly attracting cycle slowly: 1e-3 apart after hundreds of periods)."""
    kept: list[int] = []
    for k, settled in enumerate(found):
        if settled.kind == SeedKind.PERIODIC and same_as(found, k, kept, tolerance) is None:
            kept.append(k)
    return kept


def same_as(found: list[Settled], k: int, kept: list[int], tolerance: float = 1e-2) -> int | None:
    """The first of ``kept`` whose orbit outcome ``k`` settled on too, as :func:`distinct`
    tells orbits apart (``k`` itself if kept; None if none, or not periodic)."""
    if found[k].kind != SeedKind.PERIODIC:
        return None
    mine = _signature(found[k].orbit)
    return next((j for j in kept if np.allclose(mine, _signature(found[j].orbit),
                                                rtol=tolerance, atol=0)), None)


def _signature(orbit: Orbit) -> np.ndarray:
    return np.concatenate([[orbit.period], np.ptp(orbit.states, axis=0)])
