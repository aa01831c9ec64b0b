"""One-parameter equilibria and their AUTO constants.

1. the main branch from the start value, both directions, to the ends of the range;
2. at every branch point (BP) found, branch switching (ISW=-1) in both directions to the
   secondary (static-divergence) equilibria, recursively for branch points on those branches
   (each point once);
3. from every further equilibrium given at the start value (e.g. one a seed settled on, or
   one Newton's method finds from a spread of starts, :func:`spread_equilibria`) that lies on
   none of these branches, a branch both ways; of a symmetric model whose right-hand side is
   odd there, from its mirror image too (offset equilibria no branch point leads to, such as
   those of freeplay with K_in = 0).
"""

from __future__ import annotations

import numpy as np

from ..auto.constants import base_constants, par_layout
from ..errors import WhirlError
from ..models import Model
from ..results import Branch, BranchKind, Origin, PointType, SpecialPoint
from .branches import same_point, typical_amplitudes
from .engine import Engine, Numerics, RunSpec, run_branches

#: How deep branch switching recurses (main -> secondary -> tertiary).
MAX_SWITCH_DEPTH = 3
#: The spread of Newton starts: these fractions of each dof's typical amplitude (13 from 0.01
#: to 1, evenly on a log scale), both signs.
SPREAD = tuple(10.0 ** (k / 6 - 2) for k in range(13))


def _stops(model: Model, parameter: str, bounds: tuple[float, float], amplitude: float) -> dict:
    """UZSTOP: the range ends, and every dof (and first-order state) at +/- ``amplitude`` in
    units of its typical amplitude (AUTO's PVLS values are in those units: for the classical
    model rad)."""
    stops: dict = {parameter: [float(bounds[0]), float(bounds[1])]}
    for k in model.positions:
        stops[f"max_{model.state_names[k]}"] = float(amplitude)
        stops[f"min_{model.state_names[k]}"] = -float(amplitude)
    return stops


def equilibrium_constants(model: Model, numerics: Numerics, parameter: str,
                          bounds: tuple[float, float], direction: int) -> dict:
    """Constants for a one-parameter continuation of equilibria (IPS=1) of ``parameter``."""
    lower, upper = bounds
    width = upper - lower
    return base_constants(model) | {
        "IPS": 1, "ISW": 1, "IRS": 0, "ILP": 1, "ISP": 2, "MXBF": 0,
        "ICP": [parameter, *par_layout(model).measures()],
        "NMX": numerics.max_steps, "NPR": 0, "IID": 2,
        "DS": direction * numerics.step_initial * width,
        "DSMIN": numerics.step_min * width, "DSMAX": numerics.step_max * width,
        "EPSL": numerics.tolerance, "EPSU": numerics.tolerance, "EPSS": 1e-6,
        "ITMX": 30, "ITNW": numerics.newton_max_iterations, "NWTN": 3,
        "NTST": numerics.mesh_intervals, "NCOL": numerics.collocation_points, "IAD": 3,
        "RL0": lower - 0.05 * width, "RL1": upper + 0.05 * width,
        "UZSTOP": _stops(model, parameter, bounds, numerics.max_amplitude),
    } | ({"UZR": {parameter: [float(v) for v in numerics.orbits_at]}} if numerics.orbits_at
         else {})


def equilibria(engine: Engine, name: str, parameter: str, start: float,
               bounds: tuple[float, float], parameters: dict[str, float], numerics: Numerics,
               branch_points: bool = True, guess: np.ndarray | None = None,
               also_from: tuple[np.ndarray, ...] = (), spread: bool = False
               ) -> tuple[list[Branch], list[SpecialPoint]]:
    """Equilibrium branches (main, then secondary from every BP, then one from each state of
    ``also_from`` on no branch yet) and their special points; the main branch starts at the
    equilibrium :func:`starting_equilibrium` finds from ``guess``, the others at those it
    finds from each of ``also_from`` (SI states at ``start``) and, if ``spread``, from each
    of :func:`spread_equilibria`."""
    model = engine.model
    lower, upper = bounds
    width = upper - lower
    amplitudes = typical_amplitudes(model)
    start_parameters = {**parameters, parameter: float(start)}
    state = starting_equilibrium(model, start_parameters, guess, f"{name}: {parameter} = "
                                 f"{start:g}")
    specs = _both_ways(model, numerics, parameter, start, bounds, start_parameters,
                       f"{name}/main", f"start at {parameter} = {start:g}",
                       _start_line(model, state) if state.any() else None)
    branches: list[Branch] = []
    points: list[SpecialPoint] = []
    frontier = run_branches(engine, specs, branches, points, skip_first=False)

    # In a linear model a branch point carries a straight line of equilibria at a fixed
    # parameter value; AUTO's fold test fires all along it, so fold detection is switched off.
    neutral = is_linear(model, parameters)
    switched: list[SpecialPoint] = []
    depth = 0
    while branch_points and frontier and depth < MAX_SWITCH_DEPTH:
        depth += 1
        todo = []
        for point in frontier:
            if point.point_type != PointType.BP or any(
                    same_point(point, done, width, amplitudes) for done in switched):
                continue
            switched.append(point)
            source = _run_of(branches, point.branch)
            for direction, label in ((1, "a"), (-1, "b")):
                constants = equilibrium_constants(model, numerics, parameter, bounds, direction)
                constants["ISW"] = -1
                if neutral:
                    constants["ILP"] = 0
                todo.append(RunSpec(
                    f"{name}/secondary_{len(switched)}{label}", constants,
                    BranchKind.EQUILIBRIUM,
                    Origin.at(point),
                    (parameter,), restart=(source, point.label)))
        frontier = [p for p in run_branches(engine, todo, branches, points, skip_first=True)
                    if not any(same_point(p, q, width, amplitudes) for q in switched)]

    if spread:
        also_from = (*also_from, *spread_equilibria(model, start_parameters,
                                                    numerics.max_amplitude))
    found = 0
    for rest in _mirrored(model, start_parameters, also_from):
        state = starting_equilibrium(model, start_parameters, rest, f"{name}: {parameter} = "
                                     f"{start:g}")
        if on_branch(branches, start, state, width, amplitudes):
            continue
        found += 1
        run_branches(engine, _both_ways(
            model, numerics, parameter, start, bounds, start_parameters,
            f"{name}/resting_{found}", f"equilibrium at {parameter} = {start:g} off every "
            "branch (a seed settled on it, or its mirror image)", _start_line(model, state)),
            branches, points, skip_first=False)

    unique: list[SpecialPoint] = []
    for point in points:
        if not any(point.point_type == q.point_type and same_point(point, q, width, amplitudes)
                   for q in unique):
            unique.append(point)
    return branches, unique


def _both_ways(model: Model, numerics: Numerics, parameter: str, start: float,
               bounds: tuple[float, float], values: dict[str, float], name: str, origin: str,
               start_state: str | None) -> list[RunSpec]:
    """The runs of an equilibrium branch from ``start`` down and up (``<name>_down``,
    ``<name>_up``; only those with room in ``bounds``)."""
    specs = []
    for direction, label in ((-1, "down"), (1, "up")):
        if (direction < 0 and start > bounds[0]) or (direction > 0 and start < bounds[1]):
            constants = equilibrium_constants(model, numerics, parameter, bounds, direction)
            constants["PAR"] = values
            specs.append(RunSpec(f"{name}_{label}", constants, BranchKind.EQUILIBRIUM,
                                 Origin(origin), (parameter,), start_state=start_state))
    return specs


def _start_line(model: Model, state: np.ndarray) -> str:
    """``state`` (SI) as the line of AUTO's U the generated STPNT reads (RunSpec.start_state),
    to full double precision."""
    return " ".join(f"{x:.17g}" for x in state / model.state_scale) + "\n"


def _mirrored(model: Model, values: dict[str, float], states: tuple[np.ndarray, ...]
              ) -> list[np.ndarray]:
    """``states``, each followed by its mirror image -y where the model is symmetric and its
    right-hand side odd there."""
    from .mirror import is_odd

    params = model.parameter_vector(values)
    out = []
    for state in states:
        state = np.asarray(state, dtype=float)
        out.append(state)
        if model.symmetric and state.any() and is_odd(model, params, [state]):
            out.append(-state)
    return out


def spread_starts(model: Model) -> list[np.ndarray]:
    """Newton starts (SI) across the dofs' amplitudes: each dof alone, and all of them together
    (of one sign, and of alternating signs), at each fraction of :data:`SPREAD` of its typical
    amplitude, both signs; rates and first-order states zero."""
    amplitudes = typical_amplitudes(model)
    dofs = list(model.positions)
    patterns = [np.eye(len(dofs))[k] for k in range(len(dofs))]
    if len(dofs) > 1:
        patterns += [np.ones(len(dofs)), (-1.0) ** np.arange(len(dofs))]
    starts = []
    for pattern in patterns:
        for fraction in SPREAD:
            for sign in (1.0, -1.0):
                start = np.zeros(model.n_states)
                start[dofs] = sign * fraction * pattern * amplitudes[dofs]
                starts.append(start)
    return starts


def spread_equilibria(model: Model, parameters: dict[str, float], bound: float
                      ) -> list[np.ndarray]:
    """The distinct equilibria (SI) Newton's method finds from :func:`spread_starts`, those
    within ``bound`` typical amplitudes in every state (a branch stops there), the zero state
    left out."""
    values = model.parameter_vector(parameters)
    field, jacobian = model.field_at(values)
    amplitudes = typical_amplitudes(model)
    scale = np.asarray(model.state_scale, dtype=float)
    found: list[np.ndarray] = []
    for start in spread_starts(model):
        root, _ = newton(field, jacobian, start, scale)
        if root is None or np.abs(root / amplitudes).max() >= bound:
            continue
        if np.allclose(root / amplitudes, 0.0, atol=1e-9) or any(
                np.allclose(root / amplitudes, known / amplitudes, atol=1e-6, rtol=1e-6)
                for known in found):
            continue
        found.append(root)
    return found


def on_branch(branches: list[Branch], value: float, state: np.ndarray, width: float,
              amplitudes: np.ndarray) -> bool:
    """True if an equilibrium branch passes through ``state`` (SI) at parameter ``value``:
    a point of it there, interpolated between its neighbours, within 1e-4 typical
    ``amplitudes`` (or 1e-3 relatively) of it in every state."""
    target = state / amplitudes
    for branch in branches:
        if branch.is_periodic or len(branch) < 1:
            continue
        p = branch.parameters[:, 0]
        rows = branch.state_max / amplitudes
        near = [rows[k] for k in np.flatnonzero(np.abs(p - value) <= 1e-9 * width)]
        for k in np.flatnonzero((p[:-1] - value) * (p[1:] - value) < 0):
            w = (value - p[k]) / (p[k + 1] - p[k])
            near.append(rows[k] + w * (rows[k + 1] - rows[k]))
        if any(np.allclose(row, target, atol=1e-4, rtol=1e-3) for row in near):
            return True
    return False


def starting_equilibrium(model: Model, parameters: dict[str, float],
                         guess: np.ndarray | None, where: str) -> np.ndarray:
    """The equilibrium (SI) a continuation starts from: the zero state where it is one (every
    symmetric model), else the root Newton's method finds from ``guess`` (default: zero; see
    :func:`newton`). WhirlError naming ``where`` when it finds none."""
    values = model.parameter_vector(parameters)
    field, jacobian = model.field_at(values)
    start = np.zeros(model.n_states) if guess is None else np.asarray(guess, dtype=float)
    if guess is None and np.allclose(field(start), 0.0, rtol=0.0, atol=1e-14):
        return start
    state, reason = newton(field, jacobian, start, np.asarray(model.state_scale, dtype=float))
    if state is None:
        origin = "the zero state" if guess is None else "start_state"
        raise WhirlError(f"{where}: no equilibrium found by Newton's method from {origin} "
                         f"({reason}); give the continuation a `start_state` near one")
    return state


def newton(field, jacobian, start: np.ndarray, scale: np.ndarray, iterations: int = 100,
           max_step: float = 10.0) -> tuple[np.ndarray | None, str]:
    """A root of ``field`` (SI) by Newton's method from ``start``: full steps (a least-squares
    step where the Jacobian is singular), each at most ``max_step`` typical sizes ``scale``,
    until the step is below 1e-12 of them. (root, "") or (None, why not)."""
    state = np.array(start, dtype=float)
    for _ in range(iterations):
        step = np.linalg.lstsq(jacobian(state), -field(state), rcond=None)[0]
        size = float(np.abs(step / scale).max())
        if not np.isfinite(size):
            return None, "the iteration diverged"
        state = state + step * min(1.0, max_step / size) if size else state
        if size < 1e-12:
            residual = float(np.abs(field(state)).max())
            return (state, "") if residual <= 1e-9 * max(1.0, float(np.abs(
                state / scale).max())) else (None, f"stalled at a residual of {residual:.3g}")
    return None, f"no convergence in {iterations} steps"


def is_linear(model: Model, parameters: dict[str, float]) -> bool:
    """True if the right-hand side is linear in the states at these parameter values: it
    equals its Jacobian at the origin times a probe state, every component nonzero and of a
    different size (0.3 cos k, k = 1..n: up to 17 deg on an angle, beyond any freeplay gap)."""
    values = model.parameter_vector(parameters)
    probe = 0.3 * np.cos(np.arange(1.0, model.n_states + 1))
    rhs = model.rhs_numpy(probe, values)
    linearised = model.jacobian_numpy(np.zeros(model.n_states), values) @ probe
    return bool(np.allclose(rhs, linearised, rtol=1e-10, atol=1e-12 * np.abs(rhs).max()))


def _run_of(branches: list[Branch], branch_name: str) -> str:
    return next(b.runs[-1] for b in branches if b.name == branch_name)

