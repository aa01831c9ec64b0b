"""Compare two whirl result files on what is physical, not on how AUTO happened to step.

``whirl compare A.h5 B.h5`` is the drift check of CI (``tests/regression``) and of sweeps run
on other machines. Point indices, step counts and provenance are not compared; instead:

* **root**: study name and model (``created``, ``git_describe``, ``whirl_version``,
  ``auto_version`` are ignored: they legitimately change). The study text and its hash
  (``study_yaml``, ``study_sha256``) are provenance: a difference there (a comment, the plots
  asked for, a timeout) is reported as a note, not as drift, unless ``strict``; what the
  study changes in the physics shows up in the results themselves;
* **special points** of each continuation, matched by (type, kind of their branch) with an
  optimal assignment on parameter and state, then compared on the parameter values (tolerance
  ``parameter`` x the span of that parameter over the continuation), the state (``state``, SI
  units), the period (relative ``period``), the first Lyapunov coefficient (relative
  ``lyapunov``) and criticality and status (exact);
* **branches**, matched by name: ``kind``, ``end`` and ``status`` exact; each branch is cut
  into stretches where the principal parameter is monotone, and ``state_max``/``state_min``
  of both files are interpolated onto common parameter values of each stretch (tolerance
  ``branch_state``); stability is compared on the same values, ignoring the cells around
  special points where the flag legitimately flips between neighbouring points, and points
  whose stability is unknown (``Branch.stability_known``);
* **linear sweeps** directly (relative ``linear``);
* **boundaries** (``/boundaries``, curves in two parameters), when present, by the distance of
  every point of one curve to the polyline of the other, in axes scaled by their span;
* **simulations** (``/simulations``) by law, status and samples, their states within
  ``simulation`` of each state's largest magnitude (a phase error near a zero crossing is
  not drift beyond that);
* **explorations** (``explore:``) by position: value and class exact, Lyapunov exponents and
  frequencies within ``exploration`` (relative; an exponent relative to its size plus three
  standard errors);
* **runs** by status, **cross-checks** by their pass/fail outcome.

Files are read with :func:`whirl_cli.output.store.read`; ``/boundaries`` (not part of
:class:`~whirl_cli.results.StudyResult`) with h5py.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import h5py
import numpy as np

from ..errors import OutputError
from ..results import (
    Branch,
    ContinuationResult,
    LinearSweep,
    PointType,
    Simulation,
    SpecialPoint,
    StudyResult,
)
from . import store

#: Root attributes that change from run to run without any physical meaning.
IGNORED_ATTRIBUTES = frozenset({"created", "git_describe", "whirl_version", "whirl_code_sha256",
                                "auto_version", "plots"})
#: Root attributes that say where a result came from: differences are notes, drift only when
#: comparing ``strict``ly. (``study_name`` and ``model`` say what was computed: always drift.)
PROVENANCE_ATTRIBUTES = frozenset({"study_yaml", "study_sha256", "model_file", "model_file_yaml",
                                   "model_file_sha256"})


@dataclass(frozen=True)
class Tolerances:
    """What counts as "the same". Units in brackets.

    parameter: special-point parameters, fraction of the span of that parameter over the
        continuation's branches [-]; state: special-point states [rad, rad/s];
    period: relative, special-point periods [-]; branch_state: interpolated
        state_max/state_min of branches [rad, rad/s]; linear: relative, linear sweeps [-];
    boundary: boundary curves, fraction of each axis' span [-]; lyapunov: relative, first
    Lyapunov coefficients of Hopf points [-]; simulation: simulated states, fraction of each
    state's largest magnitude over the simulation [-]; exploration: relative, the
    frequencies and Lyapunov exponents of ``explore`` classifications (simulations at
    rtol 1e-6) [-].
    """

    parameter: float = 1e-6
    state: float = 1e-6
    period: float = 1e-5
    branch_state: float = 1e-5
    linear: float = 1e-9
    boundary: float = 1e-5
    lyapunov: float = 1e-4
    simulation: float = 1e-6
    exploration: float = 1e-3

    @classmethod
    def from_options(cls, rtol: float | None = None, atol: float | None = None) -> Tolerances:
        """The CLI's ``--rtol`` (periods, linear sweeps, special-point parameters as a
        fraction of the range) and ``--atol`` (states of special points and branches, SI)
        replace the defaults they name."""
        chosen: dict[str, float] = {}
        if rtol is not None:
            chosen.update(parameter=rtol, period=rtol, linear=rtol, boundary=rtol)
        if atol is not None:
            chosen.update(state=atol, branch_state=atol)
        return cls(**chosen)


@dataclass(frozen=True)
class Difference:
    """One disagreement: the HDF5 path it concerns, the two values as text, and why."""

    path: str
    a: str
    b: str
    note: str = ""

    def __str__(self) -> str:
        return f"{self.path}: {self.a} vs {self.b}" + (f"  ({self.note})" if self.note else "")


@dataclass(frozen=True)
class Comparison:
    """What :func:`compare` found: ``differences`` (drift) and ``notes`` (differences of
    provenance, :data:`PROVENANCE_ATTRIBUTES`, that are not drift; empty when ``strict``)."""

    differences: list[Difference]
    notes: list[Difference]


# ------------------------------------------------------------------------------ entry points
def compare(a: Path, b: Path, tolerances: Tolerances | None = None, strict: bool = False
            ) -> Comparison:
    """Drift and provenance notes between the result files ``a`` and ``b``; with ``strict``
    a difference of study text or hash is drift too. OutputError for results of different
    models (other equations: nothing to compare)."""
    tolerances = tolerances or Tolerances()
    result_a, result_b = store.read(a), store.read(b)
    different = different_models(result_a, result_b)
    if different:
        raise OutputError(f"{a} and {b} are results of different models ({different}): not "
                          "compared")
    differences = compare_results(result_a, result_b, tolerances, strict)
    differences += compare_boundaries(a, b, tolerances)
    return Comparison(differences, [] if strict else provenance_notes(result_a, result_b))


def different_models(a: StudyResult, b: StudyResult) -> str:
    """Why ``a`` and ``b`` come from different equations: another model variant, or a model
    file of other content (its ``model_key``); "" if from the same."""
    if a.model != b.model:
        return f"{a.model} vs {b.model}"
    keys = [r.provenance.model_key for r in (a, b)]
    if keys[0] != keys[1]:
        return f"{a.model} from model files that declare different equations or values"
    return ""


def compare_files(a: Path, b: Path, tolerances: Tolerances | None = None, strict: bool = False
                  ) -> list[Difference]:
    """All drift between the result files ``a`` and ``b`` (empty: they agree)."""
    return compare(a, b, tolerances, strict).differences


def compare_results(a: StudyResult, b: StudyResult, tolerances: Tolerances | None = None,
                    strict: bool = False) -> list[Difference]:
    """Drift between two results in memory (everything but ``/boundaries``); study text and
    hash count only if ``strict`` (else see :func:`provenance_notes`)."""
    tolerances = tolerances or Tolerances()
    found = _compare_root(a, b, IGNORED_ATTRIBUTES if strict
                          else IGNORED_ATTRIBUTES | PROVENANCE_ATTRIBUTES)
    found += _compare_named(
        "/continuations", {c.name: c for c in a.continuations},
        {c.name: c for c in b.continuations},
        lambda name, x, y: compare_continuation(x, y, tolerances))
    found += _compare_named(
        "/linear/sweeps", {s.parameter: s for s in a.linear_sweeps},
        {s.parameter: s for s in b.linear_sweeps},
        lambda name, x, y: compare_linear_sweep(x, y, tolerances.linear))
    found += _compare_named(
        "/simulations", {s.name: s for s in a.simulations},
        {s.name: s for s in b.simulations},
        lambda name, x, y: compare_simulation(x, y, tolerances.simulation))
    found += _compare_named(
        "/runs", {r.name: r for r in a.runs}, {r.name: r for r in b.runs},
        lambda name, x, y: [] if x.status == y.status else
        [Difference(f"/runs/{name}", x.status, y.status, "run status")])
    return found


def _compare_named(prefix: str, a: dict, b: dict, compare) -> list[Difference]:
    """Match items by name; report the ones only in one file, compare the others."""
    found = [Difference(f"{prefix}/{name}", "present" if name in a else "missing",
                        "present" if name in b else "missing")
             for name in sorted(set(a) ^ set(b))]
    for name in sorted(set(a) & set(b)):
        found += compare(name, a[name], b[name])
    return found


def _compare_root(a: StudyResult, b: StudyResult, skip: frozenset[str]) -> list[Difference]:
    found = []
    pairs = {"study_name": (a.study_name, b.study_name), "model": (a.model, b.model)}
    root_a, root_b = a.root_attributes(), b.root_attributes()
    for key in sorted((set(root_a) | set(root_b)) - skip):
        pairs[key] = (root_a.get(key, "<missing>"), root_b.get(key, "<missing>"))
    for key, (x, y) in pairs.items():
        if str(x) != str(y):
            shown = _first_different_line(x, y) if key == "study_yaml" and isinstance(
                x, str) and isinstance(y, str) else (_short(x), _short(y))
            found.append(Difference(f"/@{key}", *shown, "root attribute"))
    return found


def provenance_notes(a: StudyResult, b: StudyResult) -> list[Difference]:
    """Differences of study text and hash (:data:`PROVENANCE_ATTRIBUTES`): not drift."""
    paths = {f"/@{key}" for key in PROVENANCE_ATTRIBUTES}
    return [replace(d, note="provenance, not drift; --strict counts it")
            for d in _compare_root(a, b, IGNORED_ATTRIBUTES) if d.path in paths]


def _first_different_line(x: str, y: str) -> tuple[str, str]:
    """The first line where two texts differ, as ``line <k>: <text>`` (``<end>`` past the
    last line of the shorter text)."""
    lines_x, lines_y = x.splitlines(), y.splitlines()
    k = next((k for k, (p, q) in enumerate(zip(lines_x, lines_y, strict=False)) if p != q),
             min(len(lines_x), len(lines_y)))

    def line(lines: list[str]) -> str:
        return f"line {k + 1}: " + (_short(lines[k]) if k < len(lines) else "<end>")

    return line(lines_x), line(lines_y)


def _short(value, limit: int = 60) -> str:
    text = repr(value) if isinstance(value, str) else str(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


# ------------------------------------------------------------------------------ continuations
def compare_continuation(a: ContinuationResult, b: ContinuationResult,
                         tolerances: Tolerances) -> list[Difference]:
    """Special points, branches and cross-checks of one continuation present in both files."""
    path = f"/continuations/{a.name}"
    if a.kind != b.kind:
        return [Difference(f"{path}/@kind", a.kind, b.kind)]
    spans = parameter_spans(a)
    found = compare_special_points(path, a, b, spans, tolerances)
    found += _compare_named(
        f"{path}/branches", {x.name: x for x in a.branches}, {x.name: x for x in b.branches},
        lambda name, x, y: compare_branch(f"{path}/branches/{name}", x, y, spans[0],
                                          tolerances))
    found += _compare_cross_checks(path, a, b)
    found += compare_explorations(path, a, b, tolerances.exploration)
    return found


def compare_explorations(path: str, a: ContinuationResult, b: ContinuationResult,
                         rtol: float) -> list[Difference]:
    """The ``explore`` classifications, by position: value and kind exact, the largest
    Lyapunov exponent within ``rtol`` x (|exponent| + 3 x its standard error) of the larger
    (an exponent near zero is known only to its error), frequencies relative ``rtol``
    (their number exact)."""
    found = []
    if len(a.explorations) != len(b.explorations):
        return [Difference(f"{path}/explorations", f"{len(a.explorations)} values",
                           f"{len(b.explorations)} values", "explored values")]
    for k, (x, y) in enumerate(zip(a.explorations, b.explorations, strict=True)):
        where = f"{path}/explorations/{k}"
        if x.value != y.value:
            found.append(Difference(f"{where}/value", f"{x.value:.6g}", f"{y.value:.6g}"))
            continue
        if x.kind != y.kind:
            found.append(Difference(f"{where}/@kind", x.kind, y.kind,
                                    f"class at {x.parameter} = {x.value:g}"))
            continue
        limit = rtol * max(abs(x.lyapunov) + 3 * x.lyapunov_error,
                           abs(y.lyapunov) + 3 * y.lyapunov_error)
        both_nan = np.isnan(x.lyapunov) and np.isnan(y.lyapunov)
        if not both_nan and not abs(x.lyapunov - y.lyapunov) <= limit:
            found.append(Difference(f"{where}/lyapunov", f"{x.lyapunov:.6g}",
                                    f"{y.lyapunov:.6g}", f"1/s, beyond {limit:.3g}"))
        fx, fy = np.asarray(x.frequencies, float), np.asarray(y.frequencies, float)
        if fx.shape != fy.shape:
            found.append(Difference(f"{where}/frequencies", f"{len(fx)} values",
                                    f"{len(fy)} values"))
        elif len(fx) and not np.allclose(fx, fy, rtol=rtol, atol=0.0):
            found.append(Difference(f"{where}/frequencies", _short(np.round(fx, 6).tolist()),
                                    _short(np.round(fy, 6).tolist()), f"Hz, relative {rtol:g}"))
    return found


def parameter_spans(continuation: ContinuationResult) -> np.ndarray:
    """(P,) span of each parameter over all branches of a continuation (1.0 if none)."""
    tables = [b.parameters.reshape(len(b), -1) for b in continuation.branches if len(b)]
    if not tables or len({t.shape[1] for t in tables}) != 1:
        return np.ones(1)
    stacked = np.vstack(tables)
    spans = np.nanmax(stacked, axis=0) - np.nanmin(stacked, axis=0)
    return np.where(spans > 0, spans, 1.0)


# ------------------------------------------------------------------------------ special points
def compare_special_points(path: str, a: ContinuationResult, b: ContinuationResult,
                           spans: np.ndarray, tolerances: Tolerances) -> list[Difference]:
    """Match special points by (type, branch kind), then pair them by nearest position."""
    groups_a, groups_b = _point_groups(a), _point_groups(b)
    found = []
    for key in sorted(set(groups_a) | set(groups_b)):
        rows_a, rows_b = groups_a.get(key, []), groups_b.get(key, [])
        if len(rows_a) != len(rows_b):
            found.append(Difference(
                f"{path}/special_points", f"{len(rows_a)} {key[0]} on {key[1]} branches",
                f"{len(rows_b)}", "number of special points of this type"))
        for i, j in _assign(rows_a, rows_b, a.special_points, b.special_points, spans):
            found += _compare_point(f"{path}/special_points", i, a.special_points[i],
                                    b.special_points[j], spans, tolerances)
    return found


def _point_groups(continuation: ContinuationResult) -> dict[tuple[str, str], list[int]]:
    kinds = {branch.name: branch.kind for branch in continuation.branches}
    groups: dict[tuple[str, str], list[int]] = {}
    for row, point in enumerate(continuation.special_points):
        groups.setdefault((point.type_name, kinds.get(point.branch, "?")), []).append(row)
    return groups


def _assign(rows_a: list[int], rows_b: list[int], points_a, points_b, spans: np.ndarray
            ) -> list[tuple[int, int]]:
    """Pairs (row in a, row in b) minimising the summed scaled distance (Hungarian method)."""
    if not rows_a or not rows_b:
        return []
    from scipy.optimize import linear_sum_assignment

    def position(point: SpecialPoint) -> np.ndarray:
        params = np.asarray(point.parameters, float).ravel()
        scaled = params / spans[:len(params)] if len(spans) >= len(params) else params
        return np.concatenate((scaled, np.asarray(point.state, float).ravel()))

    pa = [position(points_a[r]) for r in rows_a]
    pb = [position(points_b[r]) for r in rows_b]
    cost = np.array([[_distance(x, y) for y in pb] for x in pa])
    left, right = linear_sum_assignment(cost)
    return [(rows_a[i], rows_b[j]) for i, j in zip(left, right, strict=True)]


def _distance(x: np.ndarray, y: np.ndarray) -> float:
    if x.shape != y.shape:
        return 1e30
    delta = np.abs(x - y)
    return float(np.nansum(delta) + 1e6 * np.sum(np.isnan(x) != np.isnan(y)))


def _compare_point(path: str, row: int, a: SpecialPoint, b: SpecialPoint, spans: np.ndarray,
                   tolerances: Tolerances) -> list[Difference]:
    where = f"{a.type_name} on {a.branch}"
    found = []
    params_a = np.asarray(a.parameters, float).ravel()
    params_b = np.asarray(b.parameters, float).ravel()
    if params_a.shape != params_b.shape:
        return [Difference(f"{path}/parameters[{row}]", str(params_a), str(params_b), where)]
    for k, name in enumerate(a.parameter_names[:len(params_a)]):
        limit = tolerances.parameter * (spans[k] if k < len(spans) else 1.0)
        if not _close(params_a[k], params_b[k], limit):
            found.append(Difference(f"{path}/parameters[{row}]", f"{name} = {params_a[k]:.10g}",
                                    f"{params_b[k]:.10g}",
                                    f"{where}; |diff| {abs(params_a[k] - params_b[k]):.3g} > "
                                    f"{limit:.3g}"))
    state_a, state_b = np.asarray(a.state, float), np.asarray(b.state, float)
    worst = _worst(state_a, state_b)
    if worst is not None and worst[1] > tolerances.state:
        k = worst[0]
        found.append(Difference(f"{path}/state[{row}, {k}]", f"{state_a.ravel()[k]:.10g}",
                                f"{state_b.ravel()[k]:.10g}", where))
    scale = max(abs(a.period), abs(b.period)) if np.isfinite([a.period, b.period]).all() else 0
    if not _close(a.period, b.period, tolerances.period * scale):
        found.append(Difference(f"{path}/period[{row}]", f"{a.period:.10g}", f"{b.period:.10g}",
                                where))
    scale = max(abs(a.lyapunov), abs(b.lyapunov)) if np.isfinite([a.lyapunov, b.lyapunov]).all() \
        else 0
    if not _close(a.lyapunov, b.lyapunov, tolerances.lyapunov * scale):
        found.append(Difference(f"{path}/lyapunov[{row}]", f"{a.lyapunov:.10g}",
                                f"{b.lyapunov:.10g}", where))
    for key in ("criticality", "status"):
        if getattr(a, key) != getattr(b, key):
            found.append(Difference(f"{path}/{key}[{row}]", getattr(a, key), getattr(b, key),
                                    where))
    return found


def _close(x: float, y: float, limit: float) -> bool:
    """Equal within ``limit``, NaN equal to NaN."""
    if np.isnan(x) or np.isnan(y):
        return bool(np.isnan(x) and np.isnan(y))
    return abs(x - y) <= limit


def _worst(a: np.ndarray, b: np.ndarray) -> tuple[int, float] | None:
    """(flat index, |diff|) of the largest difference; NaN against a number is infinite."""
    a, b = np.asarray(a, float).ravel(), np.asarray(b, float).ravel()
    if a.shape != b.shape:
        return 0, float("inf")
    if not a.size:
        return None
    delta = np.abs(a - b)
    delta = np.where(np.isnan(a) & np.isnan(b), 0.0, np.where(np.isnan(delta), np.inf, delta))
    k = int(np.argmax(delta))
    return k, float(delta[k])


# ------------------------------------------------------------------------------ branches
@dataclass(frozen=True)
class Stretch:
    """Rows ``start..stop`` (inclusive) of a branch where the principal parameter moves in
    one ``direction`` (+1, -1; 0: a line of points at one parameter value)."""

    start: int
    stop: int
    direction: int


def monotone_stretches(values: np.ndarray, tiny: float) -> list[Stretch]:
    """Cut a branch at its folds: runs of steps of one sign (|step| <= ``tiny`` counts as 0).

    Neighbouring stretches share the turning row. Repeated points (steps of exactly zero in
    every column, where whirl joins restarted pieces) must be removed beforehand.
    """
    if len(values) < 2:
        return [Stretch(0, max(len(values) - 1, 0), 0)]
    steps = np.diff(values)
    direction = np.where(steps > tiny, 1, np.where(steps < -tiny, -1, 0))
    cuts = np.flatnonzero(direction[1:] != direction[:-1]) + 1
    starts = np.concatenate(([0], cuts))
    stops = np.concatenate((cuts, [len(steps)]))
    return [Stretch(int(s), int(e), int(direction[s])) for s, e in zip(starts, stops, strict=True)]


def _distinct_rows(branch: Branch) -> np.ndarray:
    """Rows of ``branch`` without exact repeats of the previous point (joined pieces)."""
    table = np.column_stack((branch.parameters.reshape(len(branch), -1), branch.state_max,
                             branch.state_min))
    if len(table) < 2:
        return np.arange(len(table))
    same = np.all((table[1:] == table[:-1]) | (np.isnan(table[1:]) & np.isnan(table[:-1])),
                  axis=1)
    return np.concatenate(([0], np.flatnonzero(~same) + 1))


def compare_branch(path: str, a: Branch, b: Branch, span: float, tolerances: Tolerances
                   ) -> list[Difference]:
    """One branch of both files: attributes exact, states and stability along the parameter."""
    found = [Difference(f"{path}/@{key}", getattr(a, key), getattr(b, key))
             for key in ("kind", "status", "end") if getattr(a, key) != getattr(b, key)
             and not (key == "end" and "" in (a.end, b.end))]  # schema 1: not recorded
    if a.state_names != b.state_names:
        return found + [Difference(f"{path}/state_max", f"states {a.state_names}",
                                   f"{b.state_names}")]
    if not len(a) or not len(b):
        if len(a) != len(b):
            found.append(Difference(f"{path}/state_max", f"{len(a)} points", f"{len(b)}"))
        return found
    rows_a, rows_b = _distinct_rows(a), _distinct_rows(b)
    pa = a.parameters.reshape(len(a), -1)[rows_a, 0]
    pb = b.parameters.reshape(len(b), -1)[rows_b, 0]
    tiny = 1e-9 * span
    stretches_a, stretches_b = monotone_stretches(pa, tiny), monotone_stretches(pb, tiny)
    if [s.direction for s in stretches_a] != [s.direction for s in stretches_b]:
        return found + [Difference(f"{path}/parameters", _turns(stretches_a, pa),
                                   _turns(stretches_b, pb), "monotone stretches differ")]
    name = a.parameter_names[0]
    for k, (sa, sb) in enumerate(zip(stretches_a, stretches_b, strict=True)):
        piece_a = _Piece.of(a, rows_a[sa.start:sa.stop + 1])
        piece_b = _Piece.of(b, rows_b[sb.start:sb.stop + 1])
        inner = (k > 0, k < len(stretches_a) - 1)
        if sa.direction == 0:
            found += _compare_line(path, name, k, piece_a, piece_b, span, tolerances)
        else:
            found += _compare_stretch(path, name, k, piece_a, piece_b, inner, tolerances)
    return found


def _turns(stretches: list[Stretch], values: np.ndarray) -> str:
    marks = {1: "up", -1: "down", 0: "line"}
    return ", ".join(f"{marks[s.direction]} to {values[s.stop]:.6g}" for s in stretches[:6]) + (
        ", ..." if len(stretches) > 6 else "")


@dataclass(frozen=True)
class _Piece:
    """A monotone stretch of a branch, sorted by increasing parameter ``x``."""

    x: np.ndarray  # (m,) principal parameter
    high: np.ndarray  # (m, n) state_max
    low: np.ndarray  # (m, n) state_min
    stable: np.ndarray  # (m,) bool
    special: np.ndarray  # parameter values of special points on the stretch
    known: np.ndarray  # (m,) bool: the stability is known (Branch.stability_known)

    @classmethod
    def of(cls, branch: Branch, rows: np.ndarray) -> _Piece:
        x = branch.parameters.reshape(len(branch), -1)[rows, 0]
        order = np.argsort(x, kind="stable")
        rows = rows[order]
        special = np.array([_is_special(int(t)) for t in branch.point_type[rows]], dtype=bool)
        return cls(x[order], branch.state_max[rows], branch.state_min[rows],
                   branch.stable[rows].astype(bool), x[order][special],
                   branch.stability_known[rows].astype(bool))

    def cell(self, at: np.ndarray) -> np.ndarray:
        """Width of the cell (interval between neighbouring points) containing each ``at``."""
        if len(self.x) < 2:
            return np.zeros_like(at)
        k = np.clip(np.searchsorted(self.x, at) - 1, 0, len(self.x) - 2)
        return self.x[k + 1] - self.x[k]

    def stability(self, at: np.ndarray) -> np.ndarray:
        """1 stable, 0 unstable, -1 undefined: the two ends of the cell disagree, or ``at``
        lies outside the points of known stability (points of unknown stability are skipped:
        the cells are those between the known ones)."""
        if len(self.x) < 2:
            single = len(self.stable) and self.known[0]
            return np.full(len(at), int(self.stable[0]) if single else -1)
        x, stable = self.x[self.known], self.stable[self.known]
        if len(x) < 2:
            return np.full(len(at), -1)
        k = np.clip(np.searchsorted(x, at, side="right") - 1, 0, len(x) - 2)
        left, right = stable[k], stable[k + 1]
        inside = (at >= x[0]) & (at <= x[-1])
        return np.where(inside & (left == right), left.astype(int), -1)


def _is_special(code: int) -> bool:
    try:
        return PointType(code).is_special
    except ValueError:
        return False


def _compare_stretch(path: str, name: str, k: int, a: _Piece, b: _Piece,
                     inner: tuple[bool, bool], tolerances: Tolerances) -> list[Difference]:
    """States and stability of stretch ``k`` on common parameter values."""
    found = []
    for end, xa, xb, cell in (("start", a.x[0], b.x[0], max(a.cell(a.x[:1])[0],
                                                               b.cell(b.x[:1])[0])),
                              ("end", a.x[-1], b.x[-1], max(a.cell(a.x[-1:])[0],
                                                            b.cell(b.x[-1:])[0]))):
        if abs(xa - xb) > cell + 1e-12:
            found.append(Difference(f"{path}/parameters", f"stretch {k} {end}s at "
                                    f"{name} = {xa:.8g}", f"{xb:.8g}",
                                    "more than one step apart"))
    low, high = max(a.x[0], b.x[0]), min(a.x[-1], b.x[-1])
    grid = np.unique(np.concatenate((a.x, b.x)))
    margin_low = max(a.cell(a.x[:1])[0], b.cell(b.x[:1])[0]) if inner[0] else 0.0
    margin_high = max(a.cell(a.x[-1:])[0], b.cell(b.x[-1:])[0]) if inner[1] else 0.0
    grid = grid[(grid >= low + margin_low) & (grid <= high - margin_high)]
    if not len(grid):
        return found
    for key in ("high", "low"):
        table_a, table_b = getattr(a, key), getattr(b, key)
        for j in range(table_a.shape[1]):
            ya, error_a = _interpolate(a.x, table_a[:, j], grid)
            yb, error_b = _interpolate(b.x, table_b[:, j], grid)
            excess = np.abs(ya - yb) - (tolerances.branch_state + error_a + error_b)
            excess = np.where(np.isnan(ya) & np.isnan(yb), -1.0, np.nan_to_num(excess, nan=1.0))
            if (excess > 0).any():
                at = int(np.argmax(excess))
                dataset = "state_max" if key == "high" else "state_min"
                found.append(Difference(
                    f"{path}/{dataset}", f"state {j} = {ya[at]:.10g}", f"{yb[at]:.10g}",
                    f"at {name} = {grid[at]:.8g}, stretch {k}; |diff| "
                    f"{abs(ya[at] - yb[at]):.3g} > {tolerances.branch_state:.3g} + "
                    f"interpolation {error_a[at] + error_b[at]:.2g}"))
    found += _compare_stability(path, name, k, a, b, grid)
    return found


def _interpolate(x: np.ndarray, y: np.ndarray, at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Linear interpolation of ``y(x)`` at ``at`` and an estimate of its error there: a
    quarter of the change of slope around the cell times the cell width (~h^2 y''/4; large
    next to a fold, where y(x) has a vertical tangent, negligible on smooth stretches)."""
    value = np.interp(at, x, y)
    if len(x) < 3:
        return value, np.zeros_like(value)
    width = np.diff(x)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(width > 0, np.diff(y) / np.where(width > 0, width, 1.0), 0.0)
    change = np.abs(np.diff(slope))  # at the inner points
    bend = np.maximum(np.concatenate(([change[0]], change)), np.concatenate((change,
                                                                             [change[-1]])))
    cell = np.clip(np.searchsorted(x, at, side="right") - 1, 0, len(x) - 2)
    return value, bend[cell] * width[cell] / 4


def _compare_stability(path: str, name: str, k: int, a: _Piece, b: _Piece, grid: np.ndarray
                       ) -> list[Difference]:
    """Stability flags on ``grid``; disagreement within one cell of a special point is allowed."""
    sa, sb = a.stability(grid), b.stability(grid)
    differ = (sa >= 0) & (sb >= 0) & (sa != sb)
    specials = np.concatenate((a.special, b.special))
    if specials.size and differ.any():
        cells = np.maximum(a.cell(grid), b.cell(grid))
        near = (np.abs(grid[:, None] - specials[None, :]) <= cells[:, None] * (1 + 1e-9)).any(1)
        differ &= ~near
    if not differ.any():
        return []
    where = grid[differ]
    flag = {1: "stable", 0: "unstable"}
    first = int(np.flatnonzero(differ)[0])
    return [Difference(f"{path}/stable", flag[int(sa[first])], flag[int(sb[first])],
                       f"at {differ.sum()} value(s) of {name} in [{where.min():.8g}, "
                       f"{where.max():.8g}], stretch {k}")]


def _compare_line(path: str, name: str, k: int, a: _Piece, b: _Piece, span: float,
                  tolerances: Tolerances) -> list[Difference]:
    """A stretch at one parameter value (a line of equilibria): the value and its extent."""
    found = []
    limit = tolerances.parameter * span
    if abs(np.mean(a.x) - np.mean(b.x)) > limit:
        found.append(Difference(f"{path}/parameters", f"line {k} at {name} = "
                                f"{np.mean(a.x):.10g}", f"{np.mean(b.x):.10g}"))
    for key, dataset in (("high", "state_max"), ("low", "state_min")):
        table_a, table_b = getattr(a, key), getattr(b, key)
        step = max(_largest_step(table_a), _largest_step(table_b))
        for edge, pick in (("min", np.nanmin), ("max", np.nanmax)):
            ya, yb = pick(table_a, axis=0), pick(table_b, axis=0)
            worst = _worst(ya, yb)
            if worst is not None and worst[1] > step + tolerances.branch_state:
                j = worst[0]
                found.append(Difference(f"{path}/{dataset}", f"state {j} {edge} {ya[j]:.10g}",
                                        f"{yb[j]:.10g}", f"line {k} at {name} = "
                                        f"{np.mean(a.x):.8g}: extent differs by more than a step"))
    return found


def _largest_step(table: np.ndarray) -> float:
    if len(table) < 2:
        return 0.0
    return float(np.nanmax(np.abs(np.diff(table, axis=0))))


def _compare_cross_checks(path: str, a: ContinuationResult, b: ContinuationResult
                          ) -> list[Difference]:
    """Outcome (passed or not) of the time-simulation checks, per branch and kind."""
    def outcome(result: ContinuationResult) -> dict[tuple[str, str], str]:
        table: dict[tuple[str, str], list[int]] = {}
        for check in result.cross_checks:
            counts = table.setdefault((check.branch, check.kind), [0, 0])
            counts[0 if check.passed else 1] += 1
        return {key: f"{p} passed, {f} failed" for key, (p, f) in table.items()}

    ta, tb = outcome(a), outcome(b)
    return [Difference(f"{path}/cross_checks", ta.get(key, "none"), tb.get(key, "none"),
                       f"{key[1]} checks on {key[0]}")
            for key in sorted(set(ta) | set(tb)) if ta.get(key) != tb.get(key)]


# ------------------------------------------------------------------------------ linear sweeps
def compare_linear_sweep(a: LinearSweep, b: LinearSweep, rtol: float) -> list[Difference]:
    """Every column of a linear sweep, element by element (relative ``rtol``); the datum
    where both files store it (files before it do not: that is no drift), whether the
    study gave it in multiples of the datum, and its spacing."""
    path = f"/linear/sweeps/{a.parameter}"
    found = []
    for key in ("values", "eigenvalues", "damping_ratio", "frequency"):
        x, y = np.asarray(getattr(a, key)), np.asarray(getattr(b, key))
        found += _compare_arrays(f"{path}/{key}", x, y, rtol)
    found += _compare_labels(f"{path}/whirl", a.whirl, b.whirl)
    if (a.mode_group is None) != (b.mode_group is None):
        found.append(Difference(f"{path}/mode_group", "absent" if a.mode_group is None else
                                "stored", "absent" if b.mode_group is None else "stored"))
    elif a.mode_group is not None:
        found += _compare_labels(f"{path}/mode_group", a.mode_group, b.mode_group)
    if a.datum is not None and b.datum is not None:  # older files store no datum: no drift
        found += _compare_arrays(f"{path}/datum", np.asarray(a.datum, float),
                                 np.asarray(b.datum, float), rtol)
    for key in ("multiples", "spacing"):
        if getattr(a, key) != getattr(b, key):
            found.append(Difference(f"{path}/@{key}", str(getattr(a, key)),
                                    str(getattr(b, key))))
    return found


def compare_simulation(a: Simulation, b: Simulation, rtol: float) -> list[Difference]:
    """Law, status, parameters, initial state and sample times exactly as stored (they
    come from the study), the states within ``rtol`` of each state's largest magnitude."""
    path = f"/simulations/{a.name}"
    found = [Difference(f"{path}/@{key}", str(getattr(a, key)), str(getattr(b, key)))
             for key in ("law", "status", "parameter_names", "state_names")
             if getattr(a, key) != getattr(b, key)]
    for key in ("parameter_values", "initial", "time"):
        found += _compare_arrays(f"{path}/{key}", np.asarray(getattr(a, key), float),
                                 np.asarray(getattr(b, key), float), 1e-12)
    x, y = np.asarray(a.states, float), np.asarray(b.states, float)
    if found or x.shape != y.shape:
        return found + ([Difference(f"{path}/states", f"shape {x.shape}", f"shape {y.shape}")]
                        if x.shape != y.shape else [])
    if not x.size:
        return []
    scale = np.maximum(np.abs(x).max(axis=0), np.abs(y).max(axis=0))
    delta = np.abs(x - y) / np.where(scale > 0, scale, 1.0)
    if not (delta > rtol).any():
        return []
    at = np.unravel_index(int(np.argmax(delta)), x.shape)
    return [Difference(f"{path}/states{[int(i) for i in at]}", f"{x[at]:.12g}", f"{y[at]:.12g}",
                       f"{int((delta > rtol).sum())} element(s) beyond {rtol:.3g} of the "
                       f"state's largest magnitude")]


def _compare_labels(path: str, a: np.ndarray, b: np.ndarray) -> list[Difference]:
    """Text arrays (whirl directions, mode groups) equal element by element."""
    a, b = np.asarray(a), np.asarray(b)
    if a.shape == b.shape and not (a != b).any():
        return []
    bad = np.argwhere(a != b) if a.shape == b.shape else [[0]]
    at = tuple(int(i) for i in bad[0])
    same = a.shape == b.shape
    return [Difference(f"{path}{list(at)}", str(a[at]) if same else str(a.shape),
                       str(b[at]) if same else str(b.shape), f"{len(bad)} element(s) differ")]


def _compare_arrays(path: str, x: np.ndarray, y: np.ndarray, rtol: float) -> list[Difference]:
    """Numeric arrays equal within ``rtol`` of their magnitude (NaN equal to NaN)."""
    if x.shape != y.shape:
        return [Difference(path, f"shape {x.shape}", f"shape {y.shape}")]
    if not x.size:
        return []
    scale = float(np.nanmax(np.abs(np.concatenate((x.ravel(), y.ravel())))) or 1.0) \
        if np.isfinite(np.abs(x)).any() else 1.0
    limit = rtol * np.maximum(np.abs(x), np.abs(y)) + rtol * 1e-3 * scale
    delta = np.abs(x - y)
    bad = np.where(np.isnan(x) & np.isnan(y), False, ~(delta <= limit))
    if not bad.any():
        return []
    at = tuple(int(i) for i in np.unravel_index(int(np.argmax(np.where(bad, delta, -1))),
                                                x.shape))
    return [Difference(f"{path}{list(at)}", f"{x[at]:.12g}", f"{y[at]:.12g}",
                       f"{int(bad.sum())} element(s) beyond rtol {rtol:.3g}")]


# ------------------------------------------------------------------------------ boundaries
#: Attributes schema 2 added to the datasets of those groups: absent from a schema-1 file,
#: which is no drift.
SCHEMA_2_ATTRIBUTES = ("/@names", "/@units")
#: Attributes of HDF5 dimension scales that hold object references (which dataset a scale
#: is attached to): equal files hold different references, and the datasets themselves are
#: compared.
SCALE_LINKS = frozenset({"REFERENCE_LIST", "DIMENSION_LIST"})
#: Groups compared dataset by dataset with h5py (their layout is not needed here).
GENERIC_GROUPS = ("boundaries", "linear/grid")


def compare_boundaries(a: Path, b: Path, tolerances: Tolerances,
                       roots: tuple[str, ...] = GENERIC_GROUPS) -> list[Difference]:
    """Datasets and attributes under ``/boundaries`` (and ``/linear/grid``) of both files:
    curves (K, 2) of boundaries and grid contours by distance, other numbers element-wise
    (relative ``linear``), text exactly. Files without these groups agree trivially."""
    data_a, data_b = _datasets(a, roots), _datasets(b, roots)
    found = [Difference(name, "present" if name in data_a else "missing",
                        "present" if name in data_b else "missing")
             for name in sorted(set(data_a) ^ set(data_b))
             if not name.endswith(SCHEMA_2_ATTRIBUTES)]  # what a schema-1 file lacks
    for name in sorted(set(data_a) & set(data_b)):
        x, y = data_a[name], data_b[name]
        if _is_curve(name, x) and _is_curve(name, y):
            found += compare_curves(name, x, y, tolerances.boundary)
        elif x.dtype.kind in "fciub" and y.dtype.kind in "fciub":
            found += _compare_arrays(name, x.astype(float), y.astype(float), tolerances.linear)
        elif x.shape != y.shape or (x != y).any():
            found.append(Difference(name, _short(x.tolist()), _short(y.tolist())))
    return found


def _is_curve(name: str, data: np.ndarray) -> bool:
    """A polyline (K, 2): boundary loci and polygons, zero contours of the linear grid."""
    curve_like = name.startswith("/boundaries/") or "/flutter/" in name or "/divergence/" in name
    return curve_like and data.dtype.kind == "f" and data.ndim == 2 and data.shape[1] == 2


def _datasets(path: Path, roots: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Path -> value of every dataset (strings decoded) and group attribute (``<group>/@key``)
    under ``roots``."""
    found: dict[str, np.ndarray] = {}

    def decoded(value) -> np.ndarray:
        value = np.asarray(value)
        if value.dtype.kind in "OS":
            value = np.array([v.decode() if isinstance(v, bytes) else str(v)
                              for v in value.ravel()]).reshape(value.shape)
        return value

    with store.opened(path) as handle:
        for root in roots:
            if root not in handle:
                continue

            def visit(name: str, item, root=root) -> None:
                where = f"/{root}/{name}"
                if isinstance(item, h5py.Dataset):
                    found[where] = decoded(item[()])
                for key, value in item.attrs.items():
                    if key not in store.CONTENTS | SCALE_LINKS:
                        found[f"{where}/@{key}"] = decoded(value)

            for key, value in handle[root].attrs.items():
                if key not in store.CONTENTS:
                    found[f"/{root}/@{key}"] = decoded(value)
            handle[root].visititems(visit)
    return found


def compare_curves(path: str, a: np.ndarray, b: np.ndarray, tolerance: float
                   ) -> list[Difference]:
    """Two curves (rows of points) agree when every point of each lies within ``tolerance``
    (in axes scaled by the span of both curves) of the other's polyline."""
    a = a[np.isfinite(a).all(axis=1)]
    b = b[np.isfinite(b).all(axis=1)]
    if a.shape[1] != b.shape[1] or not len(a) or not len(b):
        if a.shape == b.shape:
            return []
        return [Difference(path, f"{len(a)} points", f"{len(b)} points", "curve")]
    both = np.vstack((a, b))
    span = np.ptp(both, axis=0)
    scale = np.where(span > 0, span, 1.0)
    sa, sb = a / scale, b / scale
    gap_ab, gap_ba = _to_polyline(sa, sb), _to_polyline(sb, sa)
    if max(gap_ab.max(), gap_ba.max()) <= tolerance:
        return []
    side, gaps, points = ("a", gap_ab, a) if gap_ab.max() >= gap_ba.max() else ("b", gap_ba, b)
    k = int(np.argmax(gaps))
    return [Difference(path, f"point {k} of {side} at {np.round(points[k], 8).tolist()}",
                       f"{gaps[k]:.3g} away from the other curve",
                       f"scaled distance > {tolerance:.3g}")]


def _to_polyline(points: np.ndarray, line: np.ndarray, neighbours: int = 8) -> np.ndarray:
    """Distance of each point to the polyline through ``line`` (same units): to the segments
    next to its ``neighbours`` nearest vertices (a k-d tree), never less than the true one."""
    from scipy.spatial import cKDTree

    if len(line) == 1:
        return np.linalg.norm(points - line[0], axis=1)
    _, nearest = cKDTree(line).query(points, k=min(neighbours, len(line)))
    nearest = nearest.reshape(len(points), -1)
    segments = np.clip(np.concatenate((nearest - 1, nearest), axis=1), 0, len(line) - 2)
    start, end = line[segments], line[segments + 1]  # (N, 2k, d)
    seg = end - start
    length2 = np.maximum((seg ** 2).sum(axis=2), 1e-300)
    t = np.clip(((points[:, None, :] - start) * seg).sum(axis=2) / length2, 0.0, 1.0)
    nearest_points = start + t[..., None] * seg
    return np.linalg.norm(points[:, None, :] - nearest_points, axis=2).min(axis=1)
