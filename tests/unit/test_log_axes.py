"""Log axes where a quantity spans decades, decided from the data each plot shows: the
period approaching a global bifurcation, freeplay amplitudes in half-gaps, a stability map
over a stiffness from soft to rigid; linear axes elsewhere (values under a factor of
DECADES, or reaching zero)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.unit.plot_data import blowup_continuation, make_branch
from whirl_cli.plots.blowup import blowup_plot
from whirl_cli.plots.freeplay import amplitude_diagram
from whirl_cli.plots.key import DECADES, spans_decades
from whirl_cli.plots.maps import boundary_plot
from whirl_cli.results import Boundary, BranchKind, ContinuationResult, FreeplayAmplitudes


@pytest.mark.parametrize("values, expected", [
    ([0.5, 50.0], True), ([1.0, DECADES], False), ([1.0, 1.01 * DECADES], True),
    ([0.0, 50.0], False), ([-1.0, 50.0], False), ([0.5, np.nan, 50.0], True), ([], False),
])
def test_spans_decades_only_for_positive_values_over_the_factor(values, expected):
    assert spans_decades(values) is expected


def test_period_blowing_up_is_on_a_log_axis_a_mild_growth_not():
    continuation = blowup_continuation()
    (ax,) = blowup_plot(continuation).axes
    assert ax.get_yscale() == "log"
    low, high = ax.get_ylim()
    assert 0 < low and high / low > DECADES
    (family,) = continuation.branches
    mild = family.__class__(**{**family.__dict__, "period": 1.0 + family.period / 300})
    (ax,) = blowup_plot(ContinuationResult("k1", "one-parameter", (mild,),
                                           continuation.special_points)).axes
    assert ax.get_yscale() == "linear"


def amplitudes(ratios: np.ndarray) -> ContinuationResult:
    parameter = np.linspace(8.0, 12.0, len(ratios))
    branch = make_branch("periodic_1", BranchKind.PERIODIC, parameter, 0 * parameter,
                         np.ones(len(parameter), dtype=bool))
    found = FreeplayAmplitudes("periodic_1", "theta", ratios, np.array([]), np.array([]),
                               np.array([]))
    return ContinuationResult("v", "one-parameter", (branch,), (), freeplay=(found,))


def test_amplitudes_in_half_gaps_spanning_decades_are_on_a_log_axis():
    (ax,) = amplitude_diagram(amplitudes(np.geomspace(1.0, 200.0, 30))).axes
    assert ax.get_yscale() == "log"
    (ax,) = amplitude_diagram(amplitudes(np.linspace(1.0, 5.0, 30))).axes
    assert ax.get_yscale() == "linear" and ax.get_ylim()[0] == 0.0


def gimbal_boundary(low: float) -> Boundary:
    """A Hopf locus in (V, K_beta) over K_beta from ``low`` to 50."""
    k_beta = np.geomspace(max(low, 1e-3), 50.0, 40) if low > 0 else np.linspace(0, 50.0, 40)
    locus = np.column_stack([6.0 + np.log1p(k_beta), k_beta])
    return Boundary("onset", ("V", "K_beta"), ("m/s", "N m/rad"), "loci",
                    {"hopf_1": ("hopf", locus)}, (), (), (10.0,))


def test_a_stiffness_from_soft_to_rigid_is_a_log_axis_with_positive_limits():
    (ax,) = boundary_plot(gimbal_boundary(0.5), None).axes
    assert (ax.get_xscale(), ax.get_yscale()) == ("linear", "log")
    low, high = ax.get_ylim()
    assert 0 < low < 0.5 and high > 50.0
    (ax,) = boundary_plot(gimbal_boundary(0.0), None).axes  # reaching zero: linear
    assert ax.get_yscale() == "linear"
