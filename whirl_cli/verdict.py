"""What makes a study fail: the one failure policy of ``whirl run`` and ``whirl sweep``.

A study has *problems* (``whirl run`` exits 1, a sweep counts it failed) when

* a branch's AUTO run did not succeed (an error, a crash, a timeout, or MX = no convergence),
  except where whirl has judged the end natural: an MX at a period blow-up (the family's
  status is then "ok") and a locus ending in MX, which has mostly reached a degenerate point
  (a cusp of folds of cycles, a Bogdanov-Takens point) and is reported as a *note*;
* a branch is truncated: it used up the study's ``max_steps`` before reaching any other end
  (the end of its range, a Hopf point, ...);
* a time-simulation cross-check failed;
* a study simulation's integration failed (status -1; one stopped at the divergence bound,
  status 1, is a result, not a failure);
* its plots could not be drawn;
* a continuation's seeds found nothing and some of them could not be judged (their motion
  did not settle: ``unsettled``); where others led to a limit cycle, the summary's note on
  the unjudged seeds says the cycles found may not be all.

Either way the results are stored, with each branch's and run's status and message.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .kinds import FOLD_LOCI, BranchKind, RunStatus, SeedKind
from .results import (
    OTHER_END,
    STEP_LIMIT,
    Boundary,
    Branch,
    ContinuationResult,
    StudyResult,
)


@dataclass(frozen=True)
class Verdict:
    """``problems``: why the study failed (empty: it did not); ``notes``: worth saying."""

    problems: tuple[str, ...]
    notes: tuple[str, ...]


def is_problem(kind: BranchKind, status: RunStatus) -> bool:
    """True if a branch of ``kind`` that ended with run ``status`` makes the study fail."""
    return status != RunStatus.OK and not is_locus_mx(kind, status)


def is_locus_mx(kind: BranchKind, status: RunStatus) -> bool:
    """A locus ending in MX: a note, not a problem (see the module doc)."""
    return status == RunStatus.MX and kind.is_locus


def truncation(branch: Branch) -> str:
    """What a truncated branch is short of, said where it stops."""
    where = ""
    if branch.end == STEP_LIMIT and len(branch):  # one end: the last point
        where = " at " + ", ".join(f"{name} = {value:.6g}" for name, value in zip(
            branch.parameter_names, branch.parameters[-1], strict=True))
    elif branch.end != STEP_LIMIT:
        where = f" ({branch.end.replace(OTHER_END, ', other end: ')})"
    return (f"{branch.name} stopped at the step limit (auto: max_steps){where}, before the "
            "end of its range")


def unjudged_seeds(continuation: ContinuationResult) -> str:
    """What a continuation's unsettled seeds leave open ("" if none): how many, why the
    first could not be judged, and whether any other seed led to a limit cycle."""
    unsettled = [s for s in continuation.seeds if s.kind == SeedKind.UNSETTLED]
    if not unsettled:
        return ""
    found = any(s.kind == SeedKind.PERIODIC for s in continuation.seeds)
    return (f"{continuation.name}: {len(unsettled)} of {len(continuation.seeds)} seeds could "
            f"not be judged (seed {unsettled[0].index}: {unsettled[0].message}); "
            + ("the limit cycles found from the others may not be all" if found else
               "no other seed led to a limit cycle, so none was looked for"))


def seeds_found_nothing(continuation: ContinuationResult) -> bool:
    """True if some seeds could not be judged and none led to a limit cycle."""
    return any(s.kind == SeedKind.UNSETTLED for s in continuation.seeds) and not any(
        s.kind == SeedKind.PERIODIC for s in continuation.seeds)


def verdict(result: StudyResult, plot_error: str = "") -> Verdict:
    """The problems and notes of ``result`` (see the module doc); ``plot_error``: why its
    plots could not be drawn, if so (a problem too)."""
    branches = [b for c in result.continuations for b in c.branches]
    loci_mx = [b for b in branches if is_locus_mx(b.kind, b.status)]
    notes = tuple(f"locus {b.name} ends with MX (no convergence) "
                  + (f"at {', '.join(f'{v:.5g}' for v in b.parameters[-1])}" if len(b)
                     else "at its start") for b in loci_mx)
    problems = [f"{b.name} ({'+'.join(b.runs)}): {b.message}" for b in branches
                if is_problem(b.kind, b.status)]
    problems += [truncation(b) for b in branches if b.truncated]
    problems += [f"cross-check failed on {x.branch} at {x.parameter:.6g}"
                 for c in result.continuations for x in c.cross_checks if not x.passed]
    problems += [f"simulation {s.name} failed: {s.message}" for s in result.simulations
                 if s.status < 0]
    problems += [unjudged_seeds(c) for c in result.continuations if seeds_found_nothing(c)]
    problems += [plot_error] if plot_error else []
    return Verdict(tuple(problems), notes)


def range_warnings(found: Boundary, tolerance: float = 1e-6) -> tuple[str, ...]:
    """Where ``found``'s unsafe region may reach past its range: an unsafe interval ending at
    an edge of the first parameter's range (within ``tolerance`` of its span), and a fold or
    fold-of-cycles locus ending there where it bounds stable cycles (the intervals it bounds
    are then never formed). None
    for a boundary whose range is not known (older files)."""
    low, high = found.first_range
    if not (math.isfinite(low) and math.isfinite(high)):
        return ()
    first, second = found.parameter_names
    near = tolerance * (high - low)

    def edge(value: float) -> bool:  # on the edge, or past it (a locus's last step may be)
        return value <= low + near or value >= high - near

    warnings = [f"{found.name}: the unsafe interval {i.lower:.6g} < {first} < {i.upper:.6g} "
                f"at {second} = {i.slice_value:.6g} ends at the edge of the range of {first} "
                f"[{low:g}, {high:g}]: the region may extend beyond it"
                for i in found.intervals if edge(i.lower) or edge(i.upper)]
    for name, (kind, curve) in found.loci.items():
        bounding = found.bounding_ends.get(name, (True, True))
        ends = [point for point, bounds in zip(curve[[0, -1]] if len(curve) else (), bounding,
                                               strict=False)
                if kind in FOLD_LOCI and bounds and edge(point[0])]
        warnings += [f"{found.name}: the {kind.replace('_', ' ')} locus {name} leaves the range "
                     f"of {first} at {first} = {p[0]:.6g}, {second} = {p[1]:.6g}: unsafe "
                     "intervals it bounds beyond are not formed" for p in ends]
    return tuple(warnings)
