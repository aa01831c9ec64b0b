"""whirl: batch continuation studies of nonlinear whirl flutter with AUTO-07p.

Importing the package costs nothing: ``__version__`` is looked up on first use (so that the
console script's first lines, before :func:`whirl_cli.entry.main` takes charge of Ctrl-C, are
as short as they can be).
"""

from functools import cache


@cache
def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("whirl")
    except PackageNotFoundError:  # running from a source tree without installation
        return "0.0.0+unknown"


def __getattr__(name: str) -> str:
    if name == "__version__":
        return _version()
    raise AttributeError(f"module 'whirl_cli' has no attribute {name!r}")
