"""A YAML file (a study, a sheet, a model file): bytes -> nodes -> plain Python data, with the
node and line of every key.

Steps 1 to 3 of :mod:`whirl_cli.study`: :func:`read_text` (at most :data:`MAX_BYTES` of UTF-8),
:func:`compose` (a SafeLoader subclass, :class:`_Loader`, that records anchors, aliases and
non-core tags as problems and stops below :data:`MAX_DEPTH` levels of nesting) and
:class:`Tree` (the data, the problems found building it, and the node and line of every key
path, for the messages). Nothing here knows the schema.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from ..errors import StudyError

#: Largest study file accepted, in bytes (1 MiB).
MAX_BYTES = 1 << 20
#: Deepest nesting of YAML lists and mappings accepted (a study needs 5).
MAX_DEPTH = 32

Loc = tuple[str | int, ...]
Problem = tuple[Loc, str]

_CORE = "tag:yaml.org,2002:"
_STR, _INT, _FLOAT, _BOOL, _NULL = (_CORE + t for t in ("str", "int", "float", "bool", "null"))
_SEQ, _MAP = _CORE + "seq", _CORE + "map"
_SCALAR_TAGS = frozenset({_STR, _INT, _FLOAT, _BOOL, _NULL})
_TAGS_BY_EVENT = {
    yaml.ScalarEvent: _SCALAR_TAGS,
    yaml.SequenceStartEvent: frozenset({_SEQ}),
    yaml.MappingStartEvent: frozenset({_MAP}),
}


def _parse(text: str, what: str = "study") -> tuple[Node | None, list[tuple[int, str]]]:
    """The root node and the (line, reason) problems recorded while composing it (``what``:
    the kind of file, for the reasons)."""
    loader = _Loader(text, what)
    try:
        return loader.get_single_node(), loader.problems
    finally:
        loader.dispose()


def _short_tag(tag: str) -> str:
    """``tag:yaml.org,2002:int`` -> ``!!int``."""
    return "!!" + tag.removeprefix(_CORE) if tag.startswith(_CORE) else tag


class _TooDeep(Exception):
    """Raised by _Loader at the first node nested deeper than MAX_DEPTH."""


class _Loader(yaml.SafeLoader):
    """SafeLoader resolving only str, int, float (``1e-6`` too), bool (true/false) and null.

    While composing it records anchors, aliases and non-core tags as (line, reason) in
    ``problems`` (an alias becomes a null node) and stops below MAX_DEPTH levels of nesting.
    """

    def __init__(self, stream: str, what: str = "study") -> None:
        super().__init__(stream)
        self.what = what
        self.problems: list[tuple[int, str]] = []
        self._depth = 0

    def compose_node(self, parent: Node | None, index: Any) -> Node:
        event = self.peek_event()
        line = event.start_mark.line + 1
        if isinstance(event, yaml.AliasEvent) or event.anchor is not None:
            self.problems.append((line, "YAML anchors and aliases are not allowed in "
                                  f"{self.what} files"))
            event.anchor = None
        tag = getattr(event, "tag", None)
        if tag is not None and tag not in _TAGS_BY_EVENT.get(type(event), ()):
            reason = f"YAML tag {_short_tag(tag)!r} is not allowed in {self.what} files"
            self.problems.append((line, reason))
        if isinstance(event, yaml.AliasEvent):
            self.get_event()
            return ScalarNode(_NULL, "", event.start_mark, event.end_mark)
        if self._depth >= MAX_DEPTH:
            raise _TooDeep(line)
        self._depth += 1
        try:
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


_Loader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag in (_INT, _NULL)]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_Loader.add_implicit_resolver(_BOOL, re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), "tTfF")
_Loader.add_implicit_resolver(
    _FLOAT,
    re.compile(
        r"""^(?:[-+]?(?:[0-9][0-9_]*\.[0-9_]*|\.[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)?
        |[-+]?[0-9][0-9_]*[eE][-+]?[0-9]+
        |[-+]?\.(?:inf|Inf|INF)
        |\.(?:nan|NaN|NAN))$""",
        re.X,
    ),
    "-+0123456789.",
)


def read_text(path: Path, label: str, what: str = "study") -> str:
    """The file's text: at most MAX_BYTES of UTF-8 (errors name the file ``label``, and call
    it a ``what`` file)."""
    try:
        with path.open("rb") as stream:
            raw = stream.read(MAX_BYTES + 1)
            size = max(len(raw), os.fstat(stream.fileno()).st_size)
    except OSError as error:
        reason = f"cannot read the {what} file ({error.strerror or error})"
        raise StudyError(f"{label}: {reason}") from None
    if len(raw) > MAX_BYTES:
        raise StudyError(too_large(label, size, what))
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as error:
        reason = f"not UTF-8 text (byte 0x{raw[error.start]:02x} at offset {error.start})"
        raise StudyError(f"{label}: {reason}") from None


def too_large(name: str, size: int, what: str = "study") -> str:
    """The message for a file of ``size`` bytes, over :data:`MAX_BYTES`."""
    return f"{name}: the {what} file is too large ({size} bytes; the limit is {MAX_BYTES})"


def compose(text: str, name: str, what: str = "study") -> MappingNode:
    """The root node of ``text``; StudyError for problems that concern the whole file
    (``what``: the kind of file, a study or a sheet)."""
    try:
        root, whole_file = _parse(text, what)
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        where = f"{name}:{mark.line + 1}" if mark else name
        raise StudyError(f"{where}: YAML syntax error: {error.problem or error.context}") from None
    except yaml.reader.ReaderError as error:
        line = text.count("\n", 0, error.position) + 1
        reason = str(error).splitlines()[0]
        raise StudyError(f"{name}:{line}: YAML syntax error: {reason}") from None
    except yaml.YAMLError as error:
        raise StudyError(f"{name}: YAML syntax error: {error}") from None
    except _TooDeep as error:
        reason = f"YAML nesting deeper than {MAX_DEPTH} levels is not allowed in {what} files"
        raise StudyError(f"{name}:{error.args[0]}: {reason}") from None
    if whole_file:
        raise StudyError("\n".join(f"{name}:{line}: {reason}" for line, reason in whole_file))
    if root is None or (root.tag == _NULL and root.value == ""):
        raise StudyError(f"{name}: the {what} file is empty")
    if not isinstance(root, MappingNode):
        line = root.start_mark.line + 1
        got = _shown(root)
        raise StudyError(f"{name}:{line}: a {what} must be a YAML mapping of keys, got {got}")
    return root


class Tree:
    """Python data built from the composed nodes, with the node and line of every key path."""

    def __init__(self, root: MappingNode) -> None:
        self.nodes: dict[Loc, Node] = {}
        self.lines: dict[Loc, int] = {(): root.start_mark.line + 1}
        self.problems: list[Problem] = []
        self.unreadable: set[Loc] = set()
        self._constructor = _Loader("")
        self.data = self._build(root, ())

    def line(self, loc: Loc) -> int:
        """Line of ``loc``, or of its nearest parent present in the file (missing keys)."""
        while loc not in self.lines:
            loc = loc[:-1]
        return self.lines[loc]

    def _build(self, node: Node, loc: Loc) -> Any:
        self.nodes[loc] = node
        if isinstance(node, MappingNode):
            return self._build_mapping(node, loc)
        if isinstance(node, SequenceNode):
            return [self._build_item(item, loc + (i,)) for i, item in enumerate(node.value)]
        try:
            return self._constructor.construct_object(node)
        except (ValueError, KeyError, yaml.YAMLError):
            self.problems.append((loc, f"cannot read {node.value!r} as {_short_tag(node.tag)}"))
            self.unreadable.add(loc)
            return None

    def _build_item(self, node: Node, loc: Loc) -> Any:
        self.lines[loc] = node.start_mark.line + 1
        return self._build(node, loc)

    def _build_mapping(self, node: MappingNode, loc: Loc) -> dict:
        data: dict[str, Any] = {}
        for key_node, value_node in node.value:
            line = key_node.start_mark.line + 1
            if not isinstance(key_node, ScalarNode):
                self.lines.setdefault(loc + ("?",), line)
                self.problems.append((loc + ("?",), f"keys must be text, got {_shown(key_node)}"))
                continue
            key = key_node.value
            if key in data:
                self.problems.append((loc + (key,), f"duplicate key {key!r}"))
            self.lines[loc + (key,)] = line
            data[key] = self._build(value_node, loc + (key,))
        return data

    def shown(self, loc: Loc) -> str:
        node = self.nodes.get(loc)
        return _shown(node) if node is not None else "nothing"

    def flow(self, loc: Loc) -> str:
        node = self.nodes.get(loc)
        return _flow(node) if node is not None else "nothing"


def _shown(node: Node) -> str:
    """A value as written: numbers verbatim, strings quoted, ``a list``/``a mapping``."""
    if isinstance(node, MappingNode):
        return "a mapping"
    if isinstance(node, SequenceNode):
        return "a list"
    if node.tag == _BOOL:
        return node.value.lower()
    if node.tag == _NULL:
        return "null"
    if node.tag in (_INT, _FLOAT):
        return node.value
    return repr(node.value)


def _flow(node: Node, depth: int = 0) -> str:
    """A value as written, lists spelled out: ``[0.5, -0.3]``."""
    if not isinstance(node, SequenceNode):
        return _shown(node)
    if depth > 2:
        return "[...]"
    items = [_flow(item, depth + 1) for item in node.value[:6]]
    return "[" + ", ".join(items[:5] + ["..."] * (len(items) > 5)) + "]"

