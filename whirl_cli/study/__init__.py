"""Study files: YAML in, a frozen and validated :class:`Study` out.

:func:`load_study` (a file) and :func:`validate_text` (a string) are the validating entry points.
They report every problem at once, as ``<file>:<line>: <key.path>: <reason>`` lines in a
:class:`~whirl_cli.errors.StudyError`, and never let a traceback escape for bad input.

How a file is read:

1. bytes: at most :data:`MAX_BYTES`, UTF-8 (:mod:`~whirl_cli.documents.source`);
2. YAML, composed with a SafeLoader subclass into nodes (for line numbers): anchors, aliases,
   tags beyond the core ones (str, int, float, bool, null, seq, map) and nesting deeper than
   :data:`~whirl_cli.documents.source.MAX_DEPTH` are refused. Two YAML 1.1 surprises are switched
   off: only ``true`` and ``false`` are booleans (``yes``, ``on`` stay strings) and ``1e-6`` is
   a number; dates stay strings and ``<<`` is a plain key (:mod:`~whirl_cli.documents.source`);
3. plain Python data from the nodes, scalars built by the safe constructors; duplicate keys are
   reported (:mod:`~whirl_cli.documents.source`);
4. structure: the pydantic models of :mod:`~whirl_cli.study.schema` (``extra="forbid"``), their
   errors translated into the reasons that tests/unit/test_study.py spells out
   (:mod:`~whirl_cli.documents.messages`);
5. meaning, on the raw data so that it adds to the structural problems: parameter names known
   to the model variant, ``K2``/``K3`` only under ``nonlinearity``, ``dof`` a degree of freedom
   of the model, unique continuation names, ``start`` inside ``range``, simulations' initial
   states and overrides (:mod:`~whirl_cli.study.checks`).

Validation also fills the model-dependent defaults (:mod:`~whirl_cli.study.resolve`):
``nonlinearity.dof`` (the family's default), ``continuations[].parameter`` and
``linear.sweeps[].parameter`` become canonical names (``K_theta`` -> ``K1``), and
``continuations[].start`` gets the parameter's study value when the file leaves it out.
``Study.model_validate`` applies these fills too, but only the two entry points check parameter
names and ranges against the model.

Modules, lowest first (each imports only those above it, :mod:`whirl_cli.models`,
:mod:`whirl_cli.documents` -- the reader, the value types and the messages -- and the schema
:mod:`whirl_cli.continuation.numerics` for the AUTO defaults its step checks use):

* :mod:`~whirl_cli.study.resolve` -- model-dependent defaults filled on the raw data;
* :mod:`~whirl_cli.study.continuations` -- the continuation types' registry;
* :mod:`~whirl_cli.study.schema` -- the pydantic models;
* :mod:`~whirl_cli.study.checks` -- meaning checks against the model variant;
* :mod:`~whirl_cli.study.reference` -- the YAML reference table, read off the schema.

This package exports its entry points and the schema's models; everything else is imported
from its module.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Callable
from pathlib import Path

from pydantic import BaseModel, ValidationError

from ..documents.messages import report, translate
from ..documents.source import MAX_BYTES, Problem, Tree, compose, read_text, too_large
from ..errors import StudyError
from ..models import is_model_file, load_model_file, register_model_text
from .checks import meaning_problems
from .reference import schema_reference
from .schema import (
    AutoSettings,
    Linear,
    LinearAxisSpec,
    LinearSpec,
    LinearSweepSpec,
    OneParameterContinuation,
    Polynomial,
    Study,
    TwoParameterContinuation,
)

__all__ = [
    "MAX_BYTES",
    "AutoSettings",
    "Linear",
    "LinearSpec",
    "LinearAxisSpec",
    "LinearSweepSpec",
    "OneParameterContinuation",
    "Polynomial",
    "Study",
    "TwoParameterContinuation",
    "load_study",
    "load_yaml_file",
    "read_yaml_data",
    "schema_reference",
    "stored_study",
    "validate_text",
]


def load_study(path: str | os.PathLike[str], label: str | None = None) -> Study:
    """Read, check and return the study at ``path``; StudyError lists every problem, each
    line starting with ``label`` (default: the file's name). A model file the study names is
    read relative to the study's folder."""
    path = Path(path)
    label = path.name if label is None else label
    return _validate(read_text(path, label), label, str(path), path.parent)


def validate_text(text: str, filename: str = "<study>",
                  model_file: tuple[str, str] | None = None) -> Study:
    """Check the study YAML ``text``; messages name it ``filename``. A model file it names is
    read relative to the working directory, or is ``model_file`` = (reference, text) where
    given (the model stored with a result)."""
    return _validate(text, filename, filename, Path.cwd(), model_file)


def load_yaml_file(path: Path, model: type[BaseModel], what: str,
                   checks: Callable[[BaseModel], list[Problem]] | None = None) -> BaseModel:
    """Another YAML file read as studies are (``what``: its kind, e.g. "sheet"): the same
    limits and YAML rules, validated as the pydantic ``model``, then ``checks`` (key path,
    reason) on the valid object; StudyError lists every problem as ``<path>:<line>: <key>:
    <reason>``."""
    label = str(path)
    tree = Tree(compose(read_text(Path(path), label, what), label, what))
    problems = list(tree.problems)
    found = None
    try:
        found = model.model_validate(tree.data)
    except ValidationError as error:
        problems += [translate(e, tree, model) for e in error.errors(include_url=False)]
    if found is not None and checks is not None:
        problems += checks(found)
    if problems:
        raise StudyError(report(problems, tree, label))
    return found


def read_yaml_data(path: Path, what: str = "study") -> dict:
    """The data of a YAML file read as studies are, not validated (StudyError where it is
    not readable YAML of a mapping)."""
    return Tree(compose(read_text(Path(path), Path(path).name, what), Path(path).name,
                          what)).data


def stored_study(provenance, filename: str = "<stored study>") -> Study:
    """The study stored with a result (its :class:`~whirl_cli.results.Provenance`:
    ``study_yaml``, and the model file beside it where it names one), validated against
    today's schema; StudyError if it does not validate."""
    stored = None
    if provenance.model_file_yaml:
        stored = (provenance.model_file, provenance.model_file_yaml)
    return validate_text(provenance.study_yaml, filename, stored)


def _model_reference(tree: Tree, name: str, folder: Path,
                     stored: tuple[str, str] | None) -> None:
    """Where the study names a model file, read it (StudyError for its problems, each at its
    own file and line) and put its reference in the data; a missing file is left for the
    schema to report at ``model``."""
    written = tree.data.get("model")
    if not is_model_file(written):
        return
    if stored is not None:
        tree.data["model"] = register_model_text(stored[0], stored[1], written)
        return
    target = Path(written) if Path(written).is_absolute() else folder / written
    if target.is_file():
        label = written if Path(written).is_absolute() else os.path.normpath(
            Path(name).parent / written)
        tree.data["model"] = load_model_file(target, label)


def _validate(text: str, name: str, path: str, folder: Path,
              model_file: tuple[str, str] | None = None) -> Study:
    try:
        encoded = text.encode("utf-8")
    except UnicodeEncodeError as error:
        code, offset = ord(text[error.start]), error.start
        reason = f"not UTF-8 text (character U+{code:04X} at offset {offset})"
        raise StudyError(f"{name}: {reason}") from None
    if len(encoded) > MAX_BYTES:
        raise StudyError(too_large(name, len(encoded)))
    tree = Tree(compose(text, name))
    _model_reference(tree, name, folder, model_file)
    study, problems = _check(tree)
    if problems:
        raise StudyError(report(problems, tree, name))
    study._source, study._sha256, study._path = text, hashlib.sha256(encoded).hexdigest(), path
    study._read = dict(study.__dict__)
    return study


def _check(tree: Tree) -> tuple[Study | None, list[Problem]]:
    """The study (None if its structure is invalid) and every problem found."""
    problems = []
    try:
        study = Study.model_validate(tree.data)
    except ValidationError as error:
        study = None
        problems = [translate(e, tree, Study) for e in error.errors(include_url=False)]
    problems += meaning_problems(tree.data)
    return study, tree.problems + [p for p in problems if p[0] not in tree.unreadable]

