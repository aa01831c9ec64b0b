"""How much runs at once when nobody says: the default of ``whirl run --jobs`` and of the
``jobs`` of :mod:`whirl_cli.api` (one for both, so a notebook runs a study as the CLI does)."""

from __future__ import annotations

import os

#: The most AUTO runs (and simulations, and plots) ``whirl run`` starts at once.
MAX_JOBS = 64


def default_jobs() -> int:
    """One job per CPU, at most :data:`MAX_JOBS`."""
    return min(os.cpu_count() or 1, MAX_JOBS)


def jobs_or_default(jobs: int | None) -> int:
    """``jobs``, or :func:`default_jobs` where it is None."""
    return default_jobs() if jobs is None else jobs
