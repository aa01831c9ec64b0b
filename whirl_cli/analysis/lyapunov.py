"""The largest Lyapunov exponent of any ODE dy/dt = f(y) by the variational equations (Benettin).

Generic: everything takes ``f(y) -> dy/dt`` and ``jac(y) -> df/dy`` (numpy, one state (n,)),
so it works on whirl's models (:mod:`whirl_cli.analysis.motion` wraps them) as on Lorenz.

:func:`tangent_run` integrates the state over a transient, then the state together with one
tangent vector v, dv/dt = J(y) v, with the analytic Jacobian, over the settled window, sampled
on a uniform grid. v is renormalised to unit length every ``renormalise`` seconds (Benettin's
periodic renormalisation, so its norm never overflows); the logarithms of the norms removed
add up to the growth L(t) = ln |v(t)| / |v(0)| at every sample. :func:`exponent_between`
turns L into the largest exponent lambda = (L(b) - L(a)) / (b - a) and its standard error
over blocks.

The tangent vector starts along the flow f(y) plus 1e-4 of a fixed random direction (drawn
isotropic in units of the states' ``scale``): on a periodic orbit or torus the flow direction is
already the neutral Lyapunov vector (no slow alignment, so lambda ~ 0 to the integration
accuracy), and the random part lets an unstable direction take over within ln(1e4) / lambda
seconds (10 s for Lorenz), inside the part :func:`exponent_between` discards. Measured between
two crossings of one Poincaré section (the same phase of a periodic orbit) the bounded
oscillation of |v| along a cycle cancels, which a fixed window would leave as O(1) / duration.

:func:`odeint_tangent_run` is the same with LSODA driven by scipy's ``odeint`` (what
:func:`whirl_cli.analysis.motion.classify_model` uses): the Fortran driver calls back only for f
and J, where ``solve_ivp`` adds Python work to every step (two thirds of the cost with the
generated models' fast fields).

Units: time in the units of ``f`` (s for whirl's models), exponents in 1 / that unit.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

#: Fraction of the random direction added to the flow direction in the first tangent vector:
#: small, because on a cycle a slowly contracting, non-normal direction can carry a random
#: start far from the flow (1e-2 biased the classical model's LCO by -0.04 1/s over 40
#: periods; 1e-4 by 1e-4 1/s); an unstable direction then takes over in ln(1e4) / lambda.
TANGENT_MIX = 1e-4
#: The tangent vector's atol, in units of ``rtol`` x ``scale``: v has unit length in the scales,
#: so the relative tolerance is what matters (1e-3 cost the gimballed model 30 % more steps for
#: the same exponent to 1e-4 1/s).
TANGENT_ATOL = 1.0


@dataclass(frozen=True, eq=False)
class TangentRun:
    """The settled part of a simulation with its tangent growth (:func:`tangent_run`).

    ``time`` (K,) from the end of the transient; ``states`` (K, n); ``growth`` (K,): ln of the
    tangent vector's length relative to its start (renormalisations added back);
    ``diverged``: the state left ``bound`` or the integration failed (``message`` says which);
    the arrays then hold what was computed before. ``tangent`` (n,): the tangent vector at
    the end, unit length in the scales (None if diverged), to continue the run from;
    ``settled``: where the transient ended early, at rest (s; NaN if it ran in full:
    :func:`odeint_tangent_run`'s ``at_rest``)."""

    time: np.ndarray
    states: np.ndarray
    growth: np.ndarray
    diverged: bool
    message: str
    tangent: np.ndarray | None = None
    settled: float = np.nan


def _escape(bound: np.ndarray):
    """A terminal event: some |y_i| / bound_i reaches 1 (the first n entries of y)."""
    def event(_t, y):
        return 1.0 - float(np.max(np.abs(y[:len(bound)]) / bound))

    event.terminal = True
    return event


def _tangent_system(f, jac, n: int):
    """The state y (n) and a tangent vector v together, z = (y, v): its right-hand side
    (f(y), J(y) v) and the Jacobian blockdiag(J, J) the implicit integrators get (the H v
    coupling left out), each a function of z alone."""
    def field(z: np.ndarray) -> np.ndarray:
        return np.concatenate((f(z[:n]), jac(z[:n]) @ z[n:]))

    def jacobian(z: np.ndarray) -> np.ndarray:
        block = jac(z[:n])
        full = np.zeros((2 * n, 2 * n))
        full[:n, :n] = block
        full[n:, n:] = block
        return full

    return field, jacobian


def tangent_run(f, jac, y0, transient: float, duration: float, dt: float, *,
                renormalise: float | None = None, rtol: float = 1e-8,
                atol: float | np.ndarray | None = None, bound: float | np.ndarray = np.inf,
                method: str = "DOP853", scale: float | np.ndarray = 1.0,
                seed: int = 0, tangent: np.ndarray | None = None,
                at_rest: float | None = None) -> TangentRun:
    """Integrate ``transient`` seconds from ``y0`` (state only), then ``duration`` seconds of
    state and tangent vector, sampled every ``dt`` (scipy ``solve_ivp``, ``method``, ``rtol``;
    ``atol`` per state, default ``rtol`` x 1e-3 x max(|y0|, 1); the tangent's atol is ``rtol`` x
    ``scale`` as it is renormalised to 1 in the scales). ``renormalise``: seconds between
    renormalisations (default ``duration`` / 20); the window is integrated one renormalisation
    interval per ``solve_ivp`` call. ``bound`` (per state or one number): |y_i| beyond it counts
    as divergence and ends the run (an event in the transient; checked on the samples in the
    window). ``scale``: the states' typical sizes: |v| is measured in
    them (sum of (v_i / scale_i)^2; the exponent does not depend on the norm, but its
    oscillation along an orbit, which blocks of finite length see, does), and the random part of
    the first tangent vector (``seed``) is isotropic in them. Implicit methods (Radau, BDF,
    LSODA) get the Jacobian blockdiag(J, J) of the augmented system (the H v coupling left out:
    it only slows their Newton iteration, not the accuracy). ``method`` "odeint": LSODA through
    :func:`odeint_tangent_run` instead (the same steps at a fraction of the Python cost).
    ``tangent``: the first tangent vector (default :func:`first_tangent`), to continue a run
    from its end (its last state and :attr:`TangentRun.tangent`); ``at_rest``: "odeint"
    only, see :func:`odeint_tangent_run`."""
    if method == "odeint":
        return odeint_tangent_run(f, jac, y0, transient, duration, dt, rtol=rtol, atol=atol,
                                  bound=bound, scale=scale, seed=seed, renormalise=renormalise,
                                  tangent=tangent, at_rest=at_rest)
    from scipy.integrate import solve_ivp

    y0 = np.asarray(y0, dtype=float)
    n = y0.size
    if atol is None:
        atol = rtol * 1e-3 * np.maximum(np.abs(y0), 1.0)
    atol = np.broadcast_to(np.asarray(atol, dtype=float), (n,))
    bound = np.broadcast_to(np.asarray(bound, dtype=float), (n,))
    escape = _escape(bound)
    implicit = method in ("Radau", "BDF", "LSODA")
    empty = TangentRun(np.zeros(0), np.zeros((0, n)), np.zeros(0), True, "")

    def state_field(_t, y):
        return f(y)

    options = {"jac": lambda _t, y: jac(y)} if implicit else {}
    if transient > 0:
        run = solve_ivp(state_field, (0.0, transient), y0, method=method, rtol=rtol, atol=atol,
                        events=escape, **options)
        if run.status != 0 or not np.all(np.isfinite(run.y[:, -1])):
            why = "left the bound" if run.status == 1 else f"failed: {run.message}"
            return TangentRun(empty.time, empty.states, empty.growth, True,
                              f"transient {why} at t = {run.t[-1]:.4g}")
        y0 = run.y[:, -1]

    field, field_jacobian = _tangent_system(f, jac, n)

    def augmented(_t, z):
        return field(z)

    options = {"jac": lambda _t, z: field_jacobian(z)} if implicit else {}
    unit = np.broadcast_to(np.asarray(scale, dtype=float), (n,))
    v = first_tangent(f, y0, unit, seed) if tangent is None else np.asarray(tangent, float)

    count = int(np.floor(duration / dt + 1e-9)) + 1
    grid = np.minimum(np.arange(count) * dt, duration)
    interval = renormalise or duration / 20
    edges = np.unique(np.r_[np.arange(0.0, duration, interval), duration])
    z = np.r_[y0, v]
    tolerance = np.r_[atol, rtol * TANGENT_ATOL * unit]
    times, states, growth = [], [], []
    offset = 0.0
    for k, (a, b) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        last = k == len(edges) - 2
        inside = grid[(grid >= a) & ((grid < b) | (last & (grid <= b)))]
        keep = len(inside)
        if not last or not len(inside) or inside[-1] < b:
            inside = np.r_[inside, b]  # the chunk's end, to renormalise from
        run = solve_ivp(augmented, (a, b), z, method=method, t_eval=inside, rtol=rtol,
                        atol=tolerance, **options)
        # the bound on the samples (an event function would cost a fifth of the run)
        outside = ~np.all(np.isfinite(run.y), axis=0) | np.any(
            np.abs(run.y[:n]) >= bound[:, None], axis=0)
        ok = run.status == 0 and not outside.any()
        got = min(keep, int(np.argmax(outside)) if outside.any() else run.y.shape[1])
        if got:
            times.append(run.t[:got])
            states.append(run.y[:n, :got].T)
            growth.append(offset + np.log(np.linalg.norm(run.y[n:, :got] / unit[:, None],
                                                         axis=0)))
        if not ok:
            why = "left the bound" if outside.any() else f"failed: {run.message}"
            when = run.t[got] if got < len(run.t) else run.t[-1]
            return _joined(times, states, growth, n, True,
                           f"settled window {why} near t = {transient + when:.4g}")
        z = run.y[:, -1].copy()
        norm = float(np.linalg.norm(z[n:] / unit))
        offset += np.log(norm)
        z[n:] /= norm
    return replace(_joined(times, states, growth, n, False, ""), tangent=z[n:].copy())


def first_tangent(f, y: np.ndarray, unit: np.ndarray, seed: int) -> np.ndarray:
    """The first tangent vector at ``y``: the flow direction plus :data:`TANGENT_MIX` of a
    random direction isotropic in the scales ``unit`` (``seed``), unit length in them."""
    flow = np.asarray(f(y), dtype=float)
    rng = np.random.default_rng(seed)
    direction = rng.standard_normal(len(y)) * unit
    direction /= np.linalg.norm(direction / unit)
    speed = np.linalg.norm(flow / unit)
    v = (flow / speed if speed > 0 else direction) + TANGENT_MIX * direction
    return v / np.linalg.norm(v / unit)


# ------------------------------------------------------------------------------ odeint
def odeint_tangent_run(f, jac, y0, transient: float, duration: float, dt: float, *,
                       rtol: float = 1e-6, atol: float | np.ndarray | None = None,
                       bound: float | np.ndarray = np.inf, scale: float | np.ndarray = 1.0,
                       seed: int = 0, renormalise: float | None = None,
                       tangent: np.ndarray | None = None,
                       at_rest: float | None = None) -> TangentRun:
    """:func:`tangent_run` with LSODA through ``scipy.integrate.odeint`` (the Fortran driver
    calls back only for f and the Jacobian, with far less Python per step than
    ``solve_ivp``): the transient sampled every ``dt`` (the bound checked there), then the
    window in chunks of ``renormalise`` seconds (default ``duration`` / 20),
    the tangent renormalised between them; ``atol`` default ``rtol`` x 1e-3 x ``scale``, the
    tangent's ``rtol`` x :data:`TANGENT_ATOL` x ``scale``. ``tangent``: the first tangent
    vector (unit length in the scales; default :func:`first_tangent`), to continue a run from
    its end (the last state and :attr:`TangentRun.tangent`). ``at_rest`` (in the scales):
    the transient, integrated in pieces of ``duration`` / 4, ends early after a piece over
    which no state moved by as much (peak to peak) and where the Jacobian's eigenvalues all
    have negative real parts: the trajectory has come to rest at a linearly stable
    equilibrium, where it stays (``TangentRun.settled``: the time it ended)."""
    from scipy.integrate import odeint

    y = np.asarray(y0, dtype=float).copy()
    n = y.size
    bound = np.broadcast_to(np.asarray(bound, dtype=float), (n,))
    unit = np.broadcast_to(np.asarray(scale, dtype=float), (n,))
    atol = np.broadcast_to(np.asarray(rtol * 1e-3 * unit if atol is None else atol,
                                      dtype=float), (n,))
    empty = (np.zeros(0), np.zeros((0, n)), np.zeros(0), True)

    def run(field, jacobian, start, grid, tolerance):
        with np.errstate(over="ignore", invalid="ignore"):
            values, info = odeint(field, start, grid, Dfun=jacobian, rtol=rtol,
                                  atol=tolerance, mxstep=1_000_000, full_output=True)
        good = info["message"] == "Integration successful."
        outside = ~np.all(np.isfinite(values[:, :n]), axis=1) | np.any(
            np.abs(values[:, :n]) >= bound, axis=1)
        return values, good and not outside.any(), (int(np.argmax(outside)) if outside.any()
                                                    else len(grid)), info["message"]

    settled = np.nan
    if transient > 0:
        # in pieces of a quarter window when a state at rest may end the transient early
        pieces = max(1, int(np.ceil(transient / (0.25 * duration)))) if at_rest else 1
        edges = np.linspace(0.0, transient, pieces + 1)
        for a, b in zip(edges[:-1], edges[1:], strict=True):
            grid = np.linspace(a, b, max(2, int(np.ceil((b - a) / dt)) + 1))
            values, ok, got, why = run(lambda z, _t: f(z), lambda z, _t: jac(z), y, grid,
                                       atol)
            if not ok:
                when = grid[min(got, len(grid) - 1)]
                reason = "left the bound" if got < len(grid) else f"failed: {why}"
                return TangentRun(*empty, f"transient {reason} at t = {when:.4g}")
            y = values[-1]
            if b < transient and at_rest and _at_rest(values, jac, unit, at_rest):
                settled = float(b)
                break

    field, field_jacobian = _tangent_system(f, jac, n)

    def augmented(z, _t):
        return field(z)

    def augmented_jacobian(z, _t):
        return field_jacobian(z)

    v = first_tangent(f, y, unit, seed) if tangent is None else np.asarray(tangent, float)
    count = int(np.floor(duration / dt + 1e-9)) + 1
    per_chunk = max(1, int(round((renormalise or duration / 20) / dt)))
    tolerance = np.r_[atol, rtol * TANGENT_ATOL * unit]
    states, growth = [y[None, :]], [np.zeros(1)]
    z, total, done = np.r_[y, v], 0.0, 1
    while done < count:
        take = min(per_chunk, count - done)
        grid = (done - 1 + np.arange(take + 1)) * dt
        values, ok, got, why = run(augmented, augmented_jacobian, z, grid, tolerance)
        values = values[1:]
        kept = min(take, max(got - 1, 0)) if not ok else take
        norms = np.linalg.norm(values[:kept, n:] / unit, axis=1)
        states.append(values[:kept, :n])
        growth.append(total + np.log(norms))
        done += kept
        if not ok:
            reason = "left the bound" if got < len(grid) else f"failed: {why}"
            states, growth = np.concatenate(states), np.concatenate(growth)
            return TangentRun(np.arange(done) * dt, states, growth, True,
                              f"settled window {reason} near t = {transient + done * dt:.4g}")
        z = values[-1].copy()
        total += float(np.log(norms[-1]))
        z[n:] /= norms[-1]
    return TangentRun(np.arange(count) * dt, np.concatenate(states), np.concatenate(growth),
                      False, "", z[n:].copy(), settled)


def _at_rest(values: np.ndarray, jac, unit: np.ndarray, tolerance: float) -> bool:
    """The samples ``values`` (K, n) spread less than ``tolerance`` scales in every state and
    the Jacobian at the last one is stable (every eigenvalue's real part negative)."""
    n = len(unit)
    if np.max(np.ptp(values[:, :n], axis=0) / unit) >= tolerance:
        return False
    return bool(np.all(np.linalg.eigvals(jac(values[-1, :n])).real < 0))


def _joined(times, states, growth, n, diverged, message) -> TangentRun:
    if not times:
        return TangentRun(np.zeros(0), np.zeros((0, n)), np.zeros(0), diverged, message)
    return TangentRun(np.concatenate(times), np.concatenate(states), np.concatenate(growth),
                      diverged, message)


def exponent_between(time: np.ndarray, growth: np.ndarray, marks: np.ndarray | None = None,
                     blocks: int = 10, discard: float = 0.1) -> tuple[float, float]:
    """(lambda, standard error) from the growth L(t) of :func:`tangent_run`.

    lambda = (L(b) - L(a)) / (b - a) over the window after the first ``discard`` fraction
    (the tangent vector's alignment). With ``marks`` (times of Poincaré section crossings,
    at least ``blocks`` + 1 of them in the window) a and b and the block ends are crossings,
    so that a bounded oscillation of |v| along a cycle cancels; else equal-length blocks.
    The error is the standard deviation of the ``blocks`` block exponents over
    sqrt(blocks) (blocks treated as independent). Fewer than two samples: (NaN, inf)."""
    if len(time) < 2:
        return np.nan, np.inf
    start = time[0] + discard * (time[-1] - time[0])
    ends = None
    if marks is not None:
        marks = np.asarray(marks, dtype=float)
        marks = marks[(marks >= start) & (marks <= time[-1])]
        if len(marks) >= blocks + 1:
            ends = marks[np.linspace(0, len(marks) - 1, blocks + 1).round().astype(int)]
    if ends is None:
        ends = np.linspace(start, time[-1], blocks + 1)
    values = np.interp(ends, time, growth)
    spans = np.diff(ends)
    rates = np.diff(values) / spans
    exponent = float((values[-1] - values[0]) / (ends[-1] - ends[0]))
    error = float(np.std(rates, ddof=1) / np.sqrt(len(rates))) if len(rates) > 1 else np.inf
    return exponent, error


@dataclass(frozen=True)
class LyapunovEstimate:
    """The largest Lyapunov exponent (1 / time unit of f) and its standard error."""

    exponent: float
    error: float


def largest_lyapunov(f, jac, y0, transient: float, duration: float, dt: float | None = None,
                     **options) -> LyapunovEstimate:
    """The largest Lyapunov exponent of dy/dt = ``f(y)`` from ``y0``: :func:`tangent_run`
    (``options``: its keywords) then :func:`exponent_between` over equal blocks; ``dt``
    (default ``duration`` / 2000) only sets the sampling of L. A run that diverges raises
    ``RuntimeError``."""
    run = tangent_run(f, jac, y0, transient, duration, dt or duration / 2000, **options)
    if run.diverged:
        raise RuntimeError(f"Lyapunov exponent: the trajectory {run.message}")
    return LyapunovEstimate(*exponent_between(run.time, run.growth))
