"""Fixtures shared by the unit tests."""

from __future__ import annotations

import pytest

from whirl_cli.results import ContinuationResult

from .plot_data import hopf_continuation


@pytest.fixture
def continuation() -> ContinuationResult:
    """Equilibrium losing stability at a Hopf (K1 = 0.3) feeding a periodic branch with a fold."""
    return hopf_continuation()
