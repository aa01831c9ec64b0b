"""YAML files read with the line of every key and checked with pydantic (studies, sheets, model
files): :mod:`.source` (bytes -> nodes -> data), :mod:`.values` (the value types of keys),
:mod:`.messages` (pydantic errors -> ``file:line: key.path: reason``). Knows no schema."""
