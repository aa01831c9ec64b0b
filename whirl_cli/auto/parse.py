"""Parsing AUTO-07p's output files into whirl's result dataclasses.

File formats (AUTO-07p 0.9.2, verified against its Fortran writers):

* ``b.NAME``: header lines start with BR = 0 (constants echo, "Active continuation parameters",
  then a column title). Data lines are ``BR PT TY LAB`` then PAR(ICP(1)), the L2 norm, the
  states (only if NICP + NDIM <= 7) and PAR(ICP(2..)). BR < 0 marks periodic solutions,
  PT < 0 stability; Fortran may print 3-digit exponents without the ``E`` (``1.0-100``).
* ``s.NAME``: per labelled solution a 16-integer header
  ``IBR NTOT ITP LAB NFPR ISW NTPL NAR NROWPR NTST NCOL NPAR NPARI NDIMU IPS IPRIV``, then NTPL
  rows of ``t, U(1..NAR-1)``, optional direction data, then PAR(1..NPAR).
* ``d.NAME``: free text; for each accepted point the last block of eigenvalues (IPS=1) or Floquet
  multipliers (IPS=2) printed before the ``BR PT TY LAB`` summary of that point.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from ..models import Model
from ..results import Branch, BranchKind, Orbit, Origin, PointType, RunStatus
from .constants import PERIOD_INDEX, TORUS_ANGLE_INDEX, auto_name, par_layout
from .runner import RunOutcome


def fortran_float(text: str) -> float:
    """A Fortran real as printed by AUTO: handles ``1.5-100`` (no E) and ``D`` exponents."""
    try:
        return float(text)
    except ValueError:
        pass
    normal = text.replace("D", "E").replace("d", "e")
    match = re.fullmatch(r"([-+]?\d*\.?\d*)([-+]\d+)", normal)
    if match:
        return float(f"{match.group(1)}E{match.group(2)}")
    try:
        return float(normal)
    except ValueError:
        return float("nan")


@dataclass(frozen=True)
class BSegment:
    """One header block of a b-file and its data rows (one branch of one run)."""

    columns: tuple[str, ...]
    active: tuple[str, ...]
    br: np.ndarray
    pt: np.ndarray
    ty: np.ndarray
    lab: np.ndarray
    values: np.ndarray  # (N, len(columns))

    def has(self, name: str) -> bool:
        """True if the segment has the column of ``name`` (whirl's name or AUTO's)."""
        return name in self.columns or auto_name(name) in self.columns

    def column(self, name: str) -> np.ndarray:
        """The column of ``name`` (whirl's name of a parameter, or AUTO's)."""
        return self.values[:, self.columns.index(
            name if name in self.columns else auto_name(name))]


def _column_names(title: str, n_columns: int) -> tuple[str, ...]:
    # HEADNG writes I4 + '    PT  TY  LAB ' (20 characters), then one A19 per column
    names = tuple(title[20 + 19 * i: 20 + 19 * (i + 1)].strip() for i in range(n_columns))
    if not all(names):
        return tuple(f"COL{i + 1}" for i in range(n_columns))
    return names


def _segment(header: list[str], rows: list[list[str]]) -> BSegment:
    titles = [line for line in header if " PT " in line and " TY " in line]
    n_columns = len(rows[0]) - 4
    columns = _column_names(titles[-1].rstrip("\n"), n_columns) if titles else tuple(
        f"COL{i + 1}" for i in range(n_columns))
    active: tuple[str, ...] = ()
    for line in header:
        found = re.search(r"Active continuation parameters?:\s*(.*)$", line)
        if found:
            active = tuple(part.strip("'") for part in found.group(1).split())
    integers = np.array([[int(x) for x in row[:4]] for row in rows], dtype=np.int64)
    values = np.array([[fortran_float(x) for x in row[4:]] for row in rows], dtype=float)
    return BSegment(columns, active, integers[:, 0], integers[:, 1], integers[:, 2],
                    integers[:, 3], values.reshape(len(rows), n_columns))


def parse_b(text: str) -> list[BSegment]:
    """Every branch segment of a b-file, in file order."""
    segments: list[BSegment] = []
    header: list[str] = []
    rows: list[list[str]] = []
    in_header = False
    for line in text.splitlines():
        tokens = line.split()
        if not tokens:
            continue
        if tokens[0] == "0":
            if not in_header:
                if rows:
                    segments.append(_segment(header, rows))
                header, rows, in_header = [], [], True
            header.append(line)
            continue
        in_header = False
        rows.append(tokens)
    if rows:
        segments.append(_segment(header, rows))
    return segments


@dataclass(frozen=True)
class Solution:
    """One labelled solution from an s-file. ``u``: (NTPL, NAR-1); PAR(i) is ``par[i-1]``."""

    br: int
    pt: int
    ty: int
    lab: int
    isw: int
    ntst: int
    ncol: int
    ndim: int
    ips: int
    t: np.ndarray
    u: np.ndarray
    par: np.ndarray


def parse_s(text: str) -> list[Solution]:
    """Every solution of an s-file, in file order."""
    lines = text.splitlines()
    solutions: list[Solution] = []
    i = 0
    while i < len(lines):
        head = lines[i].split()
        if len(head) < 16:
            i += 1
            continue
        (br, pt, ty, lab, nfpr, isw, ntpl, nar, nrowpr, ntst, ncol, npar, _npari, ndim, ips,
         _ipriv) = (int(x) for x in head[:16])
        tokens = " ".join(lines[i + 1: i + 1 + nrowpr]).split()
        i += 1 + nrowpr
        n_profile = ntpl * nar
        profile = np.array([fortran_float(x) for x in tokens[:n_profile]]).reshape(ntpl, nar)
        rest = tokens[n_profile:]
        if len(rest) > npar:  # direction information: ICP, RLDOT, UDOT
            rest = rest[2 * nfpr + ntpl * (nar - 1):]
        par = np.array([fortran_float(x) for x in rest[:npar]])
        solutions.append(Solution(br, pt, ty, lab, isw, ntst, ncol, ndim, ips, profile[:, 0],
                                  profile[:, 1:], par))
    return solutions


@dataclass(frozen=True)
class Diagnostics:
    """Eigenvalues or Floquet multipliers of one accepted point (from a d-file)."""

    br: int
    pt: int  # signed as in the b-file: negative = stable
    kind: str  # "eigenvalues" | "multipliers" | ""
    n_stable: int | None
    values: np.ndarray


_VALUE = re.compile(r"^\s*(-?\d+)\s+(-?\d+)\s+(Eigenvalue|Multiplier)\s+(\d+):?\s+(\S+)\s+(\S+)")
_STABLE = re.compile(r"^\s*-?\d+\s+-?\d+\s+(?:Eigenvalues|Multipliers)\s*:\s+Stable:\s+(-?\d+)")
_TITLE = re.compile(r"^\s*BR\s+PT\s+TY\s+LAB")


def parse_d(text: str) -> tuple[list[Diagnostics], list[str]]:
    """Per accepted point the last eigenvalue/multiplier block before its summary line,
    and AUTO's NOTE lines (retries, inaccurate multipliers, ...)."""
    points: list[Diagnostics] = []
    notes: list[str] = []
    values: list[complex] = []
    kind, n_stable = "", None
    expect_summary = False
    # most lines are Newton iterations: the patterns are tried only on lines holding their
    # words (as fast as a substring test), which changes nothing but the time taken
    for line in text.splitlines():
        if not line.strip():
            continue
        if expect_summary:
            expect_summary = False
            tokens = line.split()
            try:
                br, pt = int(tokens[0]), int(tokens[1])
            except (ValueError, IndexError):
                continue
            points.append(Diagnostics(br, pt, kind, n_stable, np.array(values, dtype=complex)))
            values, kind, n_stable = [], "", None
            continue
        if "BR" in line and _TITLE.match(line):
            expect_summary = True
            continue
        found = _STABLE.match(line) if "Stable:" in line else None
        if found:
            n_stable = int(found.group(1))
            continue
        found = _VALUE.match(line) if "Eigenvalue" in line or "Multiplier" in line else None
        if found:
            if int(found.group(4)) == 1:
                values = []
            kind = "eigenvalues" if found.group(3) == "Eigenvalue" else "multipliers"
            values.append(complex(fortran_float(found.group(5)), fortran_float(found.group(6))))
            continue
        if "NOTE" in line or "WARNING" in line:
            notes.append(line.strip())
    return points, notes


def _attach(segment: BSegment, diagnostics: list[Diagnostics], n: int) -> np.ndarray:
    """(N, n) eigenvalues/multipliers per b-file row, matched on (|BR|, |PT|) in order."""
    table = np.full((len(segment.pt), n), np.nan + 1j * np.nan, dtype=complex)
    rows: dict[tuple[int, int], list[int]] = {}
    for k, (br, pt) in enumerate(zip(segment.br, segment.pt, strict=True)):
        rows.setdefault((abs(int(br)), abs(int(pt))), []).append(k)
    for point in diagnostics:
        candidates = rows.get((abs(point.br), abs(point.pt)))
        if candidates and len(point.values):
            k = candidates.pop(0)
            table[k, : min(n, len(point.values))] = point.values[:n]
    return table


def read_branch(outcome: RunOutcome, model: Model, *, name: str, kind: BranchKind,
                origin: Origin,
                parameter_names: tuple[str, ...]) -> Branch:
    """The branch one AUTO run wrote, in SI units (see :mod:`whirl_cli.results`)."""
    segments = parse_b(outcome.file("b").read_text(errors="replace"))
    segment = segments[0] if len(segments) == 1 else _concatenate(segments)
    needed = [*parameter_names, "L2-NORM",
              *(f"{m}_{s}" for m in ("max", "min") for s in model.state_names)]
    missing = [c for c in needed if not segment.has(c)]
    if missing:
        return _unreadable_branch(outcome, model, name, kind, origin, parameter_names,
                                  f"AUTO's b-file lacks column(s) {', '.join(missing)}"
                                  + (f" in some of its {len(segments)} segments"
                                     if len(segments) > 1 else ""))
    scale = np.asarray(model.state_scale, dtype=float)
    n = model.n_states
    state_max = np.column_stack([segment.column(f"max_{s}") for s in model.state_names]) * scale
    state_min = np.column_stack([segment.column(f"min_{s}") for s in model.state_names]) * scale
    periodic = kind == BranchKind.PERIODIC
    torus = kind == BranchKind.TORUS_LOCUS
    angle_column = f"PAR({TORUS_ANGLE_INDEX})"
    if torus and angle_column not in segment.columns:
        return _unreadable_branch(outcome, model, name, kind, origin, parameter_names,
                                  f"AUTO's b-file of a torus locus lacks {angle_column} (the "
                                  "torus angle; ICP must list it)")
    period = (segment.column("PERIOD") / model.time_scale if "PERIOD" in segment.columns
              else np.full(len(segment.pt), np.nan))
    if kind == BranchKind.EQUILIBRIUM:
        period = _hopf_periods(outcome, segment) / model.time_scale
    diagnostics, _notes = (parse_d(outcome.file("d").read_text(errors="replace"))
                           if outcome.file("d").exists() else ([], []))
    eigen = _attach(segment, diagnostics, n)
    if not periodic:
        eigen = eigen * model.time_scale  # AUTO's eigenvalues are per unit tau
    on_locus = kind not in (BranchKind.EQUILIBRIUM, BranchKind.PERIODIC)
    parameters = np.column_stack([segment.column(p) for p in parameter_names])
    # AUTO's flag (the sign of PT) is a verdict only where it had eigenvalues/multipliers:
    # at the first point of a family from a Hopf point it prints none, yet flags "unstable"
    known = ~np.isnan(eigen).all(axis=1) & (not on_locus)
    return Branch(
        name=name,
        kind=kind,
        origin=origin,
        parameter_names=tuple(parameter_names),
        parameter_units=tuple(model.parameter(p).unit for p in parameter_names),
        state_names=model.state_names,
        state_units=tuple(s.unit for s in model.states),
        parameters=parameters,
        state_max=state_max,
        state_min=state_min,
        l2_norm=segment.column("L2-NORM"),
        period=period,
        stable=(segment.pt < 0) & (not on_locus),
        point_type=np.array([PointType.from_auto(int(t)) for t in segment.ty], dtype=np.int64),
        label=segment.lab.copy(),
        eigenvalues=eigen,
        status=outcome.status,
        message=outcome.message,
        runs=(outcome.name,),
        orbits=read_orbits(outcome, model, segment, parameter_names) if periodic or torus
        else (),
        stability_known=known,
        torus_angle=_principal_angle(segment.column(angle_column)) if torus else None,
    )


def _principal_angle(theta: np.ndarray) -> np.ndarray:
    """AUTO's torus angle PAR(12) (any real: multipliers exp(+-i theta)) as the angle in
    [0, pi] rad of the pair's upper member."""
    return np.abs(np.angle(np.exp(1j * np.asarray(theta, dtype=float))))


def _unreadable_branch(outcome: RunOutcome, model: Model, name: str, kind: BranchKind,
                       origin: Origin,
                       parameter_names: tuple[str, ...], message: str) -> Branch:
    """An empty branch with status error: AUTO's output lacks what whirl reads."""
    n, p = model.n_states, len(parameter_names)
    return Branch(
        name=name, kind=kind, origin=origin, parameter_names=tuple(parameter_names),
        parameter_units=tuple(model.parameter(x).unit for x in parameter_names),
        state_names=model.state_names, state_units=tuple(s.unit for s in model.states),
        parameters=np.empty((0, p)), state_max=np.empty((0, n)), state_min=np.empty((0, n)),
        l2_norm=np.empty(0), period=np.empty(0), stable=np.empty(0, dtype=bool),
        point_type=np.empty(0, dtype=np.int64), label=np.empty(0, dtype=np.int64),
        eigenvalues=np.empty((0, n), dtype=complex), status=RunStatus.ERROR, message=message,
        runs=(outcome.name,), torus_angle=np.empty(0) if kind == BranchKind.TORUS_LOCUS else None)


def _hopf_periods(outcome: RunOutcome, segment: BSegment) -> np.ndarray:
    """Per row of an equilibrium branch: the period PAR(11) at labelled Hopf points, else NaN."""
    period = np.full(len(segment.pt), np.nan)
    if not outcome.file("s").exists():
        return period
    rows = {int(lab): k for k, lab in enumerate(segment.lab) if lab}
    for solution in parse_s(outcome.file("s").read_text(errors="replace")):
        if solution.lab in rows and PointType.from_auto(solution.ty) == PointType.HB:
            period[rows[solution.lab]] = solution.par[PERIOD_INDEX - 1]
    return period


def read_orbits(outcome: RunOutcome, model: Model, segment: BSegment,
                parameter_names: tuple[str, ...]) -> tuple[Orbit, ...]:
    """Profiles of the labelled periodic solutions of a run, in SI units (on a locus of
    cycles, whose solutions extend the orbit by more components, the orbit's own first
    ``model.n_states``)."""
    if not outcome.file("s").exists():
        return ()
    layout = par_layout(model)
    scale = np.asarray(model.state_scale, dtype=float)
    rows = {int(lab): k for k, lab in enumerate(segment.lab) if lab}
    orbits = []
    for solution in parse_s(outcome.file("s").read_text(errors="replace")):
        if solution.lab not in rows or solution.ips not in (2, -2):
            continue
        period = solution.par[PERIOD_INDEX - 1] / model.time_scale
        orbits.append(Orbit(
            label=solution.lab,
            point_type=int(PointType.from_auto(solution.ty)),
            index=rows[solution.lab],
            parameters=np.array([solution.par[layout.parameters[p] - 1]
                                 for p in parameter_names]),
            period=float(period),
            time=solution.t * period,
            states=solution.u[:, : model.n_states] * scale,
        ))
    return tuple(orbits)


def _concatenate(segments: list[BSegment]) -> BSegment:
    """The rows of every segment of a b-file, in file order, with the columns all segments
    have (by name, in the first segment's order). No row is dropped: a column only some
    segments print is left out, and :func:`read_branch` fails the branch with a message if it
    needed that column."""
    first = segments[0]
    shared = tuple(c for c in first.columns if all(c in s.columns for s in segments[1:]))
    values = [s.values[:, [s.columns.index(c) for c in shared]] for s in segments]
    return BSegment(shared, first.active,
                    *(np.concatenate([getattr(s, f) for s in segments]) for f in
                      ("br", "pt", "ty", "lab")),
                    np.concatenate(values).reshape(-1, len(shared)))

