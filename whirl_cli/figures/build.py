"""``whirl figures`` (``make figures``): run what the sheets need, draw every sheet, write the
index (:func:`make_figures`).

1. every sheet is read and checked (all problems at once, nothing run);
2. the studies they name are run as one sweep into the results folder
   (:func:`whirl_cli.sweep.run.run_sweep`: up-to-date results are reused, studies run in
   parallel, without their own plots);
3. each sheet is drawn from the stored results and published as ``<out>/fig<n>.png``
   (complete or not at all); a sheet whose study failed, or whose panel cannot be drawn, is
   reported and left out, the others are drawn. A figure is not redrawn when its PNG holds the
   same key (:func:`figure_key`: the sheet's text, whirl's code, the resolution and the result
   files it draws);
4. ``<out>/index.html`` lists every figure with its caption, studies and command.
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
from ..results import StudyResult
from .index import Entry, figure_order, index_html
from .sheet import Sheet, find_sheets, load_sheet

KEY = "whirl-figure-key"
"""PNG text chunk holding a figure's :func:`figure_key`."""


@dataclass(frozen=True)
class FigureOutcome:
    """One sheet's result: the PNG (None: not drawn) and, if not, why; ``reused``: the PNG
    was up to date and not redrawn."""

    sheet: Sheet
    image: Path | None
    problem: str = ""
    reused: bool = False


def load_sheets(paths: Sequence[str | os.PathLike[str]]) -> list[Sheet]:
    """Every sheet named by ``paths`` (files, or folders of ``*.yaml``); a StudyError lists
    the problems of every bad sheet, and two sheets of one figure number."""
    sheets, problems = [], []
    for path in find_sheets(paths):
        try:
            sheets.append(load_sheet(path))
        except StudyError as error:
            problems.append(str(error))
    seen: dict[str, Path] = {}
    for sheet in sheets:
        if sheet.stem in seen:
            problems.append(f"{sheet.path}: figure {sheet.figure} is also drawn by "
                            f"{seen[sheet.stem]}")
        seen.setdefault(sheet.stem, sheet.path)
    if problems:
        raise StudyError("\n".join(problems))
    return sheets


def make_figures(paths: Sequence[str | os.PathLike[str]], out_dir: Path, results_dir: Path,
                 jobs: int = 1, force: bool = False, console=None, dpi: int = 150
                 ) -> list[FigureOutcome]:
    """Run, draw and index (module docstring); the outcome of every sheet, in figure order."""
    from ..output import store
    from ..output.atomic import publish
    from ..sweep.run import run_sweep
    from .draw import draw_sheet

    sheets = load_sheets(paths)
    studies = list(dict.fromkeys(p for s in sheets for p in s.studies()))
    tally = run_sweep(studies, results_dir, jobs=jobs, force=force, plots=False,
                      console=console)
    outputs, failed = {}, {}
    for outcome in tally.outcomes:
        source = Path(os.path.normpath(outcome.item.source))
        if outcome.status in ("ok", "failed", "skipped") and outcome.item.output is not None:
            outputs[source] = outcome.item.output
        else:
            failed[source] = "; ".join(outcome.problems) or outcome.status
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise WhirlError(f"cannot create figure folder {out_dir}: {exc}") from exc
    read: dict[Path, StudyResult] = {}
    outcomes = []
    for sheet in sorted(sheets, key=lambda s: figure_order(s.figure)):
        missing = [f"{p}: {failed.get(p, 'no result')}" for p in sheet.studies()
                   if p not in outputs]
        if missing:
            outcomes.append(FigureOutcome(sheet, None, "; ".join(missing)))
            continue
        target = out_dir / f"{sheet.stem}.png"
        key = figure_key(sheet, [outputs[p] for p in sheet.studies()], dpi)
        if not force and stored_key(target) == key:
            outcomes.append(FigureOutcome(sheet, target, reused=True))
            continue
        try:
            for path in sheet.studies():
                if path not in read:
                    read[path] = store.read(outputs[path])
            image = _render(draw_sheet(sheet, read), dpi, {KEY: key})
        except WhirlError as error:
            outcomes.append(FigureOutcome(sheet, None, str(error)))
            continue
        written = publish(image, target, overwrite=True, what="the figure")
        outcomes.append(FigureOutcome(sheet, written))
    page = index_html([_entry(o, out_dir) for o in outcomes], "whirl figures")
    publish(page.encode("utf-8"), out_dir / "index.html", overwrite=True, what="the index")
    return outcomes


def _render(figure, dpi: int, metadata: dict[str, str]) -> bytes:
    from ..plots.files import _png

    return _png(figure, dpi, metadata)


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
    """The :data:`KEY` text chunk of the PNG at ``path`` (None: no file, not a PNG, no key)."""
    try:
        data = path.read_bytes()
    except OSError:
        return None
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


def _entry(outcome: FigureOutcome, out_dir: Path) -> Entry:
    sheet = outcome.sheet
    command = f"whirl figures {shlex.quote(str(sheet.path))} -o {shlex.quote(str(out_dir))}"
    return Entry(sheet.figure, sheet.caption, sheet.note,
                 outcome.image.name if outcome.image else None,
                 tuple(str(p) for p in sheet.studies()), command, outcome.problem)
