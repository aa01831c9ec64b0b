"""whirl's vocabulary of kinds that several stages name, each declared once here (no imports
of whirl's); plot kinds are registered in :mod:`whirl_cli.plots.kinds`.

The enums' values are the words result files store and whirl prints: a value never changes.
"""

from __future__ import annotations

from enum import StrEnum


class Word(StrEnum):
    """A word of whirl's vocabulary: a str equal to its value, shown as that value (in
    reprs too, so that what whirl prints does not change with the type)."""

    def __repr__(self) -> str:
        return repr(self.value)


class BranchKind(Word):
    """What a branch (a run's curve) holds: equilibria, periodic orbits, or a locus of one
    kind of special point over two parameters; ``homoclinic`` is a HomCont run, never a
    stored branch."""

    EQUILIBRIUM = "equilibrium"
    PERIODIC = "periodic"
    HOPF_LOCUS = "hopf_locus"
    BRANCH_POINT_LOCUS = "branch_point_locus"
    FOLD_LOCUS = "fold_locus"
    FOLD_OF_CYCLES_LOCUS = "fold_of_cycles_locus"
    TORUS_LOCUS = "torus_locus"
    HOMOCLINIC = "homoclinic"

    @property
    def is_locus(self) -> bool:
        return self.value.endswith("_locus")


class LocusKind(Word):
    """The kind of special point a locus (a two-parameter curve) follows, as a boundary's
    ``loci`` name them; also the kind of a linear critical point (hopf, branch_point)."""

    HOPF = "hopf"
    BRANCH_POINT = "branch_point"
    FOLD = "fold"
    FOLD_OF_CYCLES = "fold_of_cycles"
    TORUS = "torus"


#: The kinds of locus (a two-parameter continuation's ``loci``) that bound the unsafe region
#: by folds: of equilibria and of cycles.
FOLD_LOCI = (LocusKind.FOLD, LocusKind.FOLD_OF_CYCLES)


class UnsafeCause(Word):
    """Why an interval of a slice is unsafe though linearly stable: stable limit cycles
    (flutter, between a Hopf and a fold-of-cycles locus) or offset equilibria (divergence,
    between a pitchfork and a fold locus)."""

    FLUTTER = "flutter"
    DIVERGENCE = "divergence"


class BoundaryMethod(Word):
    """How a boundary's unsafe intervals were found: from the locus curves on rows across the
    second parameter (loci) or from each slice's one-parameter branches (slices)."""

    LOCI = "loci"
    SLICES = "slices"


class Spacing(Word):
    """How a linear sweep or grid axis samples its range: evenly (linear) or with a constant
    ratio between neighbours (log, a positive range)."""

    LINEAR = "linear"
    LOG = "log"


class ContinuationKind(Word):
    """A study's continuation ``type``, and a result's continuation kind."""

    ONE_PARAMETER = "one-parameter"
    TWO_PARAMETER = "two-parameter"


class RunStatus(Word):
    """How an AUTO run ended (a branch's and a run record's ``status``)."""

    OK = "ok"
    MX = "mx"  # no convergence: the branch ends early
    ERROR = "error"
    TIMEOUT = "timeout"
    CRASHED = "crashed"


class Criticality(Word):
    """Of a Hopf point: the periodic family it starts is stable (supercritical) or unstable
    (subcritical); UNKNOWN (the empty text) for other points or where undecided."""

    SUPERCRITICAL = "supercritical"
    SUBCRITICAL = "subcritical"
    UNKNOWN = ""


class LocateStatus(Word):
    """How a special point was found: AUTO converged on it, it was estimated between points
    (a bracket), or AUTO labelled it but whirl's own check says it is not that point."""

    LOCATED = "located"
    BRACKETED = "bracketed"
    REJECTED = "rejected"


class MotionKind(Word):
    """What a simulated motion settled on (an ``explore:`` classification)."""

    EQUILIBRIUM = "equilibrium"
    PERIODIC = "periodic"
    QUASI_PERIODIC = "quasi-periodic"
    CHAOTIC = "chaotic"
    DIVERGED = "diverged"


class SeedKind(Word):
    """What a continuation's seed settled on."""

    PERIODIC = "periodic"
    EQUILIBRIUM = "equilibrium"
    DIVERGED = "diverged"
    UNSETTLED = "unsettled"


class CheckKind(Word):
    """What a cross-check simulates: an orbit of a periodic branch, or a perturbed
    equilibrium."""

    ORBIT = "orbit"
    EQUILIBRIUM = "equilibrium"


class SimulationLaw(Word):
    """The law a time simulation integrates: the smoothed one AUTO continues, or the exact
    piecewise one."""

    SMOOTHED = "smoothed"
    EXACT = "exact"


class SweepAction(Word):
    """What a sweep does with a study: run it, skip it (up to date), only plot it, or report
    it invalid."""

    RUN = "run"
    SKIP = "skip"
    PLOT = "plot"
    INVALID = "invalid"


class SweepStatus(Word):
    """What became of a study in a sweep."""

    OK = "ok"
    FAILED = "failed"  # stored, with problems
    SKIPPED = "skipped"
    PLOTTED = "plotted"
    INVALID = "invalid"
    ERROR = "error"  # no result: the task raised

    @property
    def failed(self) -> bool:
        return self in (SweepStatus.FAILED, SweepStatus.INVALID, SweepStatus.ERROR)
