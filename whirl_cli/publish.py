"""A study's outputs as one unit: its HDF5 file and its plots appear together or not at all
(a stage above :mod:`whirl_cli.output` and :mod:`whirl_cli.plots`, which it imports inside its
functions).

:func:`publish_study` is how ``whirl run`` and ``whirl sweep`` write a finished study:

1. every plot is rendered in memory first (:func:`drawn_plots`; ``whirl run`` draws them
   while the cross-checks run, :func:`whirl_cli.pipeline.run_and_draw`); if drawing fails (a
   bug), the HDF5 file is still published, alone, and the error reported (the result is not
   lost, and a sweep draws the missing plots again next time);
2. without ``overwrite`` nothing is written if the HDF5 file or any of the plot files exists
   (one message naming the first such file); with it, nothing is written unless each one
   that exists is whirl's kind of file (:mod:`whirl_cli.output.guard`: a whirl result file,
   a PNG image; never a link, a directory, a device, a FIFO); both checked, and the files
   published, with the output directory locked against other whirl processes;
3. the files are published with SIGINT and SIGTERM held back (an interrupt arriving then is
   delivered once the set is complete): the plots first, the HDF5 file last. Its root
   attribute ``plots`` lists the plot files published with it. Each file appears complete or
   not at all (:func:`whirl_cli.output.atomic.publish`); if one cannot be written (a full
   disk), the plots already published are removed again, also with ``overwrite`` (an old
   HDF5 file then stays, without the plots it had: none of the new result stays). So only a
   SIGKILL can leave plots without their HDF5 file; a sweep treats a study
   without its HDF5 file as not run, and completes the plots of an up-to-date file that lacks
   some (:func:`missing_plots`);
4. with ``overwrite``, the plots the old HDF5 file recorded that the new result does not
   draw are removed once the new file is in place (no stale figure of an old result stays
   beside the new one; the lock makes the old file the one the last publisher replaced).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from .errors import OutputError
from .output import atomic, store
from .output.guard import IMAGE, RESULT, check, refusal
from .output.owners import PLOTS_ATTRIBUTE, check_plot, owner, recorded_plots
from .results import StudyResult
from .runtime import forked_map, held_signals


@dataclass(frozen=True)
class Published:
    """What :func:`publish_study` wrote (the HDF5 file last) and, if the plots could not be
    drawn, why (else "")."""

    paths: tuple[Path, ...]
    plot_error: str = ""


@dataclass(frozen=True)
class Drawn:
    """A result's plots rendered in memory: (file name, PNG bytes) in drawing order, or, if
    drawing failed (a bug), none and why."""

    plots: tuple[tuple[str, bytes], ...] = ()
    error: str = ""


def drawn_plots(result: StudyResult, kinds: Sequence[str], stem: str,
                state: str | None = None, jobs: int = 1) -> Drawn:
    """``result``'s plots of ``kinds`` rendered in memory (``<stem>_*.png``, bifurcation
    diagrams of ``state``, None: the first dof; in ``jobs`` forked processes, the same bytes in
    the same order for any ``jobs``, :func:`whirl_cli.plots.files.render_tasks`), or, if
    drawing failed (a bug in a figure, a drawing worker that died), none and the first error:
    a result is published with all its plots or without any. Never raises but for an
    interrupt."""
    if not kinds:
        return Drawn()
    from .plots.files import render_tasks

    try:
        tasks = render_tasks(result, tuple(kinds), stem, state)
        outcomes = forked_map(lambda k: _guarded(tasks[k]), len(tasks), jobs)
    except Exception as error:  # noqa: BLE001 - a bug in drawing: reported, never raised
        return Drawn((), _reason(error))
    errors = [outcome for outcome in outcomes if isinstance(outcome, str)]
    return Drawn((), errors[0]) if errors else Drawn(tuple(outcomes))


def _guarded(task: Callable[[], tuple[str, bytes]]) -> tuple[str, bytes] | str:
    """``task()``, or the error it raised as text (it travels back from a worker whole)."""
    try:
        return task()
    except Exception as error:  # noqa: BLE001 - a bug in drawing: reported, never raised
        return _reason(error)


def _reason(error: Exception) -> str:
    return f"plots: {type(error).__name__}: {error}"


def publish_study(result: StudyResult, output: Path, kinds: Sequence[str],
                  overwrite: bool = False, state: str | None = None, jobs: int = 1,
                  drawn: Drawn | None = None) -> Published:
    """Write ``result`` to ``output`` and its plots of ``kinds`` next to it (``<output
    stem>_*.png``; bifurcation diagrams of ``state``, None: the first dof; drawn in ``jobs``
    processes, unless ``drawn`` holds them already: :func:`drawn_plots` of the same
    ``kinds``), as one unit; see the module doc. The output directory is made here (and
    removed again if nothing could be published into it)."""
    output = Path(output)
    if drawn is None:
        drawn = drawn_plots(result, kinds, output.stem, state, jobs)
    made: list[Path] = []
    try:
        with held_signals():
            made = _made_directories(output)
        with atomic.locked(output.parent):  # one publisher at a time: its file, its plots
            return Published(_publish_unit(result, output, drawn.plots, overwrite),
                             drawn.error)
    except BaseException:
        for directory in reversed(made):  # only if still empty
            try:
                directory.rmdir()
            except OSError:
                break
        raise


def _made_directories(output: Path) -> list[Path]:
    """Make ``output``'s directory and its missing parents; the ones made, outermost first."""
    missing, directory = [], output.parent
    while not os.path.lexists(directory) and directory != directory.parent:
        missing.append(directory)
        directory = directory.parent
    try:
        output.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputError(f"{output}: cannot create the output directory "
                          f"({error.strerror or error})") from None
    return missing[::-1]


def _publish_unit(result: StudyResult, output: Path, plots: tuple[tuple[str, bytes], ...],
                  overwrite: bool) -> tuple[Path, ...]:
    """Steps 2-4 of the module doc, with the output directory locked: nothing is written
    unless every file may be (:func:`whirl_cli.output.guard.check`), and the stale plots are
    those of the result file found here."""
    targets = [output.parent / name for name, _ in plots]
    check(output, RESULT, overwrite)
    for path in targets:
        check_plot(path, output, overwrite)
    names = [name for name, _ in plots]
    stale = [output.parent / name for name in recorded_plots(output)
             if name not in names and _plain(name)
             and owner(output.parent / name, output) is None] if overwrite else []
    result = replace(result, attributes={**result.attributes, PLOTS_ATTRIBUTE: names})
    written: list[Path] = []
    with held_signals():
        try:
            for (_, data), path in zip(plots, targets, strict=True):
                written.append(atomic.publish(data, path, overwrite, what="the plot",
                                              own=IMAGE))
            written.append(store.write(result, output, overwrite=overwrite))
        except BaseException:  # e.g. a full disk: none of the new result's files stays
            for path in written:
                path.unlink(missing_ok=True)
            raise
        for path in stale:
            if not refusal(path, IMAGE):  # a plot whirl wrote, nothing put in its place
                path.unlink(missing_ok=True)
    return tuple(written)


def _plain(name: str) -> bool:
    """A file name alone (no directory part, not ``.`` or ``..``): what a plot's name is."""
    return name not in ("", ".", "..") and "/" not in name and "\0" not in name


def publish_plots(output: Path, kinds: Sequence[str], state: str | None = None
                  ) -> tuple[Path, ...]:
    """Draw the plots of ``kinds`` of the existing result ``output`` next to it (replacing
    files of the same names if they are PNG images; ``state`` as for :func:`publish_study`):
    how a sweep completes an up-to-date study's plots."""
    from .plots.files import render_study_plots

    rendered = render_study_plots(store.read(output), tuple(kinds), Path(output).stem, state)
    targets = [Path(output).parent / name for name, _ in rendered]
    for path in targets:
        check_plot(path, Path(output), overwrite=True)
    with held_signals():
        return tuple(atomic.publish(data, path, True, what="the plot", own=IMAGE)
                     for (_, data), path in zip(rendered, targets, strict=True))


def missing_plots(output: Path, kinds: Sequence[str]) -> list[str]:
    """Plot files of ``kinds`` that should stand beside the existing result ``output`` and do
    not: the ones it records, or, if it records none (written with ``--no-plots`` or by an
    older whirl), the ones its result draws."""
    if not kinds:
        return []
    names = recorded_plots(output)
    if not names:
        from .plots.files import plot_names

        names = tuple(plot_names(store.read(output), tuple(kinds), Path(output).stem))
    return [name for name in names if not (Path(output).parent / name).exists()]
