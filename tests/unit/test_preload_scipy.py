"""Which studies import scipy's integrators in the background while AUTO runs: only those
whose cross-checks are the first stage to use scipy (no freeplay amplitudes or explorations,
which import scipy in the main thread between continuations). No AUTO."""

from __future__ import annotations

import pytest

from whirl_cli.pipeline import _only_checks_simulate
from whirl_cli.study import load_study

from ..conftest import ROOT


@pytest.mark.parametrize(("path", "expected"), [
    ("thesis_ch3/combined_case2.yaml", True),              # cross-checks after AUTO only
    ("thesis_ch3/boundary_combined.yaml", False),          # no cross-checks
    ("freeplay/pitch_airspeed.yaml", False),               # freeplay amplitudes (scipy)
    ("gimballed/explore_combined_case2_soft.yaml", False),  # explorations (scipy)
])
def test_scipy_is_preloaded_only_where_the_cross_checks_use_it_first(path, expected):
    study = load_study(ROOT / "studies" / path)
    assert _only_checks_simulate(study, study.variant()) is expected
