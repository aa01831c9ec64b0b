"""Result types shared by the pipeline: branches, special points, orbits, linear sweeps.

All are frozen dataclasses holding numpy columns (one array per quantity, one row per point), in
SI units with physical time: angles in rad, rates in rad/s, periods in s, eigenvalues in 1/s.
``auto/parse.py`` builds them from AUTO's files, ``output/store.py`` writes and reads them,
``plots/`` draws them; none of those modules change them.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, fields, is_dataclass
from enum import IntEnum

import numpy as np

from .kinds import (
    BoundaryMethod,
    BranchKind,
    CheckKind,
    ContinuationKind,
    Criticality,
    LocateStatus,
    LocusKind,
    MotionKind,
    RunStatus,
    SeedKind,
    SimulationLaw,
    Spacing,
    UnsafeCause,
)

#: re-exported: the vocabulary results are written in
__all__ = ["BoundaryMethod", "BranchKind", "CheckKind", "ContinuationKind", "Criticality",
           "LocateStatus", "LocusKind", "MotionKind", "RunStatus", "SeedKind", "SimulationLaw",
           "Spacing", "UnsafeCause"]


def _brief(value) -> str:
    """A field's value in a short repr: an array as its shape and type, a collection of
    results as its length, long text cut."""
    if isinstance(value, np.ndarray):
        return f"<{' x '.join(map(str, value.shape)) or 'scalar'} {value.dtype}>"
    if isinstance(value, tuple | list) and value and is_dataclass(value[0]):
        return f"<{len(value)} {type(value[0]).__name__}>"
    if isinstance(value, dict) and len(repr(value)) > 60:
        return f"<{len(value)} entries>"
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:56]}...{text[-1]}"


def _brief_repr(self) -> str:
    """``Class(field=value, ...)`` with arrays and collections summarised (:func:`_brief`)."""
    shown = ", ".join(f"{f.name}={_brief(getattr(self, f.name))}" for f in fields(self)
                      if f.repr)
    return f"{type(self).__name__}({shown})"


def _tally(codes) -> str:
    """The special points among point type ``codes``, counted by type in order of first
    appearance: "2 HB, 1 BP" ("none")."""
    counts: dict[str, int] = {}
    for code in np.asarray(codes).ravel():
        try:
            kind = PointType(int(code))
        except ValueError:
            counts[str(int(code))] = counts.get(str(int(code)), 0) + 1
            continue
        if kind.is_special:
            counts[kind.name] = counts.get(kind.name, 0) + 1
    return ", ".join(f"{n} {name}" for name, n in counts.items()) or "none"


def _named(members, name: str, what: tuple[str, str], owner: str):
    """The member of ``members`` called ``name``; KeyError listing the names there are
    (``what``: the members' noun, singular and plural)."""
    for member in members:
        if member.name == name:
            return member
    known = ", ".join(repr(m.name) for m in members) or "none"
    raise KeyError(f"no {what[0]} {name!r} in {owner} ({what[1]}: {known})")


def _html_table(caption: str, header: tuple[str, ...], rows) -> str:
    """A small HTML table (the notebook view of a result)."""
    from html import escape

    head = "".join(f"<th>{escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{escape(str(c))}</td>" for c in row) + "</tr>"
                   for row in rows)
    return (f"<table><caption style='text-align:left'><b>{escape(caption)}</b></caption>"
            f"<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>")


class PointType(IntEnum):
    """Point types: AUTO's TY codes (mod 10 on loci), plus whirl's own for global bifurcations.

    Equilibria: BP (branch point / pitchfork), LP (fold), HB (Hopf). Periodic orbits: LPC (fold of
    cycles), BPC (branch point of cycles), PD (period doubling), TR (torus). Both: RG (labelled
    regular point), UZ (user point or stop), EP (end point), MX (no convergence).
    Codimension 2 on loci: BT, CP, ZH, GH, R1..R4. HOMOCLINIC/HETEROCLINIC: period blow-up
    detected by whirl (not an AUTO code).
    """

    REGULAR = 0
    BP = 1
    LP = 2
    HB = 3
    RG = 4
    LPC = 5
    BPC = 6
    PD = 7
    TR = 8
    EP = 9
    UZ = -4
    MX = -9
    BT = -1
    CP = -2
    ZH = -3
    R1 = -5
    R2 = -6
    R3 = -7
    R4 = -8
    GH = -32
    LTR = 23
    PTR = 77
    LPD = 28
    TTR = 88
    HOMOCLINIC = 101
    HETEROCLINIC = 102

    @classmethod
    def from_auto(cls, ty: int) -> PointType:
        """Normalise an AUTO TY code (e.g. 30 on a Hopf locus is a regular point)."""
        specials = {-32: cls.GH, 23: cls.LTR, 83: cls.LTR, 77: cls.PTR, 87: cls.PTR,
                    28: cls.LPD, 78: cls.LPD, 88: cls.TTR}
        if ty in specials:
            return specials[ty]
        rest = abs(ty) % 10
        return cls(-rest if ty < 0 else rest)

    @property
    def is_special(self) -> bool:
        """Bifurcations worth listing (not regular, user, end or no-convergence points)."""
        return self not in (PointType.REGULAR, PointType.RG, PointType.UZ, PointType.EP,
                            PointType.MX)


def _type_name(code) -> str:
    try:
        return PointType(int(code)).name
    except ValueError:
        return str(int(code))


def _is_special(code) -> bool:
    try:
        return PointType(int(code)).is_special
    except ValueError:
        return True


@dataclass(frozen=True)
class Orbit:
    """One stored solution profile (a labelled AUTO solution), states in SI units.

    ``time``: (K,) in s from 0 to the period (a single point for equilibria); ``states``: (K, n).
    """

    label: int
    point_type: int
    index: int  # row of the point on its branch
    parameters: np.ndarray  # (P,) values of the branch's parameter_names
    period: float  # s, NaN for equilibria
    time: np.ndarray
    states: np.ndarray

    __repr__ = _brief_repr


#: The text form of an :class:`Origin` at a special point (its optional note after ", ").
_AT_POINT = re.compile(r"(?P<point>[A-Z0-9]+) at (?P<parameter>\S+) = (?P<value>\S+) "
                       r"on (?P<branch>[^\s,]+)(?:, (?P<note>.*))?", re.DOTALL)


@dataclass(frozen=True)
class Origin:
    """Where a branch starts: at the special point ``point`` of branch ``branch``, where the
    principal parameter ``parameter`` = ``value``, with ``note`` saying more (e.g. the
    smoothing of a short run); or, without a point, as ``note`` says (e.g. "start at K1 =
    0.5"). ``str()`` is the text a result file stores (:meth:`parse` reads it back)."""

    note: str = ""
    point: PointType | None = None
    parameter: str = ""
    value: float | None = None
    branch: str = ""

    @classmethod
    def at(cls, point: SpecialPoint, note: str = "") -> Origin:
        """The origin of a branch started at ``point`` (in its principal parameter)."""
        return cls(note, PointType(point.point_type), point.parameter_names[0],
                   float(point.parameters[0]), point.branch)

    @classmethod
    def parse(cls, text: str) -> Origin:
        """The origin whose text form is ``text`` (only the note if it names no point)."""
        found = _AT_POINT.fullmatch(text)
        if found and found["point"] in PointType.__members__:
            try:
                origin = cls(found["note"] or "", PointType[found["point"]],
                             found["parameter"], float(found["value"]), found["branch"])
            except ValueError:
                return cls(text)
            if str(origin) == text:
                return origin
        return cls(text)

    def __str__(self) -> str:
        if self.point is None:
            return self.note
        text = f"{self.point.name} at {self.parameter} = {self.value:.6g} on {self.branch}"
        return f"{text}, {self.note}" if self.note else text


#: :attr:`Branch.end` of a branch that used up its study's ``max_steps`` (AUTO's NMX) before
#: reaching any other end: a truncated branch, which makes the study fail
#: (:mod:`whirl_cli.verdict`).
STEP_LIMIT = "step limit"
#: Between the two ends in :attr:`Branch.end` of a branch traced both ways from its start.
OTHER_END = "; other end: "


@dataclass(frozen=True)
class Branch:
    """One continuation branch (one AUTO run), N points.

    Attributes
    ----------
    name : unique id within its continuation, e.g. "main_down", "secondary_1_up", "periodic_2".
    kind : one of :class:`BranchKind`.
    origin : where it started (:class:`Origin`), e.g. "start at K1 = 0.5",
        "BP at K1 = 0.0359815 on main_down".
    parameter_names : continuation parameters, principal first; ``parameters``: (N, P) values.
    state_names, state_units : the model's states and their SI units.
    state_max, state_min : (N, n) max and min of each state over the orbit (equilibria: equal).
    l2_norm : (N,) AUTO's L2 norm of its (non-dimensional) solution.
    period : (N,) s, NaN for equilibria.
    stable : (N,) bool, AUTO's stability flag (the sign of PT in its b-file); a verdict only
        where ``stability_known``.
    point_type : (N,) int, :class:`PointType` codes; label : (N,) int AUTO label (0 = none).
    eigenvalues : (N, n) complex: Jacobian eigenvalues in 1/s for equilibria, Floquet multipliers
        for periodic orbits (NaN where AUTO printed none).
    status, message : how the AUTO run ended (ok | mx | error | timeout | crashed).
    orbits : stored profiles of labelled solutions (periodic branches; on torus loci the cycle,
        the first n components of AUTO's extended solution).
    end : why the branch ends (range, amplitude bound, return to a Hopf point, period blow-up,
        step limit, no convergence).
    stability_known : (N,) bool, False where the stability is unknown: AUTO printed no (or only
        NaN) eigenvalues or Floquet multipliers there (typically the first point of a periodic
        family started at a Hopf point), and everywhere on loci, where it is undefined. None
        (the default) means known everywhere.
    torus_angle : (N,) rad, on torus (TR) loci only (None elsewhere): the angle in [0, pi] of
        the complex pair of Floquet multipliers exp(+-i angle) on the unit circle there, from
        AUTO's PAR(12) (the torus's second frequency is angle / (2 pi period)).
    """

    name: str
    kind: BranchKind
    origin: Origin
    parameter_names: tuple[str, ...]
    parameter_units: tuple[str, ...]
    state_names: tuple[str, ...]
    state_units: tuple[str, ...]
    parameters: np.ndarray
    state_max: np.ndarray
    state_min: np.ndarray
    l2_norm: np.ndarray
    period: np.ndarray
    stable: np.ndarray
    point_type: np.ndarray
    label: np.ndarray
    eigenvalues: np.ndarray
    status: RunStatus = RunStatus.OK
    message: str = "ok"
    runs: tuple[str, ...] = ()  # the AUTO runs that made it (several for a joined branch)
    orbits: tuple[Orbit, ...] = field(default=())
    end: str = ""  # how the branch ends, e.g. "range", "returns to HB at K1 = 0.0807"
    stability_known: np.ndarray | None = None
    torus_angle: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.stability_known is None:  # frozen: set through object
            object.__setattr__(self, "stability_known", np.ones(len(self.stable), dtype=bool))

    def __len__(self) -> int:
        return len(self.point_type)

    @property
    def truncated(self) -> bool:
        """True if the branch (at one of its ends) stopped at its study's step limit."""
        return STEP_LIMIT in self.end.split(OTHER_END)

    def parameter(self, name: str) -> np.ndarray:
        return self.parameters[:, self.parameter_names.index(name)]

    def state(self, name: str, which: str = "max") -> np.ndarray:
        table = self.state_max if which == "max" else self.state_min
        return table[:, self.state_names.index(name)]

    @property
    def is_periodic(self) -> bool:
        return self.kind == BranchKind.PERIODIC

    def __repr__(self) -> str:
        return (f"Branch({self.name!r}, kind={self.kind!r}, points={len(self)}, "
                f"parameters={self.parameter_names!r}, special points: "
                f"{_tally(self.point_type)}, status={self.status!r})")

    def _repr_html_(self) -> str:
        rows = [(k, _type_name(self.point_type[k]), *(f"{v:.6g}" for v in self.parameters[k]),
                 "yes" if self.stable[k] else "no") for k in range(len(self))
                if _is_special(self.point_type[k])]
        return _html_table(f"branch {self.name} ({self.kind}, {len(self)} points, "
                           f"{self.status}): special points",
                           ("point", "type", *self.parameter_names, "stable"), rows)

    def to_dataframe(self):
        """The branch as a pandas DataFrame: one row per point, one column per quantity and
        state (``K_theta [N m/rad]``, ``theta max [rad]``, ``eigenvalue 1 [1/s]``, ...)."""
        from .export.frames import dataframe
        from .export.tables import branch_table

        return dataframe(branch_table(self))

    def to_xarray(self):
        """The branch as an xarray Dataset over the dimensions ``point``, ``parameter``,
        ``state`` and ``mode`` (as ``whirl export -o OUT.nc`` writes it)."""
        from .export.frames import dataset
        from .export.tables import branch_table

        return dataset(branch_table(self))


def slice_branch(k: int, name: str) -> str:
    """The name in its two-parameter continuation of branch ``name`` of slice ``k`` (from
    0): ``slice_<k>.<name>``; :func:`on_slice` reads it back."""
    return f"slice_{k}.{name}"


def on_slice(name: str, k: int) -> str | None:
    """The name on slice ``k`` of the branch ``name`` (made by :func:`slice_branch`); None if
    it is not a branch of that slice (another slice's, a locus)."""
    head, dot, rest = name.partition(".")
    return rest if dot and head == f"slice_{k}" else None


@dataclass(frozen=True)
class SpecialPoint:
    """A bifurcation or notable end on a branch.

    ``status``: located (AUTO converged on it), bracketed (estimated between points, e.g.
    a period blow-up, with ``bracket`` the interval of the principal parameter and ``residual``
    the relative fit residual) or rejected (AUTO labelled it, but its own check says it
    is not that kind of point, e.g. a TR point without a pair of Floquet multipliers on the
    unit circle; ``note`` says why). ``criticality``: supercritical |
    subcritical | unknown (Hopf points: from the periodic family leaving it, else from
    ``lyapunov``). ``lyapunov``: first Lyapunov coefficient of a Hopf point of equilibria
    [1/(s unit^2), SI states; < 0 supercritical], NaN otherwise (see
    :mod:`whirl_cli.analysis.normal_form`).
    """

    branch: str
    index: int
    point_type: int
    parameter_names: tuple[str, ...]
    parameters: np.ndarray
    state: np.ndarray  # (n,) equilibrium state, or max over the orbit for periodic points
    period: float
    stable: bool
    label: int = 0
    status: LocateStatus = LocateStatus.LOCATED
    criticality: Criticality = Criticality.UNKNOWN
    note: str = ""
    bracket: np.ndarray = field(default_factory=lambda: np.full(2, np.nan))  # bracketed only
    residual: float = float("nan")  # relative rms fit residual (bracketed global points)
    lyapunov: float = float("nan")  # first Lyapunov coefficient (Hopf points of equilibria)
    parameter_units: tuple[str, ...] = ()  # of parameter_names; () in schema-1 files
    #: the principal parameter recomputed with every smoothing width halved and quartered
    #: (laws that smooth a piecewise one, e.g. freeplay; NaN: not recomputed or not found)
    refined: np.ndarray = field(default_factory=lambda: np.full(2, np.nan))
    artefact: bool = False  # does not persist as the smoothing shrinks (see ``note``)
    #: how ``refined`` was computed: "restart", "epsilon locus" (short runs near the point,
    #: :mod:`whirl_cli.continuation.shrinking`), "bracketing folds" (a snaking global point,
    #: from its family's recomputed folds), "repetition" (the continuation repeated) or ""
    #: (not recomputed)
    refined_by: str = ""
    #: torus (TR, Neimark-Sacker) points: the angle in (0, pi) rad of the complex pair of
    #: Floquet multipliers on the unit circle, exp(+-i angle) (NaN: not TR, no multipliers)
    torus_angle: float = float("nan")

    @property
    def type_name(self) -> str:
        return PointType(self.point_type).name


@dataclass(frozen=True)
class LinearSweep:
    """Linear analysis along a sweep of one parameter (M points, n states).

    ``eigenvalues``: (M, n) complex [1/s]; ``damping_ratio``: (M, n) [-]; ``frequency``: (M, n)
    [rad/s]; ``whirl``: (M, n) str, "FW", "BW" or "--" for real eigenvalues. Modes are ordered by
    frequency per point. ``mode_group``: (M, n) str, the model's mode group holding most of
    each mode's energy (e.g. "nacelle", "gimbal"); None for a model with one group.
    ``datum``: the parameter's datum [``unit``] (None: not stored, files before it);
    ``multiples``: the study gave the sweep in multiples of it (``values`` are absolute all
    the same: ``values / datum`` are the multiples); ``spacing``: how ``values`` sample the
    range (log: a constant ratio).
    """

    parameter: str
    unit: str
    values: np.ndarray
    eigenvalues: np.ndarray
    damping_ratio: np.ndarray
    frequency: np.ndarray
    whirl: np.ndarray
    mode_group: np.ndarray | None = None
    datum: float | None = None
    multiples: bool = False
    spacing: Spacing = Spacing.LINEAR

    __repr__ = _brief_repr


@dataclass(frozen=True)
class LinearGrid:
    """Linear stability over a grid of two parameters (Nx x Ny points).

    ``max_real``: (Ny, Nx) largest real part of the eigenvalues [1/s] (> 0: unstable);
    ``oscillatory``: (Ny, Nx) True where that eigenvalue is complex (flutter), False where it
    is real (divergence). ``flutter`` and ``divergence``: the zero contour of ``max_real`` as
    polylines (K, 2) in (x, y), split by the kind of the critical eigenvalue along it.
    ``x_spacing``, ``y_spacing``: how ``x`` and ``y`` sample their ranges.
    """

    x_parameter: str
    y_parameter: str
    x_unit: str
    y_unit: str
    x: np.ndarray
    y: np.ndarray
    max_real: np.ndarray
    oscillatory: np.ndarray
    flutter: tuple[np.ndarray, ...]
    divergence: tuple[np.ndarray, ...]
    x_spacing: Spacing = Spacing.LINEAR
    y_spacing: Spacing = Spacing.LINEAR

    __repr__ = _brief_repr


@dataclass(frozen=True)
class UnsafeInterval:
    """Where, on one slice (second parameter = ``slice_value``), the first parameter lies in
    the unsafe region: linearly stable, yet flutter (``cause`` :attr:`UnsafeCause.FLUTTER`) or
    divergence (:attr:`UnsafeCause.DIVERGENCE`) exists for ``lower`` < first < ``upper``."""

    slice_value: float
    lower: float
    upper: float
    cause: UnsafeCause


@dataclass(frozen=True)
class Boundary:
    """The stability boundary and unsafe region of a two-parameter continuation.

    ``loci``: name -> (kind, curve (K, 2) in (first, second)); kinds hopf, branch_point, fold,
    fold_of_cycles. ``polygons``: closed (K, 2) outlines of the unsafe region. ``intervals``:
    the unsafe intervals per slice (``method``, a :class:`BoundaryMethod`, says how they were
    found).
    ``first_range``, ``second_range``: the parameters' ranges (NaN in older files).
    ``bounding_ends``: fold-of-cycles locus name -> whether its first and last points bound
    stable cycles (a locus not listed: both do, as in older files).
    """

    name: str
    parameter_names: tuple[str, str]
    parameter_units: tuple[str, str]
    method: BoundaryMethod
    loci: dict[str, tuple[LocusKind, np.ndarray]]
    intervals: tuple[UnsafeInterval, ...]
    polygons: tuple[np.ndarray, ...]
    slices: tuple[float, ...]
    first_range: tuple[float, float] = (np.nan, np.nan)
    second_range: tuple[float, float] = (np.nan, np.nan)
    bounding_ends: dict[str, tuple[bool, bool]] = field(default_factory=dict)

    __repr__ = _brief_repr


@dataclass(frozen=True)
class RunRecord:
    """Bookkeeping of one AUTO run, stored under /runs."""

    name: str
    status: RunStatus
    message: str
    constants: str
    returncode: int
    wall_seconds: float
    n_points: int


@dataclass(frozen=True)
class CrossCheck:
    """One time-simulation check of a point of a branch (``whirl_cli.analysis.simulate``).

    ``kind``: "orbit" (expected/simulated: max over the orbit of ``state``, the dof that
    moves most relative to its typical amplitude, SI units) or "equilibrium" (expected: the
    initial perturbation of every dof, simulated: the largest final deviation of one, both in
    units of the dofs' typical amplitudes; for the classical model rad). ``state``: "" in
    files written before whirl recorded it. ``exact``: for an orbit of a model with a
    piecewise law (freeplay), the same maximum from a simulation of the exact, unsmoothed law
    (``passed`` needs both within the tolerance); None otherwise and in older files (NaN in
    the HDF5 file).
    """

    branch: str
    index: int
    kind: CheckKind
    parameter: float
    expected: float
    simulated: float
    passed: bool
    state: str = ""
    exact: float | None = None


@dataclass(frozen=True)
class FreeplayAmplitudes:
    """A periodic branch in the units of a freeplay law on one of its dofs
    (:mod:`whirl_cli.analysis.freeplay`).

    ``amplitude_ratio`` (N,): A/delta per row of ``branch``, A the dof's half peak-to-peak
    value over the orbit and delta the law's half-gap at that row (both in the dof's unit).
    The describing-function estimate, ``estimate_ratio`` (M,) = A/delta, ``estimate_stiffness``
    (M,) = K_eq(A) (the stiffness's unit) and ``estimate_parameter`` (M,): a value of the
    branch's principal parameter at which the linear model with the dof's stiffness K_eq(A)
    has a Hopf point (one row per such point, sorted by A/delta); empty when the principal
    parameter is one of the law's own (delta, K_in, epsilon, K_out).
    """

    branch: str
    dof: str
    amplitude_ratio: np.ndarray
    estimate_ratio: np.ndarray
    estimate_stiffness: np.ndarray
    estimate_parameter: np.ndarray
    stiffness_unit: str = ""  # of estimate_stiffness: the dof's stiffness unit
    parameter_unit: str = ""  # of estimate_parameter: the branch's principal parameter's
    #: Hopf points of the linear model with the dof's stiffness at K_out, in that parameter
    #: (the linear flutter onset freeplay cycles undercut; empty where not computed)
    onset: np.ndarray = field(default_factory=lambda: np.empty(0))

    __repr__ = _brief_repr


@dataclass(frozen=True)
class SeedOutcome:
    """What became of one seed of a continuation (``whirl_cli.analysis.seeds``): ``seed``
    (n,) the initial state (SI), ``kind`` what it settled on (periodic | equilibrium |
    diverged | unsettled), ``period`` (s, periodic only, else NaN) and ``branch`` the
    family continued from it (``periodic_o<k>``; a seed that settled on an orbit another seed
    found names that family; "" for the others); ``message``: what the simulation saw."""

    index: int
    seed: np.ndarray
    kind: SeedKind
    period: float
    branch: str
    message: str


@dataclass(frozen=True)
class Exploration:
    """The settled motion at one ``explore:`` value of a one-parameter continuation, classified
    by simulation (:func:`whirl_cli.analysis.motion.classify_model`; the fields after
    ``initial`` are those of :class:`whirl_cli.analysis.motion.MotionClass`).

    ``value``: the continuation parameter ``parameter`` [``unit``] the study's parameters
    are simulated at; ``initial`` (n,): the initial state (SI); ``state_names``,
    ``state_units``: the model's states (of ``initial`` and the ``section`` columns);
    ``kind``: equilibrium | periodic | quasi-periodic | chaotic | diverged; ``lyapunov``,
    ``lyapunov_error``: the largest Lyapunov exponent and its standard error [1/s] (NaN if
    diverged); ``frequencies`` [Hz]: the fundamental of a periodic orbit, the two bases of a
    torus, the strongest peaks otherwise; ``section`` (m, n): Poincaré section points (SI
    states); ``section_dimension``: its correlation dimension (NaN: fewer than 10 points);
    ``multiplicity``: k of a period-k orbit (0 otherwise); ``peaks`` [Hz]: the spectral
    peaks, strongest first; ``broadband``: the fraction of the spectral power away from the
    peaks; ``evidence``: the readings in words (a failure of the simulation says so, with
    kind ``diverged``)."""

    value: float
    parameter: str
    unit: str
    state_names: tuple[str, ...]
    state_units: tuple[str, ...]
    initial: np.ndarray
    kind: MotionKind
    lyapunov: float
    lyapunov_error: float
    frequencies: np.ndarray
    section: np.ndarray
    section_dimension: float
    multiplicity: int
    peaks: np.ndarray
    broadband: float
    evidence: str

    __repr__ = _brief_repr


@dataclass(frozen=True)
class ContinuationResult:
    """Everything one continuation of a study produced. ``freeplay``: its periodic branches
    in the units of each freeplay law, with the describing-function estimate (one-parameter
    continuations of models with freeplay). ``seeds``: what its seeds settled on.
    ``explorations``: the motion classified by simulation at each ``explore:`` value."""

    name: str
    kind: ContinuationKind
    branches: tuple[Branch, ...]
    special_points: tuple[SpecialPoint, ...]
    cross_checks: tuple[CrossCheck, ...] = ()
    freeplay: tuple[FreeplayAmplitudes, ...] = ()
    seeds: tuple[SeedOutcome, ...] = ()
    explorations: tuple[Exploration, ...] = ()

    def branch(self, name: str) -> Branch:
        """The branch called ``name`` (KeyError, listing the branches, if none is)."""
        return _named(self.branches, name, ("branch", "branches"), f"continuation {self.name!r}")

    def __getitem__(self, name: str) -> Branch:
        return self.branch(name)

    def __iter__(self):
        return iter(self.branches)

    def __contains__(self, name: object) -> bool:
        return any(b.name == name for b in self.branches)

    def __repr__(self) -> str:
        return (f"ContinuationResult({self.name!r}, kind={self.kind!r}, branches="
                f"{[b.name for b in self.branches]!r}, points="
                f"{sum(len(b) for b in self.branches)}, special points: "
                f"{_tally([p.point_type for p in self.special_points])})")

    def _repr_html_(self) -> str:
        rows = [(b.name, b.kind, len(b), _tally(b.point_type), b.status, b.end)
                for b in self.branches]
        return _html_table(f"continuation {self.name} ({self.kind}): special points "
                           f"{_tally([p.point_type for p in self.special_points])}",
                           ("branch", "kind", "points", "special points", "status", "end"),
                           rows)


@dataclass(frozen=True)
class ParameterValue:
    """One model parameter as a study ran it: its ``value`` (the study's override, else the
    datum), the model's ``datum``, its ``unit``."""

    name: str
    value: float
    datum: float
    unit: str


@dataclass(frozen=True)
class Simulation:
    """A time simulation from a stated initial state (a study's ``simulations:`` entry,
    :func:`whirl_cli.analysis.simulate.simulation`).

    ``parameter_names``/``parameter_units``/``parameter_values`` (P,): the simulation's own
    overrides (canonical names, SI), applied on top of the study's parameter set;
    ``initial`` (n,): the initial state (SI); ``time`` (K,) s and ``states`` (K, n) SI: the
    samples (fewer than asked if the simulation stopped early); ``hub`` (K, 2): the hub
    displacement (y, z) normal to the spin axis as the model declares it (``Model.hub_matrix``
    @ state, classical: (-psi, -theta), i.e. up to the factor a R) in ``hub_unit``; ``law``:
    "smoothed" (the law AUTO continues) or "exact" (the unsmoothed piecewise law);
    ``status``/``message``: as scipy's ``solve_ivp`` (0: the whole duration; 1: stopped by an
    event, e.g. a dof beyond the divergence bound; -1: the integration failed)."""

    name: str
    law: SimulationLaw
    parameter_names: tuple[str, ...]
    parameter_units: tuple[str, ...]
    parameter_values: np.ndarray
    state_names: tuple[str, ...]
    state_units: tuple[str, ...]
    initial: np.ndarray
    time: np.ndarray
    states: np.ndarray
    hub: np.ndarray
    hub_unit: str
    status: int
    message: str
    first_order: tuple[str, ...] = ()  # the model's (the file's root attribute)

    __repr__ = _brief_repr

    @property
    def dof_names(self) -> tuple[str, ...]:
        """The states drawn by default: every state but the dofs' rates."""
        return positions(self.state_names, self.first_order)


@dataclass(frozen=True)
class FixedParameter:
    """A parameter a study sets: canonical name, value and unit (SI)."""

    name: str
    value: float
    unit: str


@dataclass(frozen=True)
class SliceLabel:
    """The label of slice ``index`` (from 0) of the two-parameter continuation
    ``continuation`` ("" where the study gives none)."""

    continuation: str
    index: int
    label: str


@dataclass(frozen=True)
class LawCurve:
    """The stiffness law on ``dof`` as a study ran it, drawn once when the result was made.

    ``law``: its name; ``coefficient_names``/``coefficient_values``: its coefficients (study
    keys, values in their units); ``linear``: the law is K x at these values. ``stiffness``:
    the dof's linear stiffness parameter, ``stiffness_value`` its value, ``force_unit`` the
    unit of the restoring force (the stiffness's times the dof's), ``dof_unit`` the dof's.
    ``breakpoints``: where the pieces of a piecewise law meet (none for a smooth law).
    ``x`` (K,) in the dof's unit, ``force`` (K,) the law as AUTO continues it, ``exact`` (K,)
    its exact piecewise form (None: the law is exact as it is); empty for a linear law.
    """

    dof: str
    law: str
    coefficient_names: tuple[str, ...]
    coefficient_values: tuple[float, ...]
    linear: bool
    stiffness: str
    stiffness_value: float
    force_unit: str
    dof_unit: str
    breakpoints: tuple[float, ...]
    x: np.ndarray
    force: np.ndarray
    exact: np.ndarray | None = None

    __repr__ = _brief_repr

    @property
    def coefficients(self) -> dict[str, float]:
        return dict(zip(self.coefficient_names, self.coefficient_values, strict=True))


@dataclass(frozen=True)
class Provenance:
    """Where a result came from: which whirl and AUTO, which study text and model file, and
    what of the study its figures name (fixed parameters, slice labels, laws).

    The text fields are the file's root attributes (``""``: not recorded). ``fixed``: the
    parameters the study sets, in the order written; ``slice_labels``: the labels of the
    slices of its two-parameter continuations; ``laws``: the law on every dof;
    ``plot_state``: the study's ``plot_state`` (""); ``dofs``: the model's dofs; ``family``:
    the model the study names (with ``laws``, the model variant that ran)."""

    whirl_version: str = ""
    whirl_code_sha256: str = ""
    git_describe: str = ""
    auto_version: str = ""
    created: str = ""
    study_yaml: str = ""
    study_sha256: str = ""
    model_file: str = ""
    model_file_yaml: str = ""
    model_file_sha256: str = ""
    model_key: str = ""
    first_order_states: str = ""  # comma-separated, as the file stores it
    fixed: tuple[FixedParameter, ...] = ()
    slices: tuple[SliceLabel, ...] = ()
    laws: tuple[LawCurve, ...] = ()
    plot_state: str = ""
    dofs: tuple[str, ...] = ()
    family: str = ""  # the study's ``model``: a built-in family, or the model file's reference

    __repr__ = _brief_repr

    @property
    def first_order(self) -> tuple[str, ...]:
        """The model's first-order states (none for a second-order model)."""
        return tuple(self.first_order_states.split(",")) if self.first_order_states else ()

    def slice_labels(self, continuation: str) -> tuple[str, ...]:
        """The labels of the slices of ``continuation``, in order (empty: none recorded)."""
        found = sorted((s.index, s.label) for s in self.slices
                       if s.continuation == continuation)
        return tuple(label for _, label in found)

    @property
    def nonlinear_laws(self) -> tuple[LawCurve, ...]:
        """The laws that are not a linear spring at the study's values."""
        return tuple(law for law in self.laws if not law.linear)

    def root_attributes(self) -> dict[str, str]:
        """The text fields that are recorded, by their root attribute's name."""
        return {f.name: getattr(self, f.name) for f in fields(self)
                if f.name in ROOT_FIELDS and getattr(self, f.name)}


#: The :class:`Provenance` fields stored as root attributes of a result file.
ROOT_FIELDS = ("whirl_version", "whirl_code_sha256", "git_describe", "auto_version", "created",
               "study_yaml", "study_sha256", "model_file", "model_file_yaml",
               "model_file_sha256", "model_key", "first_order_states")


def positions(state_names: tuple[str, ...], first_order: tuple[str, ...] = ()
              ) -> tuple[str, ...]:
    """The states that are not the rate of a dof: the dofs (the first half of the states
    before the first-order ones) and the first-order states ``first_order`` (the last)."""
    k = (len(state_names) - len(first_order)) // 2
    return tuple(state_names[:k]) + tuple(state_names[2 * k:])


@dataclass(frozen=True)
class StudyResult:
    """A whole study's results, as written to one HDF5 file."""

    study_name: str
    model: str
    continuations: tuple[ContinuationResult, ...]
    linear_sweeps: tuple[LinearSweep, ...]
    runs: tuple[RunRecord, ...]
    attributes: dict = field(default_factory=dict)  # other root attributes (e.g. plots)
    boundaries: tuple[Boundary, ...] = ()
    linear_grid: LinearGrid | None = None
    parameters: tuple[ParameterValue, ...] = ()  # the resolved set
    simulations: tuple[Simulation, ...] = ()  # the study's ``simulations:``; () in older files
    provenance: Provenance = field(default_factory=Provenance)

    def continuation(self, name: str) -> ContinuationResult:
        """The continuation called ``name`` (KeyError, listing them, if none is)."""
        return _named(self.continuations, name, ("continuation", "continuations"),
                      f"study {self.study_name!r}")

    def __getitem__(self, name: str) -> ContinuationResult:
        return self.continuation(name)

    def __iter__(self):
        return iter(self.continuations)

    def __contains__(self, name: object) -> bool:
        return any(c.name == name for c in self.continuations)

    def __repr__(self) -> str:
        parts = [f"{c.name} ({c.kind}, {len(c.branches)} branches, special points: "
                 f"{_tally([p.point_type for p in c.special_points])})"
                 for c in self.continuations]
        extra = [f"{label}: {', '.join(names)}" for label, names in (
            ("linear sweeps", [s.parameter for s in self.linear_sweeps]),
            ("boundaries", [b.name for b in self.boundaries]),
            ("simulations", [s.name for s in self.simulations])) if names]
        return (f"StudyResult({self.study_name!r}, model={self.model!r}, continuations: "
                f"{'; '.join(parts) or 'none'}" + "".join(f", {e}" for e in extra) + ")")

    def _repr_html_(self) -> str:
        rows = [(c.name, c.kind, len(c.branches), sum(len(b) for b in c.branches),
                 _tally([p.point_type for p in c.special_points])) for c in self.continuations]
        return _html_table(f"study {self.study_name} (model {self.model})",
                           ("continuation", "kind", "branches", "points", "special points"),
                           rows)

    @property
    def first_order(self) -> tuple[str, ...]:
        """The model's first-order states (the last states; none for a second-order model)."""
        return self.provenance.first_order

    def root_attributes(self) -> dict:
        """The root attributes of its file besides its name and model: the text fields of its
        provenance and :attr:`attributes`."""
        return {**self.attributes, **self.provenance.root_attributes()}
