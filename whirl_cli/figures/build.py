"""``whirl figures`` (``make figures``): run what the sheets need, draw every sheet, write the
index (:func:`make_figures`).

1. every sheet is read and checked (all problems at once, nothing run); a sheet that is not
   valid is reported and left out (:class:`Refused`), the others are drawn;
2. the studies they name are run as one sweep into the results folder
   (:func:`whirl_cli.sweep.run.run_sweep`: up-to-date results are reused, studies run in
   parallel, without their own plots);
3. each sheet is drawn from the stored results and published as ``<out>/fig<n>.png``,
   during the sweep as soon as its studies are stored and a worker is idle, the rest after
   it in parallel
   (complete or not at all); a sheet whose study failed, or whose panel cannot be drawn, is
   reported and left out, the others are drawn. A figure is not redrawn when its PNG holds the
   same key (:func:`figure_key`: the sheet's text, whirl's code, the resolution and the result
   files it draws);
4. ``<out>/index.html`` lists every figure with its caption, studies and sheet, the thesis's
   numbers beside whirl's (the sheets' ``thesis:`` entries) and the command that redraws
   the figures.
"""

from __future__ import annotations

import hashlib
import os
import shlex
import struct
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from ..errors import StudyError, WhirlError
from ..kinds import SweepStatus
from ..results import StudyResult
from .index import Entry, figure_order, index_html
from .numbers import comparisons
from .sheet import Sheet, find_sheets, load_sheet

KEY = "whirl-figure-key"
"""PNG text chunk holding a figure's :func:`figure_key`."""

DEFAULT_FORMATS = ("png", "pdf")
"""Formats of the figures unless told otherwise: the PNG and a PDF for print."""


@dataclass(frozen=True)
class Refused:
    """A sheet file that is not valid: its path, its problems (``file:line: key: reason``
    lines) and, for the index, its figure number (its file name where the number cannot be
    read) and caption. It draws no study."""

    path: Path
    problem: str
    figure: str
    caption: str = ""
    note: str = ""

    def studies(self) -> list[Path]:
        return []


@dataclass(frozen=True)
class FigureOutcome:
    """One sheet's result: the PNG (None: not drawn) and, if not, why; ``reused``: the PNG
    was up to date and not redrawn."""

    sheet: Sheet | Refused
    image: Path | None
    problem: str = ""
    reused: bool = False


def load_sheets(paths: Sequence[str | os.PathLike[str]]) -> tuple[list[Sheet], list[Refused]]:
    """Every sheet named by ``paths`` (files, or folders of ``*.yaml``): the valid ones, and
    those refused with their problems (a second sheet of a figure number is refused too)."""
    sheets, refused = [], []
    for path in find_sheets(paths):
        try:
            sheets.append(load_sheet(path))
        except StudyError as error:
            refused.append(Refused(path, error.message, *_figure_and_caption(path)))
    seen: dict[str, Path] = {}
    for sheet in list(sheets):
        if sheet.stem in seen:
            sheets.remove(sheet)
            refused.append(Refused(sheet.path, f"{sheet.path}: figure {sheet.figure} is also "
                                   f"drawn by {seen[sheet.stem]}", sheet.figure, sheet.caption,
                                   sheet.note))
        seen.setdefault(sheet.stem, sheet.path)
    return sheets, refused


def _figure_and_caption(path: Path) -> tuple[str, str]:
    """The figure number and caption of a sheet that is not valid, as far as they can be read
    (else its file name and no caption)."""
    from ..study import read_yaml_data

    try:
        data = read_yaml_data(path, "sheet")
    except StudyError:
        data = {}
    figure, caption = data.get("figure"), data.get("caption")
    return (figure if isinstance(figure, str) and figure.strip() else path.name,
            caption if isinstance(caption, str) else "")


def make_figures(paths: Sequence[str | os.PathLike[str]], out_dir: Path, results_dir: Path,
                 jobs: int = 1, force: bool = False, console=None, dpi: int = 150,
                 formats: Sequence[str] = DEFAULT_FORMATS, program: str = "whirl"
                 ) -> list[FigureOutcome]:
    """Run, draw and index (module docstring); the outcome of every sheet, in figure order.
    Each figure is written in every format of ``formats`` (:data:`whirl_cli.plots.files.
    FORMATS`; the PNG always, the index shows it). The index's redraw command starts with
    ``program`` (how whirl was called).

    While a worker is idle (no study left waiting for one), each study stored lets one sheet
    whose studies are all stored be drawn, so sheets of the short studies are drawn while the
    long ones still run; those left after the sweep are drawn ``jobs`` at a time (what a
    sheet shows does not depend on when or where it is drawn)."""
    from ..output.atomic import publish
    from ..output.guard import PAGE
    from ..sweep.run import run_sweep

    sheets, refused = load_sheets(paths)
    sheets.sort(key=lambda s: figure_order(s.figure))
    studies = list(dict.fromkeys(p for s in sheets for p in s.studies()))
    artist = _Artist(out_dir, force, dpi, ("png", *(f for f in formats if f != "png")))

    def stored(outcome, pending: int) -> None:
        artist.record(outcome)
        if 0 < pending < jobs:  # a worker is idle: draw one sheet that is ready on its core
            # (the smallest: the next study's result waits for it); at the end, every sheet
            # left is drawn in parallel (draw_ready)
            ready = [s for s in sheets if artist.ready(s)]
            if ready:
                artist.draw_ready([min(ready, key=lambda s: len(s.panels))], jobs=1)

    if studies:
        run_sweep(studies, results_dir, jobs=jobs, force=force, plots=False, console=console,
                  on_outcome=stored)
    artist.draw_ready(sheets, jobs)
    _make_folder(out_dir)
    outcomes = [artist.outcome(sheet) for sheet in sheets]
    outcomes += [FigureOutcome(sheet, None, sheet.problem) for sheet in refused]
    outcomes.sort(key=lambda o: figure_order(o.sheet.figure))
    numbers = tuple(row for sheet in sheets for row in comparisons(sheet, artist.result))
    redraw = redraw_command(program, paths, out_dir, results_dir, formats)
    page = index_html([_entry(o) for o in outcomes], "whirl figures",
                      _about(artist.read.values()), numbers, redraw)
    publish(page.encode("utf-8"), out_dir / "index.html", overwrite=True, what="the index",
            own=PAGE)
    return outcomes


def redraw_command(program: str, paths: Sequence[str | os.PathLike[str]], out_dir: Path,
                   results_dir: Path, formats: Sequence[str]) -> str:
    """The shell command that draws the figures again as this call did (from the same
    folder; up-to-date results and figures are reused)."""
    words = [*shlex.split(program), "figures", *map(str, paths), "-o", str(out_dir),
             "--results", str(results_dir)]
    if tuple(formats) != DEFAULT_FORMATS:
        words += ["--format", ",".join(formats)]
    return shlex.join(words)


def _about(results) -> dict[str, str]:
    """whirl's version, commit and AUTO engine as the result files drawn record them (each
    distinct value once; this whirl's version when no result was read)."""
    from .. import __version__

    records = [r.provenance for r in results]
    about = {}
    for name, values in (("whirl", [p.whirl_version for p in records]),
                         ("commit", [p.git_describe for p in records]),
                         ("engine", [p.auto_version for p in records])):
        if any(values):
            about[name] = ", ".join(sorted(set(filter(None, values))))
    about.setdefault("whirl", __version__)
    return about


def _make_folder(out_dir: Path) -> None:
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise WhirlError(f"cannot create figure folder {out_dir}: {exc}") from exc


class _Artist:
    """Draws sheets from stored results as they arrive: :meth:`record` each sweep outcome,
    :meth:`draw_ready` sheets that are :meth:`ready` (their studies all stored),
    :meth:`outcome` of every sheet at the end (why a sheet was not drawn)."""

    def __init__(self, out_dir: Path, force: bool, dpi: int, formats: tuple[str, ...]
                 ) -> None:
        self.out_dir, self.force, self.dpi, self.formats = out_dir, force, dpi, formats
        self.outputs: dict[Path, Path] = {}
        self.failed: dict[Path, str] = {}
        self.read: dict[Path, StudyResult] = {}
        self.done: dict[Path, FigureOutcome] = {}

    def record(self, outcome) -> None:
        source = Path(os.path.normpath(outcome.item.source))
        if outcome.status in (SweepStatus.OK, SweepStatus.FAILED, SweepStatus.SKIPPED) \
                and outcome.item.output is not None:
            self.outputs[source] = outcome.item.output
        elif outcome.status == SweepStatus.INVALID:  # its problems name the study file
            self.failed[source] = "; ".join(outcome.problems)
        else:
            self.failed[source] = f"{source}: " + ("; ".join(outcome.problems)
                                                   or outcome.status)

    def draw_ready(self, sheets: Sequence[Sheet], jobs: int) -> None:
        """Every sheet of ``sheets`` that is ready, ``jobs`` at a time in forked processes
        (in this one if ``jobs`` < 2; the largest first; each returns its PNG, published
        here)."""
        todo = [s for s in sheets if self.ready(s)]
        keys = {}
        for sheet in todo:
            keys[sheet.path], reused = self._reused(sheet)
            if reused is not None:
                self.done[sheet.path] = reused
        todo = sorted((s for s in todo if s.path not in self.done),
                      key=lambda s: len(s.panels), reverse=True)
        from ..runtime import forked_map

        images = forked_map(lambda k: self._image(todo[k], keys[todo[k].path]), len(todo),
                            jobs)
        for sheet, (image, problem) in zip(todo, images, strict=True):
            self.done[sheet.path] = self._published(sheet, image, problem)

    def outcome(self, sheet: Sheet) -> FigureOutcome:
        """``sheet``'s outcome once every ready sheet is drawn (:meth:`draw_ready`)."""
        if sheet.path in self.done:
            return self.done[sheet.path]
        missing = [self.failed.get(p, f"{p}: no result") for p in sheet.studies()
                   if p not in self.outputs]
        return FigureOutcome(sheet, None, "; ".join(missing))

    def ready(self, sheet: Sheet) -> bool:
        """Not drawn yet, and every study it draws is stored."""
        return sheet.path not in self.done and all(p in self.outputs for p in sheet.studies())

    def _reused(self, sheet: Sheet) -> tuple[str, FigureOutcome | None]:
        """The sheet's :func:`figure_key`, and its outcome if its file of every format has
        that key."""
        target = self.out_dir / f"{sheet.stem}.png"
        key = figure_key(sheet, [self.outputs[p] for p in sheet.studies()], self.dpi)
        if not self.force and all(stored_key(self.out_dir / f"{sheet.stem}.{suffix}") == key
                                  for suffix in self.formats):
            return key, FigureOutcome(sheet, target, reused=True)
        return key, None

    def result(self, path: Path) -> StudyResult:
        """The stored result of the study at ``path`` (read once); a WhirlError says why
        there is none."""
        from ..output import store

        if path not in self.read:
            if path not in self.outputs:
                raise WhirlError(self.failed.get(path, f"{path}: no result"))
            self.read[path] = store.read(self.outputs[path])
        return self.read[path]

    def _image(self, sheet: Sheet, key: str) -> tuple[dict[str, bytes] | None, str]:
        """The sheet's file of each format (carrying ``key``), or None and why it cannot be
        drawn."""
        from .draw import sheet_files

        try:
            for path in sheet.studies():
                self.result(path)
            return sheet_files(sheet, self.read, self.formats, self.dpi, key), ""
        except WhirlError as error:
            return None, str(error)
        except Exception as error:  # noqa: BLE001 - a bug in drawing: this sheet only
            return None, f"{sheet.path}: {type(error).__name__}: {error}"

    def _published(self, sheet: Sheet, files: dict[str, bytes] | None, problem: str
                   ) -> FigureOutcome:
        """Publish the sheet's files, the vector ones first, the PNG (whose key says the
        figure is up to date) last."""
        from ..output.atomic import publish
        from ..plots.files import replaceable_image

        if files is None:
            return FigureOutcome(sheet, None, problem)
        _make_folder(self.out_dir)
        for suffix in sorted(files, key=lambda s: s == "png"):
            publish(files[suffix], self.out_dir / f"{sheet.stem}.{suffix}", overwrite=True,
                    what="the figure", own=replaceable_image(suffix))
        return FigureOutcome(sheet, self.out_dir / f"{sheet.stem}.png")


def figure_key(sheet: Sheet, outputs: Sequence[Path], dpi: int) -> str:
    """sha256 (hex) of what a figure is drawn from: the sheet's text, whirl's version and code
    fingerprint, ``dpi``, and per result file its study hash, code hash, size and mtime."""
    import h5py

    from .. import __version__
    from ..output.provenance import code_sha256

    digest = hashlib.sha256()
    for part in (sheet.path.read_bytes(), __version__, code_sha256(), str(dpi)):
        digest.update(part if isinstance(part, bytes) else part.encode())
        digest.update(b"\0")
    for output in outputs:
        status = output.stat()
        with h5py.File(output, "r") as stored:
            attrs = [str(stored.attrs.get(k, "")) for k in ("study_sha256", "whirl_code_sha256")]
        digest.update("|".join([*attrs, str(status.st_size), str(status.st_mtime_ns)]).encode())
        digest.update(b"\0")
    return digest.hexdigest()


def stored_key(path: Path) -> str | None:
    """The :data:`KEY` text chunk of the PNG at ``path``, or the key a PDF or SVG file
    there carries (None: no regular file, no key)."""
    if not os.path.isfile(path):  # a FIFO would block the read
        return None
    try:
        data = path.read_bytes()
    except OSError:
        return None
    if path.suffix != ".png":
        from ..plots.files import stored_key_in

        return stored_key_in(data)
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return None
    at = 8
    while at + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        if kind == b"tEXt":
            name, _, value = data[at + 8:at + 8 + length].partition(b"\0")
            if name == KEY.encode():
                return value.decode("latin-1")
        if kind == b"IEND":
            return None
        at += 12 + length
    return None


def _entry(outcome: FigureOutcome) -> Entry:
    sheet = outcome.sheet
    return Entry(sheet.figure, sheet.caption, sheet.note,
                 outcome.image.name if outcome.image else None,
                 tuple(str(p) for p in sheet.studies()), str(sheet.path), outcome.problem)
