"""whirl's exceptions. Bad input and missing tools raise; numerical outcomes are data.

Every exception is a ``click.ClickException``, so the CLI shows its message without a traceback
and exits with status 1.
"""

from __future__ import annotations

import click


class WhirlError(click.ClickException):
    """Base class: a message for the user, exit status 1."""

    exit_code = 1

    def format_message(self) -> str:
        return self.message

    def show(self, file=None) -> None:
        """Print the message alone (it already names the file, line and key)."""
        click.echo(self.format_message(), file=file, err=file is None)


class StudyError(WhirlError):
    """The study file is unreadable or invalid; the message lists every problem found."""


class CodegenError(WhirlError):
    """A model cannot be written as AUTO Fortran or constants."""


class ToolchainError(WhirlError):
    """gfortran or AUTO-07p is missing or broken; the message says how to fix it."""


class OutputError(WhirlError):
    """An output path cannot be written (exists without --overwrite, not writable, ...)."""
