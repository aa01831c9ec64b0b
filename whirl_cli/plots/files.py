"""A study's figures as PNG files: the kinds a study asks for (:data:`PLOT_KINDS`), their file
names, rendered in memory and published complete or not at all.
"""

from __future__ import annotations

import io
import re
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import OutputError, WhirlError
from ..results import Branch, ContinuationResult, PointType, StudyResult
from .diagrams import bifurcation_diagram, period_plot, phase_plane, projections_figure
from .freeplay import amplitude_diagram, has_amplitudes
from .key import _PLOTTED_KINDS
from .linear import linear_sweep_plot
from .maps import _oriented_grid, boundary_plot, overhang_diagram, slice_continuation

if TYPE_CHECKING:
    from matplotlib.figure import Figure

PLOT_KINDS = ("bifurcation", "linear", "projections", "period", "phase", "boundary",
              "amplitude")
"""Kinds accepted by :func:`save_study_plots`."""

PHASE_ORBITS = 12
"""Most orbits a study's phase-plane figure draws (a long family stores one every 20 steps)."""


def save_study_plots(result: StudyResult, kinds: tuple[str, ...], out_dir: Path, stem: str,
                     state: str | None = None, dpi: int = 150) -> list[Path]:
    """Write a study's figures as PNG files into ``out_dir``; return the paths, sorted.

    ``kinds`` (any of :data:`PLOT_KINDS`):

    * "bifurcation" -> ``<stem>_<continuation>_bifurcation.png`` per one-parameter continuation
      (``state`` vs the principal parameter, angles in degrees; ``state`` None: the first
      state, i.e. the model's first degree of freedom);
    * "projections" -> ``<stem>_<continuation>_projections.png`` per one-parameter continuation
      (:func:`projections_figure`);
    * "period" -> ``<stem>_<continuation>_period.png`` per continuation with a periodic branch
      (:func:`period_plot`);
    * "phase" -> ``<stem>_<continuation>_<branch>_phase.png`` per periodic branch with stored
      orbits (:func:`phase_plane` of the branch's first two states, i.e. the model's first two
      dofs: psi vs theta for the classical model; at most :data:`PHASE_ORBITS` orbits, those
      stored at ``orbits_at`` values first, the others spread along the branch);
    * "linear" -> ``<stem>_linear_<parameter>.png`` per linear sweep;
    * "amplitude" -> ``<stem>_<continuation>_amplitude.png`` per continuation with freeplay
      amplitudes (:func:`~whirl_cli.plots.freeplay.amplitude_diagram`: A/delta, the
      describing-function estimate dashed);
    * "boundary" -> per boundary of ``result.boundaries``: ``<stem>_<boundary>_boundary.png``
      (:func:`boundary_plot` with ``result.linear_grid`` if it is over the same parameters, the
      slices as cases) and ``<stem>_<boundary>_slice_<k>_overhang.png`` per slice k
      (:func:`overhang_diagram` of the two-parameter continuation named like the boundary, or
      of no branches if there is none; ``state`` as for "bifurcation"); without boundaries but
      with a linear grid,
      ``<stem>_linear_grid.png`` (the grid alone).

    Names are made filesystem-safe; repeats get ``_2``, ``_3``, ... (:func:`plot_names`).
    Each file is rendered in memory and published complete or not at all (an existing file
    of the same name is replaced). ``whirl run`` and ``whirl sweep`` publish a study's plots
    together with its HDF5 file instead (:mod:`whirl_cli.output.study_files`).
    """
    out_dir = Path(out_dir)
    rendered = render_study_plots(result, kinds, stem, state, dpi)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create plot directory {out_dir}: {exc}") from exc
    from ..output.atomic import publish

    return sorted(publish(data, out_dir / name, overwrite=True, what="the plot")
                  for name, data in rendered)


def plot_names(result: StudyResult, kinds: tuple[str, ...], stem: str,
               state: str | None = None) -> list[str]:
    """The file names :func:`save_study_plots` writes for ``result`` (in drawing order),
    found without drawing anything."""
    return [name for name, _ in _named_jobs(result, kinds, stem, state)]


def render_study_plots(result: StudyResult, kinds: tuple[str, ...], stem: str,
                       state: str | None = None, dpi: int = 150) -> list[tuple[str, bytes]]:
    """(file name, PNG bytes) of every figure of :func:`save_study_plots`, rendered in
    memory; nothing is written."""
    return [(name, _png(make(), dpi)) for name, make in _named_jobs(result, kinds, stem, state)]


def _named_jobs(result: StudyResult, kinds: tuple[str, ...], stem: str, state: str | None):
    """(unique filesystem-safe file name, figure factory) pairs of the requested kinds."""
    unknown = set(kinds) - set(PLOT_KINDS)
    if unknown:
        raise WhirlError(f"unknown plot kind(s) {sorted(unknown)}; choose from {PLOT_KINDS}")
    taken: list[Path] = []
    jobs = []
    for name, make in _figure_jobs(result, kinds, stem, state):
        path = _unique(Path(_safe_name(name)), taken)
        taken.append(path)
        jobs.append((path.name, make))
    return jobs


def _figure_jobs(result: StudyResult, kinds: tuple[str, ...], stem: str,
                 state: str | None):
    """(file name, figure factory) pairs for the requested kinds, in a stable order."""
    jobs = []
    if "bifurcation" in kinds:
        for continuation in result.continuations:
            if continuation.kind == "one-parameter":
                chosen = _state_for(continuation, state)
                jobs.append((f"{stem}_{continuation.name}_bifurcation.png",
                             lambda c=continuation, s=chosen: bifurcation_diagram(c, s)))
    if "projections" in kinds:
        for continuation in result.continuations:
            if continuation.kind == "one-parameter":
                jobs.append((f"{stem}_{continuation.name}_projections.png",
                             lambda c=continuation: projections_figure(c)))
    if "period" in kinds:
        for continuation in result.continuations:
            if any(b.is_periodic for b in continuation.branches):
                jobs.append((f"{stem}_{continuation.name}_period.png",
                             lambda c=continuation: period_plot(c)))
    if "phase" in kinds:
        for continuation in result.continuations:
            for branch in continuation.branches:
                if branch.is_periodic and branch.orbits and len(branch.state_names) >= 2:
                    jobs.append((f"{stem}_{continuation.name}_{branch.name}_phase.png",
                                 lambda b=branch: phase_plane(b, labels=phase_labels(b))))
    if "linear" in kinds:
        for sweep in result.linear_sweeps:
            jobs.append((f"{stem}_linear_{sweep.parameter}.png",
                         lambda s=sweep: linear_sweep_plot(s)))
    if "boundary" in kinds:
        jobs += _boundary_jobs(result, stem, state)
    if "amplitude" in kinds:
        for continuation in result.continuations:
            if has_amplitudes(continuation):
                jobs.append((f"{stem}_{continuation.name}_amplitude.png",
                             lambda c=continuation: amplitude_diagram(c)))
    return jobs


def _boundary_jobs(result: StudyResult, stem: str, state: str | None):
    """(file name, figure factory) pairs of the "boundary" kind."""
    grid = result.linear_grid
    if not result.boundaries:
        if grid is None:
            return []
        return [(f"{stem}_linear_grid.png", lambda: boundary_plot(None, grid))]
    jobs = []
    for boundary in result.boundaries:
        matched = None if grid is None else _oriented_grid(grid, boundary.parameter_names)
        jobs.append((f"{stem}_{boundary.name}_boundary.png",
                     lambda b=boundary, g=matched: boundary_plot(b, g, cases=b.slices)))
        continuation = next((c for c in result.continuations if c.name == boundary.name
                             and c.kind == "two-parameter"),
                            ContinuationResult(boundary.name, "one-parameter", (), ()))
        for k, value in enumerate(boundary.slices):
            chosen = (_state_for(slice_continuation(continuation, k), state)
                      if continuation.kind == "two-parameter" else state)
            jobs.append((f"{stem}_{boundary.name}_slice_{k}_overhang.png",
                         lambda c=continuation, b=boundary, v=value, s=chosen:
                         overhang_diagram(c, b, v, state=s)))
    return jobs


def phase_labels(branch: Branch, most: int = PHASE_ORBITS) -> list[int]:
    """Labels of the orbits a study's phase plane of ``branch`` draws, in branch order: all of
    them if there are at most ``most``; else every orbit stored at an ``orbits_at`` value (UZ)
    and, up to ``most`` in all, others evenly spread along the branch (first and last
    included)."""
    orbits = sorted(branch.orbits, key=lambda o: o.index)
    if len(orbits) <= most:
        return [o.label for o in orbits]
    asked = [o for o in orbits if o.point_type == PointType.UZ]
    others = [o for o in orbits if o.point_type != PointType.UZ]
    room = max(most - len(asked), 0)
    picks = np.unique(np.linspace(0, len(others) - 1, room).round().astype(int)) if room else []
    chosen = {id(o) for o in asked} | {id(others[k]) for k in picks}
    return [o.label for o in orbits if id(o) in chosen]


def _state_for(continuation: ContinuationResult, state: str | None) -> str | None:
    """``state`` if every plotted branch has it, else None (the first state)."""
    branches = [b for b in continuation.branches if b.kind in _PLOTTED_KINDS]
    if state is None or not branches or all(state in b.state_names for b in branches):
        return state
    return None


def _safe_name(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._+-]", "_", name)


def _unique(path: Path, taken: list[Path]) -> Path:
    candidate, n = path, 1
    while candidate in taken:
        n += 1
        candidate = path.with_name(f"{path.stem}_{n}{path.suffix}")
    return candidate


def _png(figure: Figure, dpi: int) -> bytes:
    """``figure`` rendered as PNG bytes (the figure is cleared afterwards)."""
    buffer = io.BytesIO()
    try:
        figure.savefig(buffer, format="png", dpi=dpi)
    finally:
        figure.clear()
    return buffer.getvalue()

