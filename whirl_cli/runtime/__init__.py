"""How whirl stops and forks: the one place that handles signals, threads and worker
processes.

* :class:`Interrupted` is the KeyboardInterrupt whirl raises for SIGINT and SIGTERM; it
  survives pickling, so it can travel back from a worker process.
* :func:`catching`: signals raise :class:`Interrupted` inside, and one Python would drop is
  raised again (:func:`check`); :func:`held_signals`: signals wait until the block ends;
  :func:`wrapped_interrupt` finds one Python wrapped in another exception.
* :func:`thread_map` maps over threads that never outlive the call, an interrupt included;
  :func:`forked_map` over forked worker processes (CPU-bound Python: simulations, plots);
  :class:`Standby` is one worker forked early, importing what a later call needs.
* :func:`preload` imports modules a later stage needs in a background thread; every fork
  (:func:`forking`) waits for it first.
* :func:`quiet_worker` sets up a worker process forked inside :func:`forking`.

The names are looked up in their modules on first use: the console script takes
:func:`terminate_as_interrupt` from here before it imports anything else, and that imports
:mod:`signal` only.
"""

from __future__ import annotations

import importlib

TYPE_CHECKING = False  # typing's, without importing typing

#: Each public name -> the module of this package that defines it.
_MODULES = {
    "Interrupted": "signals",
    "terminate_as_interrupt": "signals",
    "wrapped_interrupt": "signals",
    "catching": "blocks",
    "check": "blocks",
    "held_signals": "blocks",
    "preload": "threads",
    "preloaded": "threads",
    "thread_map": "threads",
    "Standby": "processes",
    "forked_map": "processes",
    "forking": "processes",
    "quiet_worker": "processes",
}

__all__ = [
    "Interrupted",
    "Standby",
    "catching",
    "check",
    "forked_map",
    "forking",
    "held_signals",
    "preload",
    "preloaded",
    "quiet_worker",
    "terminate_as_interrupt",
    "thread_map",
    "wrapped_interrupt",
]

if TYPE_CHECKING:
    from .blocks import catching, check, held_signals
    from .processes import Standby, forked_map, forking, quiet_worker
    from .signals import Interrupted, terminate_as_interrupt, wrapped_interrupt
    from .threads import preload, preloaded, thread_map


def __getattr__(name: str) -> object:
    if name not in _MODULES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_MODULES[name]}", __name__), name)
    globals()[name] = value
    return value
