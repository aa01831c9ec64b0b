"""How whirl's registries find what they register (no imports of whirl's): every instance of
one class declared at the top of a package's public modules. A new plot kind, continuation
type or stiffness law is then one more module in its package."""

from __future__ import annotations

import importlib
import os
from collections.abc import Iterable
from typing import TypeVar

T = TypeVar("T")


def declared(package: str, folders: Iterable[str], kind: type[T], what: str,
             found: dict[str, T] | None = None) -> dict[str, T]:
    """The instances of ``kind`` in the public modules (``.py`` files not starting with ``_``)
    of ``package`` (whose ``__path__`` is ``folders``), by their ``name``, module by module in
    name order after those in ``found``; a name declared twice raises ValueError (naming it
    as ``what``)."""
    found = dict(found or {})
    modules = sorted({entry.name.removesuffix(".py") for folder in folders
                      for entry in os.scandir(folder)
                      if entry.name.endswith(".py") and not entry.name.startswith("_")})
    for module in modules:
        loaded = importlib.import_module(f"{package}.{module}")
        for value in vars(loaded).values():
            if isinstance(value, kind) and found.setdefault(value.name, value) is not value:
                raise ValueError(f"{what} {value.name!r} declared twice")
    return found


def by_rank(found: dict[str, T]) -> dict[str, T]:
    """``found`` ordered by each entry's ``rank``, then name."""
    return dict(sorted(found.items(), key=lambda item: (item[1].rank, item[0])))
