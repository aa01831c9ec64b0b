"""Periodic families, continued fold by fold to their ends (a Hopf point reached, the range, the
amplitude bound, a period blow-up, ...): from every Hopf point (:func:`periodic_families`,
grown first), or both ways from a given orbit (:func:`orbit_families`: an AUTO start from data,
e.g. an orbit settled by time simulation or one stored on a family).

The period cap and blow-up detection are judged against a family's reference period: its Hopf
point's, or its start orbit's.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..analysis import global_bifurcations
from ..auto.constants import AMPLITUDE, par_layout
from ..models import Model
from ..results import (
    OTHER_END,
    STEP_LIMIT,
    Branch,
    BranchKind,
    Orbit,
    Origin,
    PointType,
    RunStatus,
    SpecialPoint,
)
from ..runtime import thread_map
from .branches import amplitude, head, join, last_good_label, reverse, special_points
from .engine import Engine, Numerics, RunSpec, read_run
from .equilibria import equilibrium_constants
from .homoclinic import locate_homoclinics
from .mirror import mirror_sources, mirrored_branch, mirrored_point

#: A periodic run from a Hopf point first stops once the orbit has grown to this amplitude
#: (AUTO's non-dimensional units, the PVLS ``amplitude``).
GROWN_AMPLITUDE = 2e-3
#: A family that shrinks back below this amplitude has reached a Hopf point.
HOPF_RETURN_AMPLITUDE = 1e-3
#: Periodic runs stop when the period exceeds this multiple of the Hopf period (blow-up).
PERIOD_CAP = 25.0
#: Label an orbit profile (kept in the results) every this many steps.
ORBIT_EVERY = 20
#: A family is continued fold by fold (AUTO stops at each fold of cycles); at most this many.
MAX_SEGMENTS = 24
#: After MX, a family is restarted with a finer mesh and smaller steps at most this often in a
#: row (each time twice the mesh intervals and half the largest step, kept for its later
#: segments); a segment that ends without MX starts the count again ...
MAX_RETRIES = 2
#: ... up to this many retries in all (the mesh grows 2**MAX_REFINEMENTS times at most).
MAX_REFINEMENTS = 3
#: A family that came back onto its own Hopf point is computed again with this many times
#: the mesh intervals.
RETRACE_MESH_FACTOR = 2
#: The first AUTO label of the second side of a family started at an orbit (the first side's
#: start at 1): the two sides are one branch, whose labels name its orbits.
SECOND_SIDE_LABEL = 5001


def periodic_constants(model: Model, numerics: Numerics, parameter: str,
                       bounds: tuple[float, float], period_tau: float) -> dict:
    """Constants for periodic orbits (IPS=2) restarted from a Hopf or an earlier orbit;
    ``period_tau``: the reference period in AUTO's time units (the cap is a multiple of it)."""
    constants = equilibrium_constants(model, numerics, parameter, bounds, 1)
    constants.update({
        "IPS": 2, "ISW": 1, "ILP": 1, "ISP": 2,
        "ICP": [parameter, "PERIOD", *par_layout(model).measures()],
        "NPR": ORBIT_EVERY,
    })
    constants["UZSTOP"] = dict(constants["UZSTOP"], PERIOD=PERIOD_CAP * period_tau)
    return constants


@dataclass(frozen=True)
class OrbitStart:
    """A start for :func:`orbit_families`: ``orbit`` (time from 0 to its period in s, states
    in SI units; its rows need not close exactly), ``value`` of the continued parameter there
    (every other parameter is the study's) and ``origin``, said in the results."""

    orbit: Orbit
    value: float
    origin: Origin


@dataclass
class FamilySide:
    """One side of a periodic family being continued, and its branch pieces so far.

    ``name``: its branch name; ``period``: its reference period (s), the Hopf period or the
    start orbit's; ``hopf``: the index of the Hopf point it starts from (None for an orbit
    start); ``grows``: its first run grows it from the Hopf point to GROWN_AMPLITUDE;
    ``stop(piece, row)``: why the family ends at that row of a piece of it, if it does there
    ("" if not; judged at each fold it reaches)."""

    name: str
    period: float
    spec: RunSpec
    pieces: list[Branch]
    hopf: int | None = None
    grows: bool = False
    retries: int = 0
    refinements: int = 0
    stop: Callable[[Branch, int], str] | None = None


def periodic_families(engine: Engine, name: str, parameter: str, bounds: tuple[float, float],
                      numerics: Numerics, equilibria: list[Branch], points: list[SpecialPoint],
                      parameters: dict[str, float]
                      ) -> tuple[list[Branch], list[SpecialPoint]]:
    """The periodic family of every Hopf point, each stored once, with its special points.

    A family starts at its Hopf point and grows to GROWN_AMPLITUDE; it is then continued in
    segments that AUTO ends at each fold of cycles. A fold where the orbit has shrunk onto a
    Hopf point is the family reaching that Hopf point (AUTO would go on round the closed family
    again); there the family ends. Families that reach each other's Hopf points are one family,
    kept once. A family whose period blows up ends there, with a bracketed global bifurcation.
    Of a symmetric model, the family of a Hopf point that mirrors an earlier one is that one's
    mirror image (:mod:`.mirror`), not computed again.
    """
    model = engine.model
    width = bounds[1] - bounds[0]
    scale = np.asarray(model.state_scale, dtype=float)
    hopfs = [p for p in points if p.point_type == PointType.HB]
    sources = mirror_sources(model, hopfs, width, parameters)
    runs = {b.name: b.runs[-1] for b in equilibria}
    families: dict[int, FamilySide] = {}
    for k, hopf in enumerate(hopfs):
        if k in sources:
            continue
        constants = periodic_constants(model, numerics, parameter, bounds,
                                       hopf.period * model.time_scale)
        constants["UZSTOP"][AMPLITUDE] = GROWN_AMPLITUDE
        spec = RunSpec(f"{name}/periodic_{k + 1}.0", constants, BranchKind.PERIODIC,
                       _hopf_origin(hopf), (parameter,), restart=(runs[hopf.branch], hopf.label))
        families[k] = FamilySide(f"periodic_{k + 1}", hopf.period, spec, [], hopf=k, grows=True)

    continue_families(engine, list(families.values()), hopfs, width)
    # On too coarse a mesh AUTO can turn back along a family of long orbits and retrace it to
    # its own Hopf point (combined case 5 at 40 mesh intervals): such families are computed
    # once more on a finer mesh, kept if they then do not come back
    again = [replace(f, pieces=[], retries=0, refinements=0, spec=replace(
        f.spec, name=f"{name}/{f.name}m.0",
        constants=dict(f.spec.constants, NTST=RETRACE_MESH_FACTOR * f.spec.constants["NTST"])))
        for f in families.values() if _back_at_own_hopf(f, hopfs, width, scale)]
    continue_families(engine, again, hopfs, width)
    for family in again:
        if not _back_at_own_hopf(family, hopfs, width, scale):
            families[family.hopf] = family

    image = {**sources, **{j: k for k, j in sources.items()}}
    ended: dict[int, Ended] = {}
    reached: set[int] = set()
    for k in range(len(hopfs)):
        if k in reached or (k in sources and sources[k] not in ended):
            continue  # the same family, already reached from another Hopf point (or its image)
        side = _mirrored(ended[sources[k]], k, hopfs, image) if k in sources else \
            end_of(families[k], model, hopfs, bounds, numerics, equilibria, parameters)
        if side.returned_to is not None:  # and the image of the family, to the image point
            reached |= {side.returned_to} | ({image.get(side.returned_to, side.returned_to)}
                                             if k in image else set())
        ended[k] = side
    kept, found = collect(engine, name, bounds, parameters, hopfs,
                           [(side.branch, side.blowups()) for k, side in ended.items()
                            if k not in sources], skip_first=True)
    for k in sorted(set(ended) & set(sources)):
        source, branch = ended[sources[k]].branch, ended[k].branch
        found += [mirrored_point(p, branch) for p in found if p.branch == source.name]
        kept.append(branch)
    order = {f"periodic_{k + 1}": k for k in ended}
    kept.sort(key=lambda b: order[b.name])
    return kept, sorted(found, key=lambda p: order[p.branch])


def _hopf_origin(hopf: SpecialPoint) -> Origin:
    """The origin of the family of ``hopf``."""
    return Origin.at(hopf)


def _mirrored(side: Ended, k: int, hopfs: list[SpecialPoint], image: dict[int, int]
              ) -> Ended:
    """The family of Hopf point ``k``, the mirror image of ``side`` (that of k's image)."""
    returned = None if side.returned_to is None else image.get(side.returned_to,
                                                               side.returned_to)
    end = side.branch.end if returned is None else \
        _return_end(side.branch.parameter_names[0], hopfs, returned, own=returned == k)
    branch = mirrored_branch(side.branch, f"periodic_{k + 1}", _hopf_origin(hopfs[k]), end)
    return Ended(branch, None, returned)


def _return_end(parameter: str, hopfs: list[SpecialPoint], returned: int, own: bool) -> str:
    """The end of a family that returns to Hopf point ``returned`` (``own``: its start)."""
    hopf = hopfs[returned]
    which = "its own HB" if own else "HB"
    return f"returns to {which} at {parameter} = {hopf.parameters[0]:.6g} on {hopf.branch}"


def orbit_families(engine: Engine, name: str, parameter: str, bounds: tuple[float, float],
                   numerics: Numerics, starts: list[OrbitStart], equilibria: list[Branch],
                   points: list[SpecialPoint], parameters: dict[str, float]
                   ) -> tuple[list[Branch], list[SpecialPoint]]:
    """The periodic family through each start orbit (branch ``periodic_o<k>``), with its
    special points: AUTO starts from the orbit (IRS=0 and a data file, the period in PAR(11))
    and continues it both ways, fold by fold, to its ends, as :func:`periodic_families` does;
    the two sides are one branch, the first side reversed, ending where the start orbit sits.
    ``points``: the equilibria's special points (a family shrinking onto one of their Hopf
    points ends there)."""
    model = engine.model
    width = bounds[1] - bounds[0]
    hopfs = [p for p in points if p.point_type == PointType.HB]
    sides = []
    for k, start in enumerate(starts, 1):
        period_tau = start.orbit.period * model.time_scale
        for direction, tag in ((-1, "a"), (1, "b")):
            constants = periodic_constants(model, numerics, parameter, bounds, period_tau)
            constants.update(IRS=0, STOP=["LP1"], DS=direction * abs(constants["DS"]),
                             LAB=1 if direction < 0 else SECOND_SIDE_LABEL)
            constants["PAR"] = {**parameters, parameter: float(start.value),
                                "PERIOD": period_tau}
            spec = RunSpec(f"{name}/periodic_o{k}{tag}.0", constants, BranchKind.PERIODIC,
                           start.origin, (parameter,), data=orbit_data(model, start.orbit))
            sides.append(FamilySide(f"periodic_o{k}", start.orbit.period, spec, []))
    continue_families(engine, sides, hopfs, width)
    families = []
    for first, second in zip(sides[::2], sides[1::2], strict=True):
        a, b = (end_of(side, model, hopfs, bounds, numerics, equilibria, parameters)
                for side in (first, second))
        families.append((_two_sided(a.branch, b.branch), a.blowups() + b.blowups()))
    return collect(engine, name, bounds, parameters, hopfs, families, skip_first=False)


def _two_sided(a: Branch, b: Branch) -> Branch:
    """One branch from the two sides of a family started at an orbit: ``a`` reversed, then
    ``b`` (both start with the same converged orbit); its end says both sides' ends."""
    if not len(a) or not len(b):  # a side failed: the other one, with both ends said
        whole = b if len(b) else a
    else:
        whole = join(reverse(a), b, a.name)
    end = a.end if a.end == b.end else f"{a.end}{OTHER_END}{b.end}"
    return replace(whole, end=end)


@dataclass(frozen=True)
class Ended:
    """One side of a family, assembled: its branch (``end`` set), the global bifurcation its
    period blows up at (if so) and the index of the Hopf point it returns to (if so)."""

    branch: Branch
    global_point: SpecialPoint | None
    returned_to: int | None

    def blowups(self) -> list[tuple[SpecialPoint, Branch]]:
        """(global point, the side to locate it from) pairs: none or one."""
        return [] if self.global_point is None else [(self.global_point, self.branch)]


def end_of(family: FamilySide, model: Model, hopfs: list[SpecialPoint], bounds: tuple[float, float],
         numerics: Numerics, equilibria: list[Branch], parameters: dict[str, float]) -> Ended:
    """Assemble ``family``'s pieces and say how it ends: a Hopf point, a period blow-up (a
    bracketed global bifurcation; never for a family that ends on a Hopf point, whose period
    is that point's), the range, ..."""
    width = bounds[1] - bounds[0]
    scale = np.asarray(model.state_scale, dtype=float)
    whole, returned_to = _assembled(family, hopfs, width, scale)
    end, returned_to = _periodic_end(whole, model, hopfs, bounds, numerics, family, returned_to)
    global_point = None if returned_to is not None else global_bifurcations.analyse(
        whole, model, parameters, equilibria, family.period, width)
    if global_point is not None:
        end = f"period blow-up: {PointType(global_point.point_type).name.lower()} approach"
        if whole.status == RunStatus.MX:  # AUTO's expected failure right at the blow-up
            whole = replace(whole, status=RunStatus.OK, message="ended with MX at the period "
                            "blow-up (expected near a global bifurcation)")
    return Ended(replace(whole, end=end), global_point, returned_to)


def collect(engine: Engine, name: str, bounds: tuple[float, float],
             parameters: dict[str, float], hopfs: list[SpecialPoint],
             families: list[tuple[Branch, list[tuple[SpecialPoint, Branch]]]],
             skip_first: bool) -> tuple[list[Branch], list[SpecialPoint]]:
    """The families' branches and special points: each family's global bifurcations (those
    of homoclinic type located with HomCont from the side they were found on), then its
    bifurcations, except its first point if ``skip_first`` (a Hopf start) and points where
    it has shrunk onto a Hopf point."""
    model = engine.model
    width = bounds[1] - bounds[0]
    scale = np.asarray(model.state_scale, dtype=float)
    kept: list[Branch] = []
    found: list[SpecialPoint] = []
    homoclinic: list[tuple[int, Branch]] = []  # (row in found, side) to locate with HomCont
    for whole, blowups in families:
        for point, side in blowups:
            found.append(point)
            if point.point_type == PointType.HOMOCLINIC:
                homoclinic.append((len(found) - 1, side))
        kept.append(whole)
        small = amplitude(whole, model) < HOPF_RETURN_AMPLITUDE
        found += [p for p in special_points(whole, skip_first=skip_first)
                  if not small[p.index] and hopf_at(whole, p.index, hopfs, width, scale) is None]
    for row, point in zip([row for row, _ in homoclinic], locate_homoclinics(
            engine, name, [(side, found[row]) for row, side in homoclinic], bounds,
            parameters), strict=True):
        found[row] = point
    return kept, found


def orbit_data(model: Model, orbit: Orbit) -> str:
    """One period of ``orbit`` as an AUTO data file: rows ``tau u1 .. un`` in AUTO's
    non-dimensional units (see :mod:`whirl_cli.models.variant`), to 12 significant digits: a
    simulated orbit is good to about 1e-9, and the digits beyond are round-off that differs
    between machines (their BLAS kernels), which AUTO's path through a difficult stretch of
    the family can follow."""
    scale = np.asarray(model.state_scale, dtype=float)
    rows = np.column_stack([np.asarray(orbit.time) * model.time_scale,
                            np.asarray(orbit.states) / scale])
    return "".join(" ".join(f"{x:.12g}" for x in row) + "\n" for row in rows)


def continue_families(engine: Engine, families: list[FamilySide], hopfs: list[SpecialPoint],
              width: float) -> None:
    """Run every family's segments: each family's one after another (a segment starts where
    the last one ended), the families side by side, each as soon as its last segment is read
    (no family waits for another's; the engine runs at most its ``jobs`` at once)."""
    def grow(family: FamilySide) -> None:
        spec = family.spec
        while spec is not None:
            outcome, = engine.run_many([spec])
            family.pieces.append(read_run(engine, spec, outcome))
            spec = _next_segment(family, engine.model, hopfs, width)

    thread_map(grow, families, len(families))


def _back_at_own_hopf(family: FamilySide, hopfs: list[SpecialPoint], width: float,
                      scale: np.ndarray) -> bool:
    """True if the family, grown, has come back onto the Hopf point it started from."""
    whole = _assemble(family, hopfs, width, scale)
    return len(whole) > 3 and hopf_at(whole, len(whole) - 1, hopfs, width,
                                       scale) == family.hopf


def _assemble(family: FamilySide, hopfs: list[SpecialPoint], width: float,
              scale: np.ndarray) -> Branch:
    """One branch from a family's pieces, cut after the first point beyond the period cap
    (AUTO can step over that stop while it locates a fold there) or the first return to a
    Hopf point."""
    return _assembled(family, hopfs, width, scale)[0]


def _assembled(family: FamilySide, hopfs: list[SpecialPoint], width: float,
               scale: np.ndarray) -> tuple[Branch, int | None]:
    """:func:`_assemble`, and the index of the Hopf point the family first returns to (judged
    on the whole of its pieces, where the family's size is that of all of it), if any."""
    whole = family.pieces[0]
    for piece in family.pieces[1:]:
        if len(piece):
            whole = join(whole, piece, whole.name)
    whole = replace(whole, name=family.name)
    ends = list(np.flatnonzero(whole.period > PERIOD_CAP * family.period)[:1])
    returned = _first_return(whole, hopfs, width, scale, family.grows)
    returned_to = None
    if returned is not None:
        ends.append(returned)
        returned_to = hopf_at(whole, returned, hopfs, width, scale)
    if ends and min(ends) + 1 < len(whole):
        if returned is not None and min(ends) < returned:
            returned_to = None  # the period cap came first
        whole = head(whole, min(ends) + 1)
    return whole, returned_to


def _first_return(branch: Branch, hopfs: list[SpecialPoint], width: float,
                  scale: np.ndarray, grows: bool = True) -> int | None:
    """First row where a family has shrunk onto a Hopf point (AUTO may pass through a Hopf
    point without stopping there and go round the family again): after it has grown, for a
    family that ``grows`` from a Hopf point, else after its first row (an orbit start). Sizes
    are in AUTO's units (``scale``), so that no dof counts more for its unit."""
    size = ((branch.state_max - branch.state_min) / (2 * scale)).max(axis=1)
    grown = np.flatnonzero(size > 0.5 * size.max()) if grows else np.arange(1, len(branch))
    if not len(grown):
        return None
    for row in range(int(grown[0]), len(branch)):
        if hopf_at(branch, row, hopfs, width, scale) is not None:
            return row
    return None


def hopf_at(branch: Branch, row: int, hopfs: list[SpecialPoint], width: float,
             scale: np.ndarray) -> int | None:
    """Index of the Hopf point the orbit at ``row`` has shrunk onto, if any: a small orbit
    (in AUTO's non-dimensional units, ``scale`` = the model's state scale) centred on that Hopf
    point's equilibrium."""
    size = ((branch.state_max - branch.state_min) / (2 * scale)).max(axis=1)
    if size[row] > max(5e-3, 0.05 * size.max()):
        return None
    centre = 0.5 * (branch.state_max[row] + branch.state_min[row]) / scale
    for k, hopf in enumerate(hopfs):
        if abs(hopf.parameters[0] - branch.parameters[row, 0]) < 2e-3 * width and np.allclose(
                hopf.state / scale, centre, rtol=0, atol=2e-3 + 2 * size[row]):
            return k
    return None


def _next_segment(family: FamilySide, model: Model, hopfs: list[SpecialPoint],
                  width: float) -> RunSpec | None:
    """The run continuing ``family`` after its last piece, or None if the family has ended."""
    piece = family.pieces[-1]
    if piece.status == RunStatus.MX:
        return _retry(family, piece) if family.retries < MAX_RETRIES and \
            family.refinements < MAX_REFINEMENTS else None
    family.retries = 0
    scale = np.asarray(model.state_scale, dtype=float)
    if not len(piece) or piece.status != RunStatus.OK or len(family.pieces) >= MAX_SEGMENTS:
        return None
    last = PointType(int(piece.point_type[-1]))
    if family.grows and len(family.pieces) == 1:
        grown = last == PointType.UZ and abs(amplitude(piece, model)[-1] - GROWN_AMPLITUDE) \
            < 1e-3 * GROWN_AMPLITUDE
        if not grown:
            return None
    elif last != PointType.LPC or \
            _first_return(piece, hopfs, width, scale, family.grows) is not None or \
            hopf_at(piece, len(piece) - 1, hopfs, width, scale) is not None or \
            family.stop is not None and family.stop(piece, len(piece) - 1):
        return None  # an end (range, amplitude, period, steps), back at a Hopf point, its own
    if global_bifurcations.in_blowup(piece, family.period) and \
            global_bifurcations.blowup_turns(*_columns(family), family.period) \
            >= global_bifurcations.BRACKET_TURNS:
        return None
    return replace(family.spec, name=f"{family.spec.name.rsplit('.', 1)[0]}."
                   f"{len(family.pieces)}", constants=_segment_constants(family),
                   restart=(piece.runs[-1], int(piece.label[-1])), data=None)


def _segment_constants(family: FamilySide, **changes) -> dict:
    """Constants of a run that continues ``family`` from a labelled point of its last piece:
    its first run's (the sign of DS with them: AUTO goes on in the direction the restart
    point was reached), to the next fold of cycles, without a Hopf start's amplitude stop, an
    orbit start's parameter values and first label (they would replace the restart point's)
    or a branch switch (ISW=1: the restart point is a regular one)."""
    constants = {key: value for key, value in family.spec.constants.items()
                 if key not in ("PAR", "LAB")}
    constants.update(STOP=["LP1"], ISW=1, **changes)
    constants["UZSTOP"] = {k: v for k, v in constants["UZSTOP"].items() if k != AMPLITUDE}
    return constants


def _columns(family: FamilySide) -> tuple[np.ndarray, np.ndarray]:
    """(principal parameter, period) along the family's pieces so far (a restart repeats the
    point it starts from: a zero step, which counts as no turn)."""
    return (np.concatenate([p.parameters[:, 0] for p in family.pieces]),
            np.concatenate([p.period for p in family.pieces]))


def _retry(family: FamilySide, piece: Branch) -> RunSpec | None:
    """After MX (no convergence): restart from the last good labelled point of the piece with
    twice the mesh intervals and half the largest step; the piece is cut back to that point.
    A retry that failed before its first label is dropped and the family restarts from the
    label before the one that retry started from."""
    row = last_good_label(piece)
    if row is None and family.retries and len(family.pieces) > 1:
        family.pieces.pop()
        piece = family.pieces[-1]
        row = last_good_label(piece, len(piece) - 1)
    if row is None or global_bifurcations.in_blowup(piece, family.period):
        return None
    family.pieces[-1] = head(piece, row + 1)
    family.retries += 1
    family.refinements += 1
    # the family keeps the finer mesh for its later segments: back on the coarse one, the
    # next segment fails where the last one did
    first = family.spec.constants
    family.spec = replace(family.spec, constants=dict(
        first, NTST=2 * first["NTST"], DSMAX=first["DSMAX"] / 2))
    return replace(family.spec, name=f"{family.spec.name.rsplit('.', 1)[0]}."
                   f"{len(family.pieces)}r{family.retries}",
                   constants=_segment_constants(family),
                   restart=(piece.runs[-1], int(piece.label[row])), data=None)


def _periodic_end(family: Branch, model: Model, hopfs: list[SpecialPoint],
                  bounds: tuple[float, float], numerics: Numerics,
                  state: FamilySide, returned_to: int | None = None) -> tuple[str, int | None]:
    """Why a periodic family ends, and the index of the Hopf point it returns to (if so;
    ``returned_to``: the one :func:`_assembled` found, if its last point does not say)."""
    if not len(family):
        return f"failed: {family.message}", None
    width = bounds[1] - bounds[0]
    scale = np.asarray(model.state_scale, dtype=float)
    value = family.parameters[-1, 0]
    returned = hopf_at(family, len(family) - 1, hopfs, width, scale) if len(family) > 3 else None
    if returned is None:
        returned = returned_to
    if returned is not None:
        return _return_end(family.parameter_names[0], hopfs, returned,
                           returned == state.hopf), returned
    if family.point_type[-1] == PointType.MX:
        return "no convergence (MX)", None
    stopped = state.stop(family, len(family) - 1) if state.stop is not None else ""
    if stopped:
        return stopped, None
    if family.period[-1] >= 0.999 * PERIOD_CAP * state.period:
        return "period cap", None
    if min(abs(value - bounds[0]), abs(value - bounds[1])) < 1e-6 * width:
        return "range", None
    watched = list(model.positions)  # in typical amplitudes, as the UZSTOP bound
    reach = (np.abs(np.concatenate([family.state_max[-1, watched],
                                    family.state_min[-1, watched]]))
             / np.tile(np.asarray(scale)[watched], 2)).max()
    if reach >= 0.999 * numerics.max_amplitude:
        return "amplitude bound", None
    if len(state.pieces) >= MAX_SEGMENTS:
        return f"fold limit ({MAX_SEGMENTS} segments)", None
    if state.pieces and len(state.pieces[-1]) >= numerics.max_steps:
        return STEP_LIMIT, None
    return "AUTO end point", None

