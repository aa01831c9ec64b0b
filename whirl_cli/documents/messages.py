"""Pydantic's validation errors of a YAML file (a study, a sheet, a model file) as whirl's
messages: (key path, reason), and the report.

:func:`translate` turns one pydantic error into (YAML key path, reason), with the value as
written in the file; :func:`report` sorts the problems by line and prints them as
``<file>:<line>: <key.path>: <reason>``. :func:`_walk`, :func:`strip` and their helpers read
the schema's annotations.
"""

from __future__ import annotations

import types
from typing import Annotated, Any, Union, get_args, get_origin

from pydantic import BaseModel

from .source import Loc, Problem, Tree


def report(problems: list[Problem], tree: Tree, name: str) -> str:
    """The problems as ``<file>:<line>: <key.path>: <reason>`` lines, sorted by line."""
    lines = sorted((tree.line(loc), dotted(loc), reason) for loc, reason in problems)
    return "\n".join(f"{name}:{line}: {path}: {reason}" for line, path, reason in lines)


def dotted(loc: Loc) -> str:
    """``('continuations', 0, 'range')`` -> ``continuations[0].range``."""
    text = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in loc)
    return text.removeprefix(".")


_MAPPING_ERRORS = {"dict_type", "model_type", "model_attributes_type"}
_LIST_ERRORS = {"tuple_type", "list_type"}
_LENGTH_ERRORS = {"too_short": ("min_length", "at least"), "too_long": ("max_length", "at most")}


def translate(error: Any, tree: Tree, root: type[BaseModel]) -> Problem:
    """One pydantic error of a file validated as ``root`` as (key path, reason)."""
    loc, owner, annotation = _walk(error["loc"], root)
    if loc[:2] == ("nonlinearity", 0) and isinstance(tree.data.get("nonlinearity"), dict):
        loc = loc[:1] + loc[2:]  # one law mapping counts as a list of one: report at it
    kind = error["type"]
    if kind == "whirl":
        loc += tuple(error["ctx"].get("at", ()))
        template = error["ctx"]["reason"]
        return loc, template.format(got=tree.shown(loc), value=tree.flow(loc))
    if kind == "missing" and loc and isinstance(loc[-1], int):  # a fixed-length list
        return loc[:-1], f"expected {loc[-1] + 1} items, got {tree.flow(loc[:-1])}"
    if kind == "missing":
        return loc, "required key is missing"
    if kind in _LENGTH_ERRORS:
        limit, most = _LENGTH_ERRORS[kind]
        return loc, f"expected {most} {error['ctx'][limit]} items, got {tree.flow(loc)}"
    if kind == "extra_forbidden":
        return loc, f"unknown key (allowed: {', '.join(owner.model_fields)})"
    if kind in ("union_tag_invalid", "union_tag_not_found"):
        loc += (error["ctx"]["discriminator"].strip("'"),)
        if loc not in tree.nodes:
            return loc, "required key is missing"
        return loc, choice_reason([_tag(m) for m in union_members(annotation)], tree.shown(loc))
    if kind == "literal_error":
        return loc, choice_reason(get_args(annotation), tree.shown(loc))
    if kind in _MAPPING_ERRORS:
        return loc, f"expected a mapping, got {tree.shown(loc)}"
    if kind in _LIST_ERRORS:
        return loc, f"expected a list, got {tree.shown(loc)}"
    return loc, error["msg"]


def choice_reason(options: Any, got: str) -> str:
    """The reason for a value not among ``options``."""
    return f"expected one of {', '.join(map(str, options))}, got {got}"


def _walk(loc: tuple, root: type[BaseModel]) -> tuple[Loc, type[BaseModel], Any]:
    """A pydantic loc as (YAML key path, model owning its last key, annotation at its end).

    Union tags in the loc (``nonlinearity.polynomial.K2``) are not YAML keys and are dropped.
    """
    path: list[str | int] = []
    owner: type[BaseModel] = root
    annotation: Any = root
    for part in loc:
        annotation = strip(annotation)
        members = union_members(annotation)
        if members:
            annotation = next((m for m in members if _tag(m) == part), None)
            continue
        path.append(part)
        if isinstance(annotation, type) and issubclass(annotation, BaseModel):
            owner = annotation
            field = annotation.model_fields.get(str(part))
            annotation = field.annotation if field else None
        else:
            args = get_args(annotation)
            annotation = args[0] if args[-1:] == (Ellipsis,) else (args[-1] if args else None)
    return tuple(path), owner, strip(annotation)


def strip(annotation: Any) -> Any:
    """``annotation`` without Annotated metadata and without ``| None``."""
    while True:
        if get_origin(annotation) is Annotated:
            annotation = get_args(annotation)[0]
        elif _is_union(annotation) and type(None) in get_args(annotation):
            rest = [a for a in get_args(annotation) if a is not type(None)]
            annotation = rest[0] if len(rest) == 1 else Union[tuple(rest)]  # noqa: UP007
        else:
            return annotation


def _is_union(annotation: Any) -> bool:
    return get_origin(annotation) in (Union, types.UnionType)


def union_members(annotation: Any) -> list[type[BaseModel]]:
    """The models of a discriminated union, else []."""
    return list(get_args(annotation)) if _is_union(annotation) else []


def _tag(model: type[BaseModel]) -> str:
    return get_args(model.model_fields["type"].annotation)[0]

