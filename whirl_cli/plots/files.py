"""A study's figures as PNG files: the kinds a study asks for (:data:`PLOT_KINDS`), their file
names, rendered in memory and published complete or not at all.
"""

from __future__ import annotations

import io
import re
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache, partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import OutputError, WhirlError
from ..output.guard import PLOT_CHARACTERS, plot_stem
from ..results import Branch, ContinuationResult, PointType, StudyResult
from .captions import Captions, Fixed, captions
from .key import PLOTTED_KINDS, drawn_points, legend_columns
from .kinds import Figures, plot_kinds, registry

if TYPE_CHECKING:
    from matplotlib.figure import Figure


PLOT_KINDS = plot_kinds()
"""The kinds a study's figures are drawn in (:mod:`whirl_cli.plots.kinds`), in drawing order."""

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
    return registry()[kind].missing(result)


def available_kinds(result: StudyResult) -> tuple[str, ...]:
    """The kinds of :data:`PLOT_KINDS` that ``result`` has the data for, in that order."""
    return tuple(kind for kind in plot_kinds() if not missing_data(result, kind))


def save_study_plots(result: StudyResult, kinds: tuple[str, ...], out_dir: Path, stem: str,
                     state: str | None = None, dpi: int = 150, view: View = View(),
                     result_file: Path | None = None, formats: tuple[str, ...] = ("png",)
                     ) -> list[Path]:
    """Write a study's figures as PNG files into ``out_dir`` (and each also in the other
    ``formats`` of :data:`FORMATS`, beside it: ``<name>.pdf``); return the paths, sorted.

    ``kinds``: any of :data:`PLOT_KINDS`; each kind's files are those its
    :class:`~whirl_cli.plots.kinds.PlotKind` declares (``figures``; docs/plots.md lists
    them), e.g. ``<stem>_<continuation>_bifurcation.png`` per one-parameter continuation
    (``state``: the state drawn, None: the first state, i.e. the model's first dof).

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
            check(out_dir / name, replaceable_image(Path(name).suffix[1:]), overwrite=True)
    return sorted(publish(data, out_dir / name, overwrite=True, what="the plot",
                          own=replaceable_image(Path(name).suffix[1:])) for name, data in rendered)


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
    its aspect by its box, not by moving the limits), its titles wrapped at the canvas edge
    (a long one is never clipped) and its legends off the data (:func:`legends_off_data`)."""
    for text in _titles(figure):
        text.set_wrap(True)
    for ax in figure.axes:
        if (view.xlim or view.ylim) and ax.get_aspect() != "auto":
            ax.set_adjustable("box")
        if view.xlim is not None:
            ax.set_xlim(*view.xlim)
        if view.ylim is not None:
            ax.set_ylim(*view.ylim)
    legends_off_data(figure)
    return figure


def legends_off_data(figure: Figure) -> None:
    """Move every axes legend that lies over drawn data (a vertex of a line, a point of a
    collection, found by laying ``figure`` out once, without rendering it) off it: beside the
    axes if the figure has one axes, else below all of them as one legend of the figure (each
    entry once)."""
    legends = [(ax, ax.get_legend()) for ax in figure.axes if ax.get_legend() is not None]
    if not legends:
        return
    figure.draw_without_rendering()
    covering = [(ax, legend) for ax, legend in legends if _over_data(ax, legend)]
    if len(figure.axes) == 1:
        for ax, legend in covering:
            legend.set_loc("upper left")
            legend.set_bbox_to_anchor((_right_of_texts(ax) + 0.02, 1.0),
                                      transform=ax.transAxes)
        return
    entries: dict[str, object] = {}
    for _, legend in covering:
        for handle, text in zip(legend.legend_handles, legend.get_texts(), strict=False):
            entries.setdefault(text.get_text(), handle)
        legend.remove()
    if entries:
        columns = min(3, legend_columns(list(entries), figure.get_size_inches()[0]))
        figure.legend(list(entries.values()), list(entries), loc="outside lower center",
                      fontsize="small", ncols=columns, frameon=False)


def _right_of_texts(ax) -> float:
    """The right edge, in axes fractions, of ``ax`` and of its texts drawn beside it (labels
    of the cases of a boundary map), 1.0 if none is."""
    box = ax.get_window_extent()
    right = max([box.x1, *(t.get_window_extent().x1 for t in ax.texts if t.get_visible())])
    return 1.0 + (right - box.x1) / max(box.width, 1.0)


def _over_data(ax, legend) -> bool:
    """Whether ``legend`` (drawn) covers a vertex of ``ax``'s lines or a point of its
    collections."""
    box = legend.get_window_extent()
    drawn = [(line.get_transform(), line.get_xydata()) for line in ax.lines
             if line.get_visible() and len(line.get_xdata())]
    drawn += [(c.get_offset_transform(), c.get_offsets()) for c in ax.collections
              if c.get_visible() and len(c.get_offsets())]
    for transform, data in drawn:
        xy = np.asarray(data, dtype=float).reshape(-1, 2)
        xy = transform.transform(xy[np.isfinite(xy).all(axis=1)])
        if ((xy[:, 0] > box.x0) & (xy[:, 0] < box.x1) & (xy[:, 1] > box.y0)
                & (xy[:, 1] < box.y1)).any():
            return True
    return False


def _titles(figure: Figure) -> list:
    """The figure's suptitle and every axes' titles (left, centre, right)."""
    texts = [figure._suptitle] if getattr(figure, "_suptitle", None) is not None else []
    return texts + [t for ax in figure.axes for t in (ax.title, ax._left_title, ax._right_title)]


def _named_jobs(result: StudyResult, kinds: tuple[str, ...], stem: str, state: str | None,
                view: View = View()):
    """(unique filesystem-safe file name, figure factory) pairs of the requested kinds."""
    unknown = set(kinds) - set(plot_kinds())
    if unknown:
        raise WhirlError(f"unknown plot kind(s) {sorted(unknown)}; choose from {plot_kinds()}")
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
    result = drawn_points(result, artefacts=view.artefacts)
    figures = Figures(result, stem, state, view, caption)
    return [job for name, kind in registry().items() if name in kinds
            for job in kind.figures(figures)]


def slice_title(caption: Captions, boundary, k: int, value: float) -> str:
    """``"<study title>\n<slice label>: <second parameter> = <value> <unit>"``."""
    fixed = Fixed(boundary.parameter_names[1], float(value), boundary.parameter_units[1])
    return (f"{caption.title(boundary.parameter_names)}\n"
            f"{caption.slice_label(boundary.name, k)}: {fixed}")


def phase_labels(branch: Branch, most: int = PHASE_ORBITS) -> list[int]:
    """Labels of the orbits a study's phase plane of ``branch`` draws, in branch order: of
    the orbits within the small-angle range (:func:`small_angle`; all of them if none is)
    and those stored at an ``orbits_at`` value (UZ), all if there are at most ``most``; else
    every UZ orbit and, up to ``most`` in all, others evenly spread along the branch (first
    and last included)."""
    orbits = sorted(branch.orbits, key=lambda o: o.index)
    within = [o for o in orbits if o.point_type == PointType.UZ or small_angle(branch, o)]
    orbits = within or orbits
    if len(orbits) <= most:
        return [o.label for o in orbits]
    asked = [o for o in orbits if o.point_type == PointType.UZ]
    others = [o for o in orbits if o.point_type != PointType.UZ]
    room = max(most - len(asked), 0)
    picks = np.unique(np.linspace(0, len(others) - 1, room).round().astype(int)) if room else []
    chosen = {id(o) for o in asked} | {id(others[k]) for k in picks}
    return [o.label for o in orbits if id(o) in chosen]


SMALL_ANGLE = float(np.radians(20.0))
"""Largest angle [rad] of the small-angle range the models assume (sin and tan of it differ
from it by 2 % and 4 %): a study's phase plane leaves out orbits that go beyond it."""


def small_angle(branch: Branch, orbit) -> bool:
    """Whether every angle state (unit rad) of ``orbit`` stays within :data:`SMALL_ANGLE`."""
    angles = [k for k, unit in enumerate(branch.state_units) if unit == "rad"]
    states = np.asarray(orbit.states, dtype=float)
    return bool(not angles or not states.size
                or np.nanmax(np.abs(states[:, angles])) <= SMALL_ANGLE)


def state_for(continuation: ContinuationResult, state: str | None) -> str | None:
    """``state`` if every plotted branch has it, else None (the first state)."""
    branches = [b for b in continuation.branches if b.kind in PLOTTED_KINDS]
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


def replaceable_image(suffix: str):
    """The kind of file (:class:`whirl_cli.output.guard.Own`) a figure of ``suffix`` may
    replace: a PNG, PDF or SVG file."""
    from ..output.guard import IMAGE, Own, starting

    return {"png": IMAGE,
            "pdf": Own("a PDF document", starting("a file that is not PDF", b"%PDF-")),
            "svg": Own("an SVG image", starting("a file that is not SVG", b"<?xml"))}[suffix]


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
        if not isinstance(canvas, FigureCanvasAgg):  # not from new_figure
            canvas = FigureCanvasAgg(figure)
        figure.set_dpi(dpi)
        canvas.draw()
        imsave(buffer, canvas.buffer_rgba(), format="png", origin="upper", dpi=dpi,
               metadata=metadata)
    finally:
        if clear:
            figure.clear()
    return buffer.getvalue()

