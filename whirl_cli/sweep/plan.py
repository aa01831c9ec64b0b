"""Planning a sweep (pure, no AUTO): which studies to (re)run, skip, complete or refuse.

:func:`plan` finds the study files, validates them, names each output
``<out_dir>/<study name>.h5`` and decides per study: ``run`` (no output yet, the study, whirl
or the AUTO engine changed, or ``force``), ``skip`` (the output holds the same
``study_sha256``, ``whirl_version``, ``whirl_code_sha256`` and, where stored,
``auto_version``), ``plot`` (up to date, but plots it should have are
missing: they are drawn from the stored result) or ``invalid`` (the YAML does not validate, or
two files share a name).
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import h5py

from .. import __version__
from ..auto.toolchain import auto_version
from ..errors import StudyError, WhirlError
from ..kinds import BranchKind, RunStatus, SweepAction
from ..models import MODEL_SUFFIX, file_key
from ..output.mapping import word
from ..output.provenance import code_sha256
from ..output.store import check_contents
from ..publish import missing_plots
from ..study import Study, load_study
from ..verdict import is_problem

RUN, SKIP, PLOT, INVALID = (SweepAction.RUN, SweepAction.SKIP, SweepAction.PLOT,
                             SweepAction.INVALID)


@dataclass(frozen=True)
class SweepItem:
    """One study file of a sweep and what to do with it.

    ``action``: what to do with it; ``reason`` says why (e.g. "new", "study
    changed", "up to date", "up to date, plots missing", or the validation errors).
    ``stored_problems``: problems recorded in an up-to-date output that is skipped (failed
    branches or cross-checks), so that a resumed sweep still reports them.
    """

    source: Path
    action: SweepAction
    reason: str
    study: Study | None = None
    output: Path | None = None
    stored_problems: tuple[str, ...] = ()

    @property
    def name(self) -> str:
        return self.study.name if self.study is not None else self.source.name


def find_studies(paths: Iterable[str | os.PathLike[str]], what: str = "study files"
                 ) -> list[Path]:
    """Study files named by ``paths``: files as given, directories searched recursively for
    ``*.yaml`` (sorted) other than model files (``*.model.yaml``); each file once, in the
    order found. ``what`` names them in errors."""
    found: list[Path] = []
    seen: set[Path] = set()
    for entry in map(Path, paths):
        if entry.is_dir():
            candidates = sorted(p for p in entry.rglob("*.yaml") if p.is_file()
                                and not p.name.endswith(MODEL_SUFFIX))
            if not candidates:
                raise WhirlError(f"{entry}: no {what} (*.yaml) in this directory")
        elif entry.exists():
            candidates = [entry]
        else:
            raise WhirlError(f"{entry}: no such file or directory")
        for path in candidates:
            key = path.resolve()
            if key not in seen:
                seen.add(key)
                found.append(path)
    return found


def plan(paths: Iterable[str | os.PathLike[str]], out_dir: str | os.PathLike[str],
         force: bool = False, plots: bool = True) -> list[SweepItem]:
    """What a sweep of ``paths`` into ``out_dir`` will do, study by study (no AUTO, no writes).

    A study is skipped when ``<out_dir>/<study name>.h5`` exists with the same
    ``study_sha256``, ``whirl_version``, ``whirl_code_sha256`` and ``auto_version`` (the AUTO
    engine, :func:`whirl_cli.auto.toolchain.auto_version`; not checked if not stored) root
    attributes, unless ``force``; if ``plots`` and some of its plots are missing, they are
    drawn ("plot").
    """
    out_dir = Path(out_dir)
    items: list[SweepItem] = []
    owners: dict[str, Path] = {}
    for path in find_studies(paths):
        try:
            study = load_study(path, label=str(path))
        except StudyError as error:
            items.append(SweepItem(path, INVALID, error.message))
            continue
        if study.name in owners:
            items.append(SweepItem(path, INVALID, f"{path}: study name {study.name!r} is also "
                                   f"used by {owners[study.name]} (outputs would collide)",
                                   study))
            continue
        owners[study.name] = path
        output = out_dir / f"{study.name}.h5"
        action, reason, problems = _decide(study, output, force)
        if action == SKIP and plots:
            try:
                if missing_plots(output, study.plots):
                    action, reason = PLOT, "up to date, plots missing"
            except (OSError, KeyError, ValueError, WhirlError) as error:
                action, reason = RUN, f"unreadable output ({type(error).__name__})"
        items.append(SweepItem(path, action, reason, study, output, problems))
    return items


def _decide(study: Study, output: Path, force: bool) -> tuple[SweepAction, str, tuple[str, ...]]:
    """(action, reason, stored problems) for one valid study and its output path."""
    if force:
        return RUN, "forced", ()
    if not output.exists():
        return RUN, "new", ()
    if output.is_symlink() or not output.is_file():  # never opened: a FIFO would block
        return RUN, "not a result file", ()
    try:
        stored = stored_state(output)
    except (OSError, KeyError, ValueError) as error:
        return RUN, f"unreadable output ({type(error).__name__})", ()
    if stored.study_sha256 != study.sha256:
        return RUN, "study changed", ()
    if stored.model_key != file_key(study.model):
        return RUN, "model file changed", ()
    if stored.whirl_version != __version__:
        return RUN, f"whirl {stored.whirl_version} -> {__version__}", ()
    if stored.code_sha256 != code_sha256():
        return RUN, "whirl's code changed", ()
    if stored.auto_version and stored.auto_version != auto_version():
        return RUN, f"AUTO engine {stored.auto_version} -> {auto_version()}", ()
    return SKIP, "up to date", stored.problems


@dataclass(frozen=True)
class StoredState:
    """What a sweep needs to know of an existing result file."""

    study_sha256: str
    whirl_version: str
    code_sha256: str  # "" in files written before whirl recorded it
    problems: tuple[str, ...]  # by the failure policy of :mod:`whirl_cli.verdict`
    auto_version: str = ""  # the AUTO engine's version (toolchain.auto_version); "" if unknown
    model_key: str = ""  # what a model file declares (its content key); "" for a built-in


def stored_state(output: Path) -> StoredState:
    """The provenance and stored problems of an existing result file, read with h5py (root
    attributes, branch attributes and cross-check outcomes only, not the data);
    :class:`whirl_cli.output.mapping.Damaged` if a group it was written with is missing."""
    def text(value) -> str:
        return value.decode() if isinstance(value, bytes) else str(value)

    problems: list[str] = []
    with h5py.File(output, "r") as handle:
        check_contents(handle)  # a file not whole is not up to date (Damaged)
        attrs = handle.attrs
        for name, group in handle.get("continuations", {}).items():
            for branch, sub in group.get("branches", {}).items():
                if is_problem(word(BranchKind, text(sub.attrs.get("kind", "")), sub.name, "kind"),
                              word(RunStatus, text(sub.attrs.get("status", "ok")), sub.name,
                                   "status")):
                    problems.append(f"{branch} ({text(sub.attrs.get('run', ''))}): "
                                    f"{text(sub.attrs.get('message', ''))}")
            if "cross_checks" in group:
                failed = int((~group["cross_checks/passed"][()].astype(bool)).sum())
                if failed:
                    problems.append(f"{failed} cross-check(s) failed in {name}")
        return StoredState(text(attrs["study_sha256"]), text(attrs["whirl_version"]),
                           text(attrs.get("whirl_code_sha256", "")), tuple(problems),
                           text(attrs.get("auto_version", "")),
                           text(attrs.get("model_key", "")))

