"""Limit cycles not born at a Hopf point, found from simulation.

A seed is an initial state. :func:`settle` simulates it (LSODA on the model's smoothed
right-hand side) until the motion has settled, and says what it settled on:

* "periodic": successive upward crossings of a Poincare section (the first dof through the
  mean of its recent motion) repeat, in state and in time, to ``tolerance`` of the motion's
  size; the orbit is the last period, for AUTO to start from (see
  :func:`whirl_cli.continuation.periodic.orbit_families`);
* "equilibrium": every dof has stopped moving (peak to peak below ``tolerance`` of the seed);
* "diverged": a dof has left ``limit`` typical amplitudes;
* "unsettled": none of these within ``max_periods`` periods of the slowest oscillatory
  linear mode (:func:`reference_period`).

:func:`auto_seeds` makes the seeds of ``seeds: auto``; :func:`distinct` keeps one of the seeds
that settle on the same orbit. Time in s, states in SI units.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..models import Model
from ..results import Orbit
from ..units import display_unit
from .simulate import integrate

#: Samples per reference period in the simulation (and the rows of a settled orbit + 1).
SAMPLES_PER_PERIOD = 200
ORBIT_ROWS = 801
#: Simulated in chunks of this many reference periods, at most ``max_periods`` in all.
CHUNK_PERIODS = 50


@dataclass(frozen=True)
class Settled:
    """What a seed settled on: ``kind`` (periodic | equilibrium | diverged | unsettled),
    ``orbit`` (one period, periodic only), ``state`` (the last simulated state) and
    ``message`` (what was seen, e.g. the period and the return mismatch)."""

    kind: str
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
    k = model.n_dof
    dofs = list(range(k)) + list(range(2 * k, model.n_states))  # and first-order states
    amplitudes = np.array(model.typical_amplitudes, dtype=float)[dofs]
    state, elapsed = seed.copy(), 0.0
    while elapsed < max_periods * period:
        t, y = integrate(model, params, state, CHUNK_PERIODS * period,
                         samples=CHUNK_PERIODS * SAMPLES_PER_PERIOD + 1)
        elapsed += t[-1]
        if not np.isfinite(y).all() or (np.abs(y[:, dofs]) > limit * amplitudes).any():
            return Settled("diverged", seed, y[-1], None,
                           f"a dof beyond {limit:g} typical amplitudes after {elapsed:.3g} s")
        state = y[-1]
        recent = y[-10 * SAMPLES_PER_PERIOD:]
        size = np.ptp(recent[:, dofs], axis=0) / amplitudes
        if size.max() < tolerance * max(np.abs(seed[dofs] / amplitudes).max(), 1e-12):
            return Settled("equilibrium", seed, state, None,
                           f"at rest after {elapsed:.3g} s")
        orbit, message = _repeating_orbit(t, y, tolerance)
        if orbit is not None:
            return Settled("periodic", seed, state, orbit, f"{message} after {elapsed:.3g} s")
    return Settled("unsettled", seed, state, None,
                   f"no repeating motion within {max_periods} periods ({elapsed:.3g} s)")


def _repeating_orbit(t: np.ndarray, y: np.ndarray, tolerance: float
                     ) -> tuple[Orbit | None, str]:
    """The last period of ``y`` if its last three returns to the Poincare section (the first
    state through its recent mean, upwards) repeat to ``tolerance``: in every state relative
    to that state's size, and in the return times."""
    x = y[:, 0] - y[len(y) // 2:, 0].mean()
    up = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    if len(up) < 4:
        return None, ""
    share = -x[up] / (x[up + 1] - x[up])
    times = t[up] + share * (t[up + 1] - t[up])
    returns = y[up] + share[:, None] * (y[up + 1] - y[up])
    size = np.maximum(np.ptp(y[len(y) // 2:], axis=0), 1e-300)
    mismatch = (np.abs(np.diff(returns[-3:], axis=0)) / size).max()
    periods = np.diff(times[-3:])
    drift = abs(periods[1] / periods[0] - 1)
    if mismatch > tolerance or drift > tolerance:
        return None, ""
    begin, end = times[-2], times[-1]
    grid = np.linspace(begin, end, ORBIT_ROWS)
    states = np.column_stack([np.interp(grid, t, y[:, k]) for k in range(y.shape[1])])
    orbit = Orbit(label=0, point_type=0, index=0, parameters=np.empty(0), period=float(end - begin),
                  time=grid - begin, states=states)
    return orbit, (f"period {end - begin:.6g} s, returns repeat to {mismatch:.1e} of the "
                   f"motion's size")


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
        if settled.kind == "periodic" and same_as(found, k, kept, tolerance) is None:
            kept.append(k)
    return kept


def same_as(found: list[Settled], k: int, kept: list[int], tolerance: float = 1e-2) -> int | None:
    """The first of ``kept`` whose orbit outcome ``k`` settled on too, as :func:`distinct`
    tells orbits apart (``k`` itself if kept; None if none, or not periodic)."""
    if found[k].kind != "periodic":
        return None
    mine = _signature(found[k].orbit)
    return next((j for j in kept if np.allclose(mine, _signature(found[j].orbit),
                                                rtol=tolerance, atol=0)), None)


def _signature(orbit: Orbit) -> np.ndarray:
    return np.concatenate([[orbit.period], np.ptp(orbit.states, axis=0)])
