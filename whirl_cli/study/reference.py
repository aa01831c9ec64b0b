"""The study YAML reference: a Markdown table of every key, read off the schema (the table of
docs/study-yaml.md, tested to be this one).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any, Literal, get_args, get_origin

from pydantic import BaseModel
from pydantic.fields import FieldInfo

from ..documents.messages import strip, union_members
from .schema import Study


def schema_reference() -> str:
    """Markdown table of every study key: path, type, default, description."""
    rows: dict[str, list[str]] = {}
    for path, field in _fields(Study, ""):
        shown = (field.json_schema_extra or {}).get("type_text")  # a type the YAML spells so
        row = [shown or _type_text(field.annotation), _default_text(field),
               field.description or ""]
        if path in rows and rows[path][0] != row[0]:
            rows[path][0] += " or " + row[0]
        rows.setdefault(path, row)
    lines = ["| Key | Type | Default | Description |", "| --- | --- | --- | --- |"]
    lines += [f"| `{path}` | {' | '.join(row)} |" for path, row in rows.items()]
    return "\n".join(lines) + "\n"


def _fields(model: type[BaseModel], prefix: str) -> Iterator[tuple[str, FieldInfo]]:
    """(key path, field) for ``model`` and the models nested in it, depth first."""
    for name, field in model.model_fields.items():
        path = prefix + name
        yield path, field
        annotation = strip(field.annotation)
        suffix = ""
        if get_origin(annotation) is tuple and get_args(annotation)[-1:] == (Ellipsis,):
            annotation, suffix = strip(get_args(annotation)[0]), "[]"
        for member in union_members(annotation) or [annotation]:
            if isinstance(member, type) and issubclass(member, BaseModel):
                yield from _fields(member, f"{path}{suffix}.")


def _type_text(annotation: Any) -> str:
    annotation = strip(annotation)
    origin, args = get_origin(annotation), get_args(annotation)
    simple = {bool: "true/false", int: "integer", float: "number", str: "string"}
    if annotation in simple:
        return simple[annotation]
    if origin is Literal:
        return " or ".join(f"`{a}`" for a in args)
    if origin is tuple and args[-1:] == (Ellipsis,):
        inner = strip(args[0])
        if isinstance(inner, type) and issubclass(inner, BaseModel):
            return "list of mappings"
        return f"list of {_type_text(inner)}"
    if origin is tuple:
        return "[" + ", ".join(_type_text(a) for a in args) + "]"
    if origin is dict:
        return f"mapping of name: {_type_text(args[1])}"
    return "mapping"


def _default_text(field: FieldInfo) -> str:
    if field.is_required():
        return "required"
    value = field.get_default(call_default_factory=True)
    return "unset" if value is None else f"`{_yaml_flow(value)}`"


def _yaml_flow(value: Any) -> str:
    """A default as YAML flow text."""
    if isinstance(value, BaseModel):
        value = value.model_dump(exclude_defaults=True)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return value or '""'
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_yaml_flow(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_yaml_flow(v)}" for k, v in value.items()) + "}"
    return repr(value)

