"""A study's figures as PNG files: the kinds a study asks for (:data:`PLOT_KINDS`), their file
names, rendered in memory and published complete or not at all.
"""

from __future__ import annotations

import io
import re
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cache, partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import OutputError, WhirlError
from ..kinds import MOTION_KINDS, PLOT_KINDS
from ..output.guard import PLOT_CHARACTERS, plot_stem
from ..results import Branch, ContinuationResult, PointType, StudyResult
from .captions import Captions, Fixed, captions
from .diagrams import bifurcation_diagram, period_plot, phase_plane, projections_figure
from .freeplay import amplitude_diagram, has_amplitudes
from .key import _PLOTTED_KINDS
from .laws import law_plot, nonlinear_laws
from .linear import damping_multiples_plot, linear_sweep_plot, root_locus_plot, sweep_datum
from .maps import _oriented_grid, boundary_plot, overhang_diagram, slice_continuation
from .motion import orbit_diagram, poincare_plot, spectrum_plot
from .simulations import hub_path, time_history

if TYPE_CHECKING:
    from matplotlib.figure import Figure


PHASE_ORBITS = 12
"""Most orbits a study's phase-plane figure draws (a long family stores one every 20 steps)."""


@dataclass(frozen=True)
class View:
    """How the figures of :func:`save_study_plots` are drawn beyond their data: axis limits
    (in the units shown, applied to every axes of every figure; None: from the data) and
    frequencies in Hz instead of rad/s (linear sweeps); ``artefacts``: draw the special points
    flagged as smoothing artefacts too (hidden by default)."""

    xlim: tuple[float, float] | None = None
    ylim: tuple[float, float] | None = None
    hz: bool = False
    artefacts: bool = False


def missing_data(result: StudyResult, kind: str) -> str:
    """What ``result`` lacks to draw plot ``kind`` (a sentence), or "" if it can draw it."""
    one_parameter = [c for c in result.continuations if c.kind == "one-parameter"]
    if kind in ("bifurcation", "projections") and not one_parameter:
        return "no one-parameter continuation"
    if kind == "period" and not any(b.is_periodic for c in result.continuations
                                    for b in c.branches):
        return "no periodic branch (a continuation with periodic: true)"
    if kind == "phase" and not any(b.is_periodic and b.orbits and len(b.state_names) >= 2
                                   for c in result.continuations for b in c.branches):
        return "no stored orbits on a periodic branch (periodic: true; orbits_at stores more)"
    if kind in ("linear", "root_locus", "damping_multiples") and not result.linear_sweeps:
        return "no linear sweep (linear.sweeps)"
    if kind == "damping_multiples" and not _multiple_sweeps(result):
        return "no linear sweep of a parameter with a non-zero datum (linear.sweeps)"
    if kind == "boundary" and not result.boundaries and result.linear_grid is None:
        return "no stability boundary (a two-parameter continuation) and no linear grid " \
               "(linear.grid)"
    if kind == "amplitude" and not any(has_amplitudes(c) for c in result.continuations):
        return "no freeplay amplitudes (a periodic branch of a model with a freeplay law)"
    if kind == "law" and not nonlinear_laws(result):
        return "no nonlinear stiffness law (nonlinearity) in the stored study"
    if kind in ("time_history", "hub_path") and not result.simulations:
        return "no simulation (simulations:)"
    if kind in MOTION_KINDS and not any(c.explorations for c in result.continuations):
        return "no explored values (a one-parameter continuation with explore:)"
    return ""


def _datums(result: StudyResult) -> dict[str, float]:
    """The datum of every parameter (for files whose sweeps do not store theirs)."""
    return {p.name: p.datum for p in result.parameters}


def _multiple_sweeps(result: StudyResult) -> list:
    """The linear sweeps that can be drawn against parameter / datum (a non-zero datum)."""
    datums = _datums(result)
    return [s for s in result.linear_sweeps if sweep_datum(s, datums) is not None]


def available_kinds(result: StudyResult) -> tuple[str, ...]:
    """The kinds of :data:`PLOT_KINDS` that ``result`` has the data for, in that order."""
    return tuple(kind for kind in PLOT_KINDS if not missing_data(result, kind))


def save_study_plots(result: StudyResult, kinds: tuple[str, ...], out_dir: Path, stem: str,
                     state: str | None = None, dpi: int = 150, view: View = View(),
                     result_file: Path | None = None, formats: tuple[str, ...] = ("png",)
                     ) -> list[Path]:
    """Write a study's figures as PNG files into ``out_dir`` (and each also in the other
    ``formats`` of :data:`FORMATS`, beside it: ``<name>.pdf``); return the paths, sorted.

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
    * "root_locus" -> ``<stem>_root_locus_<parameter>.png`` per linear sweep
      (:func:`~whirl_cli.plots.linear.root_locus_plot`);
    * "damping_multiples" -> ``<stem>_damping_multiples.png``, one for all the linear sweeps
      of a parameter with a non-zero datum, given in multiples or not
      (:func:`~whirl_cli.plots.linear.damping_multiples_plot`: the least-damped mode against
      parameter / datum);
    * "amplitude" -> ``<stem>_<continuation>_amplitude.png`` per continuation with freeplay
      amplitudes (:func:`~whirl_cli.plots.freeplay.amplitude_diagram`: A/delta, the
      describing-function estimate dashed);
    * "time_history" -> ``<stem>_<simulation>_time_history.png`` per simulation
      (:func:`~whirl_cli.plots.simulations.time_history`: every dof against time);
    * "hub_path" -> ``<stem>_<simulation>_hub_path.png`` per simulation
      (:func:`~whirl_cli.plots.simulations.hub_path`);
    * "law" -> ``<stem>_law_<dof>.png`` per dof with a nonlinear law
      (:func:`~whirl_cli.plots.laws.law_plot`: the law as continued, exact, and K x);
    * "poincare", "spectrum", "orbit_diagram" -> ``<stem>_<continuation>_<kind>.png`` per
      continuation with ``explore:`` classifications (:mod:`~whirl_cli.plots.motion`: the
      Poincaré sections of the first two states, the frequencies found against the
      parameter, the section's values of ``state`` (else the first dof) over the bifurcation
      diagram);
    * "boundary" -> per boundary of ``result.boundaries``: ``<stem>_<boundary>_boundary.png``
      (:func:`boundary_plot` with ``result.linear_grid`` if it is over the same parameters, the
      slices as cases) and ``<stem>_<boundary>_slice_<k>_overhang.png`` per slice k
      (:func:`overhang_diagram` of the two-parameter continuation named like the boundary, or
      of no branches if there is none; ``state`` as for "bifurcation"); without boundaries but
      with a linear grid,
      ``<stem>_linear_grid.png`` (the grid alone).

    Titles name the study and the parameters it fixes (:mod:`~whirl_cli.plots.captions`,
    from the study stored with ``result``), slices by the study's labels; ``view`` sets axis
    limits and Hz. A kind without data draws nothing (:func:`missing_data` says why).
    The stem is kept as given; in the rest of a name, characters other than ``A-Za-z0-9._+-``
    become ``_``; repeats get ``_2``, ``_3``, ... (:func:`plot_names`).
    Each file is rendered in memory and published complete or not at all (an existing file
    of the same name is replaced if it is a PNG image, and nothing is written if one is not,
    or if a whirl result file other than ``result_file`` beside it records it as its plot:
    :func:`whirl_cli.output.owners.check_plot`). ``whirl run`` and ``whirl sweep`` publish a
    study's plots together with its HDF5 file instead (:mod:`whirl_cli.publish`).
    """
    out_dir = Path(out_dir)
    rendered = render_study_plots(result, kinds, stem, state, dpi, view, formats=formats)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create plot directory {out_dir}: {exc}") from exc
    from ..output.atomic import publish
    from ..output.guard import check
    from ..output.owners import check_plot

    for name, _ in rendered:  # a PNG is replaced, never a link, directory, device, FIFO
        if name.endswith(".png"):
            check_plot(out_dir / name, result_file or out_dir / f"{stem}.h5", overwrite=True)
        else:
            check(out_dir / name, _own(Path(name).suffix[1:]), overwrite=True)
    return sorted(publish(data, out_dir / name, overwrite=True, what="the plot",
                          own=_own(Path(name).suffix[1:])) for name, data in rendered)


def plot_names(result: StudyResult, kinds: tuple[str, ...], stem: str,
               state: str | None = None) -> list[str]:
    """The file names :func:`save_study_plots` writes for ``result`` (in drawing order),
    found without drawing anything."""
    return [name for name, _ in _named_jobs(result, kinds, stem, state)]


def render_study_plots(result: StudyResult, kinds: tuple[str, ...], stem: str,
                       state: str | None = None, dpi: int = 150, view: View = View(),
                       jobs: int = 1, formats: tuple[str, ...] = ("png",)
                       ) -> list[tuple[str, bytes]]:
    """(file name, bytes) of every figure of :func:`save_study_plots` in each of ``formats``
    (the PNG always, first), rendered in memory, in ``jobs`` forked processes
    (:func:`whirl_cli.runtime.forked_map`; the same bytes in the same order for any
    ``jobs``); nothing is written."""
    from ..runtime import forked_map

    if tuple(formats) == ("png",):
        tasks = render_tasks(result, kinds, stem, state, dpi, view)
        return forked_map(lambda k: tasks[k](), len(tasks), jobs)
    formats = ("png", *(f for f in formats if f != "png"))
    jobs_ = _named_jobs(result, kinds, stem, state, view)
    drawn = forked_map(lambda k: rendered_formats(_viewed(jobs_[k][1](), view), formats, dpi),
                       len(jobs_), jobs)
    return [(str(Path(name).with_suffix(f".{suffix}")), files[suffix])
            for (name, _), files in zip(jobs_, drawn, strict=True) for suffix in formats]


def render_tasks(result: StudyResult, kinds: tuple[str, ...], stem: str,
                 state: str | None = None, dpi: int = 150, view: View = View()
                 ) -> list[Callable[[], tuple[str, bytes]]]:
    """One task per figure of :func:`save_study_plots`, in drawing order: called (in any
    process), it draws its figure and returns (file name, PNG bytes). Nothing is drawn here."""
    return [partial(_rendered, name, make, view, dpi)
            for name, make in _named_jobs(result, kinds, stem, state, view)]


def _rendered(name: str, make: Callable[[], Figure], view: View, dpi: int
              ) -> tuple[str, bytes]:
    return name, _png(_viewed(make(), view), dpi)


def study_figures(result: StudyResult, kinds: tuple[str, ...], stem: str = "",
                  state: str | None = None, view: View = View()):
    """(file name, matplotlib Figure) of every figure of :func:`save_study_plots`, drawn one
    at a time as the iterator advances (nothing is written)."""
    for name, make in _named_jobs(result, kinds, stem, state, view):
        yield name, _viewed(make(), view)


def _viewed(figure: Figure, view: View) -> Figure:
    """``figure`` with ``view``'s axis limits on every axes (an equal-aspect axes then keeps
    its aspect by its box, not by moving the limits)."""
    for ax in figure.axes:
        if (view.xlim or view.ylim) and ax.get_aspect() != "auto":
            ax.set_adjustable("box")
        if view.xlim is not None:
            ax.set_xlim(*view.xlim)
        if view.ylim is not None:
            ax.set_ylim(*view.ylim)
    return figure


def _without_artefacts(result: StudyResult) -> StudyResult:
    """``result`` without the special points flagged as smoothing artefacts."""
    return replace(result, continuations=tuple(
        replace(c, special_points=tuple(p for p in c.special_points if not p.artefact))
        for c in result.continuations))


def _named_jobs(result: StudyResult, kinds: tuple[str, ...], stem: str, state: str | None,
                view: View = View()):
    """(unique filesystem-safe file name, figure factory) pairs of the requested kinds."""
    unknown = set(kinds) - set(PLOT_KINDS)
    if unknown:
        raise WhirlError(f"unknown plot kind(s) {sorted(unknown)}; choose from {PLOT_KINDS}")
    taken: list[Path] = []
    jobs = []
    for name, make in _figure_jobs(result, kinds, stem, state, view):
        path = _unique(Path(plot_stem(stem) + _safe_name(name.removeprefix(stem))), taken)
        taken.append(path)
        jobs.append((path.name, make))
    return jobs


def _figure_jobs(result: StudyResult, kinds: tuple[str, ...], stem: str,
                 state: str | None, view: View = View()):
    """(file name, figure factory) pairs for the requested kinds, in a stable order."""
    caption = cache(lambda: captions(result))  # read the stored study once, when drawing
    if not view.artefacts:
        result = _without_artefacts(result)
    jobs = []
    if "bifurcation" in kinds:
        for continuation in result.continuations:
            if continuation.kind == "one-parameter":
                chosen = _state_for(continuation, state)
                jobs.append((f"{stem}_{continuation.name}_bifurcation.png",
                             lambda c=continuation, s=chosen: bifurcation_diagram(
                                 c, s, title=_title(caption, c))))
    if "projections" in kinds:
        for continuation in result.continuations:
            if continuation.kind == "one-parameter":
                jobs.append((f"{stem}_{continuation.name}_projections.png",
                             lambda c=continuation: projections_figure(
                                 c, title=_title(caption, c))))
    if "period" in kinds:
        for continuation in result.continuations:
            if any(b.is_periodic for b in continuation.branches):
                jobs.append((f"{stem}_{continuation.name}_period.png",
                             lambda c=continuation: period_plot(c, title=_title(caption, c))))
    if "phase" in kinds:
        for continuation in result.continuations:
            for branch in continuation.branches:
                if branch.is_periodic and branch.orbits and len(branch.state_names) >= 2:
                    jobs.append((f"{stem}_{continuation.name}_{branch.name}_phase.png",
                                 lambda b=branch, c=continuation: phase_plane(
                                     b, labels=phase_labels(b),
                                     title=f"{_title(caption, c)}\n{b.name}")))
    if "linear" in kinds:
        for sweep in result.linear_sweeps:
            jobs.append((f"{stem}_linear_{sweep.parameter}.png",
                         lambda s=sweep: linear_sweep_plot(
                             s, hz=view.hz, title=caption().title({s.parameter}))))
    if "root_locus" in kinds:
        for sweep in result.linear_sweeps:
            jobs.append((f"{stem}_root_locus_{sweep.parameter}.png",
                         lambda s=sweep: root_locus_plot(s, title=caption().title(
                             {s.parameter}))))
    if "damping_multiples" in kinds:
        chosen = _multiple_sweeps(result)
        if chosen:
            jobs.append((f"{stem}_damping_multiples.png",
                         lambda c=tuple(chosen): damping_multiples_plot(
                             c, _datums(result), hz=view.hz, title=caption().title(
                                 {s.parameter for s in c}))))
    if "boundary" in kinds:
        jobs += _boundary_jobs(result, stem, state, caption, view)
    if "amplitude" in kinds:
        for continuation in result.continuations:
            if has_amplitudes(continuation):
                jobs.append((f"{stem}_{continuation.name}_amplitude.png",
                             lambda c=continuation: amplitude_diagram(c)))
    if "law" in kinds:
        for curve in nonlinear_laws(result):
            jobs.append((f"{stem}_law_{curve.dof}.png", lambda c=curve: law_plot(c)))
    for kind, draw in (("time_history", time_history), ("hub_path", hub_path)):
        if kind in kinds:
            for found in result.simulations:
                jobs.append((f"{stem}_{found.name}_{kind}.png",
                             lambda s=found, draw=draw: draw(
                                 s, title=caption().simulation_title(s))))
    for kind in (k for k in MOTION_KINDS if k in kinds):
        for continuation in result.continuations:
            if continuation.explorations:
                jobs.append((f"{stem}_{continuation.name}_{kind}.png",
                             lambda c=continuation, kind=kind: _motion_figure(
                                 kind, c, state, _title(caption, c))))
    return jobs


def _motion_figure(kind: str, continuation: ContinuationResult, state: str | None,
                   title: str) -> Figure:
    """The figure of a :data:`MOTION_KINDS` kind (``state``: the orbit diagram's, if the
    explorations have it)."""
    if kind == "poincare":
        return poincare_plot(continuation, title=title)
    if kind == "spectrum":
        return spectrum_plot(continuation, title=title)
    names = continuation.explorations[0].state_names
    return orbit_diagram(continuation, state if state in names else None, title=title)


def _title(caption: Callable[[], Captions], continuation: ContinuationResult) -> str:
    """The study's title over the parameters ``continuation`` does not vary."""
    varied = {name for b in continuation.branches for name in b.parameter_names}
    return caption().title(varied)


def _boundary_jobs(result: StudyResult, stem: str, state: str | None,
                   caption: Callable[[], Captions], view: View = View()):
    """(file name, figure factory) pairs of the "boundary" kind."""
    grid = result.linear_grid
    if not result.boundaries:
        if grid is None:
            return []
        return [(f"{stem}_linear_grid.png", lambda: boundary_plot(
            None, grid, title=caption().title({grid.x_parameter, grid.y_parameter}),
            xlim=view.xlim, ylim=view.ylim))]
    jobs = []
    for boundary in result.boundaries:
        matched = None if grid is None else _oriented_grid(grid, boundary.parameter_names)
        jobs.append((f"{stem}_{boundary.name}_boundary.png",
                     lambda b=boundary, g=matched: boundary_plot(
                         b, g, cases=b.slices, case_labels=caption().case_labels(b),
                         title=caption().title(b.parameter_names),
                         xlim=view.xlim, ylim=view.ylim)))
        continuation = next((c for c in result.continuations if c.name == boundary.name
                             and c.kind == "two-parameter"),
                            ContinuationResult(boundary.name, "one-parameter", (), ()))
        for k, value in enumerate(boundary.slices):
            chosen = (_state_for(slice_continuation(continuation, k), state)
                      if continuation.kind == "two-parameter" else state)
            jobs.append((f"{stem}_{boundary.name}_slice_{k}_overhang.png",
                         lambda c=continuation, b=boundary, v=value, s=chosen, k=k:
                         overhang_diagram(c, b, v, state=s,
                                          title=_slice_title(caption(), b, k, v))))
    return jobs


def _slice_title(caption: Captions, boundary, k: int, value: float) -> str:
    """``"<study title>\n<slice label>: <second parameter> = <value> <unit>"``."""
    fixed = Fixed(boundary.parameter_names[1], float(value), boundary.parameter_units[1])
    return (f"{caption.title(boundary.parameter_names)}\n"
            f"{caption.slice_label(boundary.name, k)}: {fixed}")


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
    return re.sub(f"[^{PLOT_CHARACTERS}]", "_", name)


def _unique(path: Path, taken: list[Path]) -> Path:
    candidate, n = path, 1
    while candidate in taken:
        n += 1
        candidate = path.with_name(f"{path.stem}_{n}{path.suffix}")
    return candidate


FORMATS = ("png", "pdf", "svg")
"""File formats a figure is written in: PNG (raster, at the given dpi), and the vector
formats PDF (fonts embedded as TrueType) and SVG (text as paths)."""

VECTOR_RC = {"pdf.fonttype": 42, "svg.fonttype": "path", "svg.hashsalt": "whirl"}
"""matplotlib settings of the vector files: fonts embedded whole (type 42, not type 3
bitmaps), SVG text drawn as paths (no font needed to view it), SVG ids the same each run."""


def _own(suffix: str):
    """The kind of file (:class:`whirl_cli.output.guard.Own`) a figure of ``suffix`` may
    replace: a PNG, PDF or SVG file."""
    from ..output.guard import IMAGE, Own, _starting

    return {"png": IMAGE,
            "pdf": Own("a PDF document", _starting(b"%PDF-", "a file that is not PDF")),
            "svg": Own("an SVG image", _starting(b"<?xml", "a file that is not SVG"))}[suffix]


def rendered_formats(figure: Figure, formats: tuple[str, ...], dpi: int,
                     key: str | None = None) -> dict[str, bytes]:
    """``figure`` in each of ``formats`` (:data:`FORMATS`, in that order), the figure
    cleared afterwards. A file drawn after another keeps the layout of the first draw (not
    laid out again: the vector files of a sheet cost a draw each, not a layout too). Vector
    files are drawn with :data:`VECTOR_RC`, without dates: the same bytes run to run.
    ``key`` (if given) is stored in each: PNG text chunk, PDF and SVG keywords
    (:func:`stored_key_in`)."""
    from matplotlib import rc_context

    out: dict[str, bytes] = {}
    try:
        for suffix in formats:
            if out:
                figure.set_layout_engine("none")
            if suffix == "png":
                out[suffix] = _png(figure, dpi, {_KEY: key} if key else None, clear=False)
                continue
            buffer = io.BytesIO()
            keywords = f"{_KEY}:{key}" if key else None
            metadata = ({"CreationDate": None, "Keywords": keywords} if suffix == "pdf"
                        else {"Date": None, "Keywords": keywords})
            with rc_context(VECTOR_RC):  # the backend's canvas itself: savefig would draw
                _VECTOR_CANVAS[suffix](figure, buffer, metadata)  # twice, once to lay out
            out[suffix] = buffer.getvalue()
    finally:
        figure.clear()
    return out


def _pdf(figure: Figure, buffer: io.BytesIO, metadata: dict) -> None:
    from matplotlib.backends.backend_pdf import FigureCanvasPdf

    FigureCanvasPdf(figure).print_pdf(buffer, metadata=metadata)


def _svg(figure: Figure, buffer: io.BytesIO, metadata: dict) -> None:
    from matplotlib.backends.backend_svg import FigureCanvasSVG

    FigureCanvasSVG(figure).print_svg(buffer, metadata=metadata)


_VECTOR_CANVAS = {"pdf": _pdf, "svg": _svg}
"""Vector format -> a function drawing a figure into a buffer with that backend."""

_KEY = "whirl-figure-key"
_KEY_RE = re.compile(rb"whirl-figure-key:([0-9a-f]{64})")


def stored_key_in(data: bytes) -> str | None:
    """The key :func:`rendered_formats` stored in a PDF or SVG file's bytes (None: none)."""
    found = _KEY_RE.search(data)
    return found.group(1).decode() if found else None


def _png(figure: Figure, dpi: int, metadata: dict[str, str] | None = None,
         clear: bool = True) -> bytes:
    """``figure`` rendered as PNG bytes at ``dpi``, with ``metadata`` as PNG text chunks (the
    figure is cleared afterwards if ``clear``). Drawn once on its Agg canvas (its layout
    engine runs in that draw), then its pixels written: the pixels and PNG chunks ``savefig``
    writes, without its first pass over the figure, a draw that only lays it out."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.image import imsave

    buffer = io.BytesIO()
    try:
        canvas = figure.canvas
        if not isinstance(canvas, FigureCanvasAgg):  # not from _new_figure
            canvas = FigureCanvasAgg(figure)
        figure.set_dpi(dpi)
        canvas.draw()
        imsave(buffer, canvas.buffer_rgba(), format="png", origin="upper", dpi=dpi,
               metadata=metadata)
    finally:
        if clear:
            figure.clear()
    return buffer.getvalue()

