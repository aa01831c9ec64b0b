"""Time simulation with scipy (LSODA, ``odeint``) on the numpy right-hand side of the symbolic
model: the independent check of what continuation claims.

* A stable periodic orbit: started on AUTO's orbit, the simulation must stay on it (the maximum
  of the dof that moves most, relative to its typical amplitude, over the last periods within
  ``tolerance`` of AUTO's). On a model with a piecewise law (freeplay) the exact, unsmoothed
  law is simulated too (:func:`integrate_exact`) and must stay on it as well.
* A stable equilibrium: a small perturbation of every dof must decay.

:func:`simulation` is the free simulation a study states (``simulations:``): from an initial
state, with the smoothed or the exact law, its failure reported in the result.

Time in seconds, states in SI units (the classical model's rad, rad/s), as everywhere outside
AUTO; perturbations and deviations of equilibria in units of the dofs' typical amplitudes.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

import numpy as np

from ..models import Model
from ..results import (
    Branch,
    BranchKind,
    CheckKind,
    CrossCheck,
    Orbit,
    PointType,
    Simulation,
    SimulationLaw,
)
from ..runtime import forked_map, preloaded
from .global_bifurcations import BLOWUP_FACTOR

#: What simulating imports (scipy's integrators, with scipy.optimize: about 0.5 s): imported
#: once before forking simulation workers, which then inherit it.
MODULES = ("scipy.integrate",)


def import_integrators() -> None:
    """Import scipy's integrators (:data:`MODULES`) here, once, before workers fork: they
    inherit them instead of each importing them."""
    for module in MODULES:
        importlib.import_module(module)

#: Relative tolerance on the amplitude for "the simulation stays on the orbit".
ORBIT_TOLERANCE = 0.01


def integrate(model: Model, params: np.ndarray, y0: np.ndarray, duration: float,
              samples: int = 4000, rtol: float = 1e-8) -> tuple[np.ndarray, np.ndarray]:
    """(t (K,), y (K, n)): the trajectory from ``y0`` over ``duration`` seconds, sampled at
    ``samples`` equally spaced times (LSODA through ``scipy.integrate.odeint``, with the
    analytic Jacobian, so stiff points of strongly hardening springs cost no more than others;
    odeint drives the Fortran solver with far less Python per step than ``solve_ivp``)."""
    from scipy.integrate import odeint

    field, jacobian = model.field_at(params)
    times = np.linspace(0.0, duration, samples)
    states, info = odeint(lambda y, _t: field(y), np.asarray(y0, dtype=float), times,
                          Dfun=lambda y, _t: jacobian(y), rtol=rtol, atol=rtol * 1e-3,
                          mxstep=1_000_000, full_output=True)
    if info["message"] != "Integration successful.":
        raise RuntimeError(f"time integration failed: {info['message']}")
    return times, states


@dataclass(frozen=True)
class ExactTrajectory:
    """A simulation of the exact piecewise laws (:func:`integrate_exact`).

    ``time`` (K,) s and ``states`` (K, n) SI: the samples; ``event_time`` (E,) s,
    ``event_state`` (E, n) and ``event_dof`` (E,): where a piecewise dof reached a breakpoint
    of its law (freeplay: |x| = delta) and the law changed piece, in order."""

    time: np.ndarray
    states: np.ndarray
    event_time: np.ndarray
    event_state: np.ndarray
    event_dof: np.ndarray


#: Most piece changes one exact simulation may make (a guard against chattering).
MAX_EVENTS = 100_000


def _piece(breakpoints: tuple[float, ...], x: float, rate: float) -> int:
    """The piece a dof at ``x`` moving at ``rate`` is on: the number of breakpoints below it
    (at a breakpoint, the piece it moves into)."""
    below = int(np.searchsorted(breakpoints, x, side="left"))
    at = below < len(breakpoints) and x == breakpoints[below]
    return below + 1 if at and rate > 0 else below


def _inside(breakpoint: float, step: int, scale: float) -> float:
    """Where a dof that has just passed ``breakpoint`` going ``step`` (+1 up, -1 down)
    restarts: a few units of round-off beyond it (``scale``: its typical amplitude), on the
    side of the piece it enters. On the breakpoint itself, or a round-off on the wrong side,
    the event of coming back would start at zero or on its far side, and a return within the
    first step (a short excursion) would go unseen: the motion then continues on the wrong
    piece."""
    unit = np.spacing(max(abs(breakpoint), 1e-3 * scale))
    return float(breakpoint + step * 16 * unit)


def integrate_exact(model: Model, params: np.ndarray, y0: np.ndarray, duration: float,
                    samples: int = 4000, rtol: float = 1e-10) -> ExactTrajectory:
    """The trajectory from ``y0`` over ``duration`` seconds with every piecewise law (the
    model's ``piecewise_dofs``: freeplay) in its exact form, unsmoothed, sampled at
    ``samples`` equally spaced times.

    The exact law is smooth on each piece, so each piece is integrated on its own (scipy
    ``solve_ivp``, DOP853, atol ``rtol`` x 1e-3 typical amplitudes) up to the event where a
    piecewise dof reaches a breakpoint of its piece in the direction that leaves it (located
    on the dense output, to round-off); the integration restarts there on the next piece
    (:func:`_inside`: a few units of round-off into it).
    The right-hand side of each piece is the model's exact numeric module
    (:attr:`whirl_cli.models.Model.exact_numeric`), generated from the same symbolic model as
    the smoothed one."""
    from scipy.integrate import solve_ivp

    dofs = model.piecewise_dofs
    if not dofs:
        raise ValueError(f"model {model.name} has no piecewise law to simulate exactly")
    values = dict(zip(model.parameter_names, map(float, params), strict=True))
    breakpoints = [model.breakpoints(i, values) for i in dofs]
    n_dof = len(model.dofs)
    state = np.asarray(y0, dtype=float).copy()
    pieces = [_piece(b, state[i], state[n_dof + i]) for i, b in zip(dofs, breakpoints,
                                                                     strict=True)]
    grid = np.linspace(0.0, duration, samples)
    scale = np.asarray(model.state_scale, dtype=float)
    times, states = [], []
    event_time: list[float] = []
    event_state: list[np.ndarray] = []
    event_dof: list[int] = []
    start = 0.0
    while True:
        field, jacobian = model.exact_numeric.field_at(np.r_[params, pieces])
        events, moves = [], []
        for k, (i, b) in enumerate(zip(dofs, breakpoints, strict=True)):
            if pieces[k] > 0:  # the lower end of the piece, reached going down
                events.append(_crossing(i, b[pieces[k] - 1], -1.0))
                moves.append((k, -1))
            if pieces[k] < len(b):  # the upper end, reached going up
                events.append(_crossing(i, b[pieces[k]], 1.0))
                moves.append((k, 1))
        inside = grid[(grid >= start) & (grid <= duration)]
        solution = solve_ivp(lambda _t, y, f=field: f(y), (start, duration), state,
                             method="DOP853",
                             t_eval=inside, events=events, rtol=rtol, atol=rtol * 1e-3 * scale)
        if solution.status < 0:
            raise RuntimeError(f"exact time integration failed: {solution.message}")
        times.append(solution.t)
        states.append(solution.y.T)
        fired = [(t[0], e) for e, t in enumerate(solution.t_events) if len(t)]
        if solution.status == 0 or not fired:
            break
        start, which = min(fired)
        state = solution.y_events[which][0].copy()
        k, step = moves[which]
        pieces[k] += step
        event_time.append(start)
        event_state.append(state.copy())
        event_dof.append(dofs[k])
        state[dofs[k]] = _inside(breakpoints[k][pieces[k] - (step > 0)], step, scale[dofs[k]])
        if len(event_time) > MAX_EVENTS:
            raise RuntimeError(f"exact time integration: more than {MAX_EVENTS} piece changes "
                               "(chattering at a breakpoint)")
    time = np.concatenate(times)
    keep = np.concatenate([[True], np.diff(time) > 0])  # a sample at an event appears twice
    return ExactTrajectory(time[keep], np.concatenate(states)[keep], np.array(event_time),
                           np.array(event_state).reshape(-1, model.n_states),
                           np.array(event_dof, dtype=int))


#: A free simulation stops (status 1) when a dof leaves this many typical amplitudes.
DIVERGENCE_LIMIT = 100.0


def simulation(model: Model, params: np.ndarray, initial: np.ndarray, duration: float,
               samples: int = 2001, law: SimulationLaw = SimulationLaw.SMOOTHED, name: str = "",
               overrides: dict[str, float] | None = None, rtol: float = 1e-9,
               limit: float = DIVERGENCE_LIMIT) -> Simulation:
    """The trajectory from ``initial`` (SI) over ``duration`` s at ``params``, sampled at
    ``samples`` equally spaced times, as a :class:`~whirl_cli.results.Simulation` named
    ``name`` (``overrides``: the parameters it sets beyond the study's, kept with it).

    ``law`` "smoothed": the model's right-hand side (the law AUTO continues), scipy
    ``solve_ivp`` LSODA with the analytic Jacobian, rtol ``rtol``, atol ``rtol`` x 1e-3
    typical amplitudes; it stops (status 1) where a dof leaves ``limit`` typical amplitudes.
    "exact": the unsmoothed piecewise law (:func:`integrate_exact`; the model needs one).
    A failed integration is not raised: the samples up to the failure are kept, with
    status -1 and scipy's message."""
    from scipy.integrate import solve_ivp

    try:
        law = SimulationLaw(law)
    except ValueError:
        raise ValueError(f"unknown law {law!r} (smoothed | exact)") from None
    y0 = np.asarray(initial, dtype=float)
    grid = np.linspace(0.0, duration, samples)
    status, message = 0, "The solver successfully reached the end of the integration interval."
    if law == SimulationLaw.EXACT:
        try:
            run = integrate_exact(model, params, y0, duration, samples, rtol=rtol)
            time, states = run.time, run.states
        except (RuntimeError, ArithmeticError, ValueError) as error:
            time, states, status, message = grid[:1], y0[None, :], -1, str(error)
    else:
        field, jacobian = model.field_at(params)
        scale = np.asarray(model.state_scale, dtype=float)
        watched = list(model.positions)
        amplitudes = scale[watched]

        def diverged(_t, y):
            return float(np.max(np.abs(y[watched]) / amplitudes)) - limit

        diverged.terminal = True
        diverged.direction = 1.0
        try:
            with np.errstate(over="ignore", invalid="ignore"):
                solved = solve_ivp(lambda _t, y: field(y), (0.0, duration), y0,
                                   method="LSODA", jac=lambda _t, y: jacobian(y), t_eval=grid,
                                   rtol=rtol, atol=rtol * 1e-3 * scale, events=[diverged])
            time, states, status = solved.t, solved.y.T, int(solved.status)
            message = str(solved.message)
            if status == 1:
                message = (f"a dof beyond {limit:g} typical amplitudes at t = "
                           f"{solved.t_events[0][0]:.6g} s")
        except (ArithmeticError, ValueError, RuntimeError) as error:
            time, states, status, message = grid[:1], y0[None, :], -1, str(error)
    overrides = dict(overrides or {})
    matrix = model.hub_matrix
    used = {model.states[k].unit for k in np.flatnonzero(np.abs(matrix).sum(axis=0))}
    return Simulation(
        name=name, law=law, parameter_names=tuple(overrides),
        parameter_units=tuple(model.parameter(n).unit for n in overrides),
        parameter_values=np.array(list(overrides.values()), dtype=float),
        state_names=model.state_names, state_units=tuple(s.unit for s in model.states),
        initial=y0, time=np.asarray(time, dtype=float),
        states=np.asarray(states, dtype=float).reshape(-1, model.n_states),
        hub=np.asarray(states, dtype=float).reshape(-1, model.n_states) @ matrix.T,
        hub_unit=used.pop() if len(used) == 1 else "1", status=status, message=message,
        first_order=tuple(x.name for x in model.family.first_order))


def _crossing(dof: int, value: float, direction: float):
    """A terminal solve_ivp event: state ``dof`` passes ``value`` in ``direction``."""
    def event(_t, y):
        return y[dof] - value

    event.terminal = True
    event.direction = direction
    return event


def _parameters(model: Model, overrides: dict[str, float], names: tuple[str, ...],
                values: np.ndarray) -> np.ndarray:
    return model.parameter_vector({**overrides, **dict(zip(names, map(float, values),
                                                           strict=True))})


def check_orbit(model: Model, overrides: dict[str, float], branch: Branch, orbit: Orbit,
                periods: int = 10, tolerance: float = ORBIT_TOLERANCE) -> CrossCheck:
    """Start on ``orbit`` and simulate ``periods`` periods; the max of the dof that moves most
    (relative to its typical amplitude) over the last two periods must match AUTO's within
    ``tolerance`` (relative to its half peak-to-peak amplitude). With a piecewise law
    (freeplay) the exact law's simulation must too; its max is stored as ``exact``."""
    watched = list(model.positions)
    spans = np.ptp(orbit.states[:, watched], axis=0) / np.asarray(model.state_scale)[watched]
    dof = watched[int(np.argmax(spans))]
    params = _parameters(model, overrides, branch.parameter_names, orbit.parameters)
    time, states = integrate(model, params, orbit.states[0], periods * orbit.period,
                             samples=periods * 400)
    last = time >= (periods - 2) * orbit.period
    simulated = float(states[last, dof].max())
    expected = float(branch.state_max[orbit.index, dof])
    half_span = max(np.ptp(orbit.states[:, dof]) / 2, 1e-12)
    passed = abs(simulated - expected) / half_span <= tolerance
    exact = None
    if model.piecewise_dofs:  # freeplay: the exact law, beside the smoothed one AUTO continued
        run = integrate_exact(model, params, orbit.states[0], periods * orbit.period,
                              samples=periods * 400)
        exact = float(run.states[run.time >= (periods - 2) * orbit.period, dof].max())
        passed = passed and abs(exact - expected) / half_span <= tolerance
    return CrossCheck(branch.name, orbit.index, CheckKind.ORBIT, float(orbit.parameters[0]),
                      expected, simulated, bool(passed), model.state_names[dof], exact)


def check_equilibrium(model: Model, overrides: dict[str, float], branch: Branch, index: int,
                      perturbation: float = 1e-4) -> CrossCheck:
    """Perturb every dof of a stable equilibrium by ``perturbation`` typical amplitudes (rad for
    the classical model; at most 0.1 % of its deflection: the basin is tiny next to a
    pitchfork) and simulate T = ten slowest decay times 1/sigma (sigma = -max Re lambda of
    the Jacobian), at most 60 s. For the linearised motion the largest dof deviation left is
    at most kappa sqrt(m) e^(-sigma T) times the perturbation (||e^(J T)|| <= kappa
    e^(-sigma T), kappa the condition number of the eigenvector matrix: the non-normal
    transient; m dofs perturbed). The check passes if it is below

        min(2 kappa sqrt(m) e^(-sigma T), 0.1) * perturbation + 1e-8 (typical amplitudes),

    e^(-sigma T) = e^-10 unless T is capped. The factor 2 leaves room for the nonlinear terms,
    which the default perturbation keeps small also two steps from a fold of equilibria (where
    1e-3 rad decayed 40 times slower than linear); 1e-8 rad is the accuracy of AUTO's stored
    equilibrium (Newton to EPSU = 1e-8) and of LSODA. So a stored state wrong by more than
    that, or a decay slower than the eigenvalues say, fails; and never may more than a tenth
    of the perturbation remain."""
    state = branch.state_max[index]
    params = _parameters(model, overrides, branch.parameter_names, branch.parameters[index])
    eigenvalues, vectors = np.linalg.eig(model.jacobian_numpy(state, params))
    slowest = float(-eigenvalues.real.max())
    # the dofs, in units of their typical amplitudes (rad for the classical model)
    typical = np.asarray(model.state_scale, dtype=float)
    angles = np.isin(np.arange(model.n_states), model.positions)
    deflection = np.abs(state / typical)[angles].max()
    if deflection > 0:  # stay within the basin (tiny next to a pitchfork) of the equilibrium
        perturbation = min(perturbation, 1e-3 * deflection)
    start = state + perturbation * typical * angles
    duration = min(10.0 / max(slowest, 1e-3), 60.0)
    _, states = integrate(model, params, start, duration, samples=200)
    final = float(np.abs((states[-1] - state) / typical)[angles].max())
    transient = 2.0 * float(np.linalg.cond(vectors)) * np.sqrt(angles.sum())
    floor = 1e-8  # rad: AUTO's Newton tolerance EPSU (whirl's default); LSODA adds far less
    allowed = min(transient * np.exp(-max(slowest, 0.0) * duration), 0.1) * perturbation + floor
    return CrossCheck(branch.name, index, CheckKind.EQUILIBRIUM, float(branch.parameters[index, 0]),
                      perturbation, final, bool(slowest > 0 and final < allowed))


def _interior_stable(branch: Branch, index: int) -> bool:
    """Known to be stable, and so are both neighbours (away from bifurcations)."""
    lo, hi = max(index - 1, 0), min(index + 2, len(branch))
    special = branch.point_type[lo:hi]
    stable = branch.stable[lo:hi] & branch.stability_known[lo:hi]
    return bool(stable.all()) and not np.isin(
        special, [PointType.LPC, PointType.BPC, PointType.PD, PointType.TR, PointType.HB,
                  PointType.BP, PointType.LP]).any()


#: An orbit this fraction of its branch's parameter span or closer to a fold of cycles is not
#: checked: a smoothed law moves its folds by about its smoothing width, so the unsmoothed
#: law's cycle may be gone there (it leaves for another attractor).
FOLD_MARGIN = 1e-3


def _near_fold(branch: Branch, index: int) -> bool:
    """True if row ``index`` lies within FOLD_MARGIN of the branch's parameter span of one of
    its folds of cycles."""
    p = branch.parameters[:, 0]
    folds = p[branch.point_type == PointType.LPC]
    return bool(len(folds)) and bool(
        np.abs(folds - p[index]).min() <= FOLD_MARGIN * max(float(np.ptp(p)), 1e-300))


def cross_check(model: Model, overrides: dict[str, float], branches: tuple[Branch, ...],
                per_branch: int = 2, jobs: int = 1) -> tuple[CrossCheck, ...]:
    """Checks of up to ``per_branch`` stable points of every branch (orbits for periodic
    branches, perturbations for equilibria), spread along each branch. Not checked: points next
    to bifurcations, orbits near a fold of cycles (:data:`FOLD_MARGIN`), orbits in a period
    blow-up (T > 3 T_Hopf) and equilibria too weakly damped or too stiff to simulate in
    bounded time. ``jobs`` > 1 simulates in that many forked
    processes (:func:`whirl_cli.runtime.forked_map`: results identical, in the same
    order; an interrupt of the parent kills them at once)."""
    preloaded()  # scipy may be being imported in the background (it is then used here)
    tasks = planned_checks(branches, per_branch)
    return tuple(forked_map(lambda k: _check(model, overrides, branches, tasks[k]), len(tasks),
                            jobs))


def _check(model: Model, overrides: dict[str, float], branches: tuple[Branch, ...],
           task: tuple[int, str, int]) -> CrossCheck:
    number, kind, item = task
    branch = branches[number]
    if kind == CheckKind.ORBIT:
        return check_orbit(model, overrides, branch, branch.orbits[item])
    return check_equilibrium(model, overrides, branch, item)


def planned_checks(branches: tuple[Branch, ...], per_branch: int = 2
                   ) -> list[tuple[int, str, int]]:
    """What :func:`cross_check` simulates: (branch index, check kind, orbit index
    in ``branch.orbits`` or row of the equilibrium branch)."""
    tasks: list[tuple[int, str, int]] = []
    for number, branch in enumerate(branches):
        if branch.kind == BranchKind.PERIODIC:
            # orbits in a period blow-up (near a homoclinic/heteroclinic orbit) are too
            # sensitive for simulation to follow for 20 periods; they are not checked
            hopf_period = branch.period[0]
            candidates = [k for k, o in enumerate(branch.orbits)
                          if 0 < o.index < len(branch) - 1
                          and _interior_stable(branch, o.index) and o.states.shape[0] > 1
                          and o.period < BLOWUP_FACTOR * hopf_period
                          and not _near_fold(branch, o.index)]
            tasks += [(number, CheckKind.ORBIT, k) for k in _spread(candidates, per_branch)]
        elif branch.kind == BranchKind.EQUILIBRIUM:
            rows = [k for k in range(1, len(branch) - 1)
                    if _interior_stable(branch, k) and _checkable(branch.eigenvalues[k])]
            tasks += [(number, CheckKind.EQUILIBRIUM, row) for row in _spread(rows, per_branch)]
    return tasks


def _checkable(eigenvalues: np.ndarray, max_cycles: float = 300.0) -> bool:
    """True if a perturbation decays tenfold within a minute and within ``max_cycles`` periods
    of the fastest mode (stiff, fast-oscillating points cost too much to simulate)."""
    if not np.all(np.isfinite(eigenvalues)):
        return False
    decay = -float(eigenvalues.real.max())
    if decay <= 0.1:
        return False
    duration = min(10.0 / decay, 60.0)
    return duration * float(np.abs(eigenvalues).max()) / (2 * np.pi) <= max_cycles


def _spread(items: list, count: int) -> list:
    if len(items) <= count:
        return list(items)
    picks = np.linspace(0, len(items) - 1, count).round().astype(int)
    return [items[k] for k in picks]


def whirl_sense(model: Model, states: np.ndarray) -> str:
    """"FW" or "BW": the sense in which the hub path of an orbit turns relative to the spin
    (+x), from the signed area enclosed in the hub plane (``model.hub_matrix``)."""
    hub_y, hub_z = (states @ model.hub_matrix.T).T
    area = 0.5 * np.sum(hub_y * np.roll(hub_z, -1) - np.roll(hub_y, -1) * hub_z)
    return "FW" if area > 0 else "BW"
