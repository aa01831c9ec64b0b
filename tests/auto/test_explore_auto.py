"""``explore:`` end to end on the real AUTO-07p: hardening case 2 (classical model) over a
short range with periodic branches; the class by simulation against the cycle AUTO continues
in the same run."""

from __future__ import annotations

import tempfile
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from whirl_cli.output import store
from whirl_cli.pipeline import run_study
from whirl_cli.study import validate_text

from ..conftest import STUDIES

pytestmark = pytest.mark.auto


@cache
def computed():
    text = (STUDIES / "hardening_case2.yaml").read_text()
    text = text.replace("start: 0.5", "start: 0.45").replace("range: [-0.3, 0.5]",
                                                             "range: [0.2, 0.5]")
    text = text.replace("    branch_points: true\n",
                        "    branch_points: true\n    explore: [0.24, 0.45]\n")
    study = validate_text(text, "h.yaml")
    return run_study(study, Path(tempfile.mkdtemp(prefix="whirl-test-")))


def stable_period(result, k1: float) -> float:
    """The period (s) of the stable periodic orbit AUTO found at ``k1``, interpolated."""
    (continuation,) = result.continuations
    found = []
    for branch in (b for b in continuation.branches if b.is_periodic):
        x = branch.parameter(branch.parameter_names[0])
        for i in np.nonzero(np.diff(np.sign(x - k1)))[0]:
            if branch.stable[i] and branch.stable[i + 1]:
                w = (k1 - x[i]) / (x[i + 1] - x[i])
                found.append((1 - w) * branch.period[i] + w * branch.period[i + 1])
    assert len(found) == 1, found
    return float(found[0])


def test_the_class_at_autos_stable_cycle_is_periodic_at_its_frequency():
    result = computed()
    at_cycle, far = result.continuations[0].explorations
    assert at_cycle.kind == "periodic", at_cycle.evidence
    assert at_cycle.frequencies[0] == pytest.approx(1.0 / stable_period(result, 0.24), rel=1e-2)
    assert far.kind == "equilibrium", far.evidence


def test_explorations_of_a_run_round_trip(tmp_path):
    result = computed()
    back = store.read(store.write(result, tmp_path / "h.h5"))
    for a, b in zip(result.continuations[0].explorations, back.continuations[0].explorations,
                    strict=True):
        assert (a.value, a.kind, a.multiplicity, a.evidence) == (b.value, b.kind,
                                                                 b.multiplicity, b.evidence)
        assert np.array_equal(a.section, b.section)
        assert np.array_equal(a.frequencies, b.frequencies)
