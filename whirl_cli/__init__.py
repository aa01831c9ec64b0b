"""whirl: batch continuation studies of nonlinear whirl flutter with AUTO-07p."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("whirl")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0+unknown"
