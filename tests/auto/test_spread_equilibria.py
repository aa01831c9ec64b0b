"""Equilibria that no seed settles on and no branch point reaches (real AUTO-07p): with
``spread_equilibria: true`` Newton's method from a spread of starts finds them, and each starts
a branch. Checked on tests/data/sextic_well.model.yaml, m q'' = -c q' - k q - q^5 + 1.25 q^3,
whose equilibria off the origin are q^2 = (1.25 +- sqrt(1.5625 - 4 k)) / 2 (closed form) for
every k in the range, never meeting the origin's branch; stable where the restoring force
rises, k + 5 q^4 - 3.75 q^2 > 0."""

from __future__ import annotations

import numpy as np
import pytest

from whirl_cli.pipeline import run_study
from whirl_cli.study import load_study

from ..conftest import ROOT

STUDY = ROOT / "tests" / "data" / "sextic_well_k.yaml"


@pytest.fixture(scope="module")
def branches(tmp_path_factory):
    result = run_study(load_study(STUDY), tmp_path_factory.mktemp("spread"))
    (continuation,) = result.continuations
    return continuation.branches


def closed_form(k: np.ndarray, sign: float, outer: bool) -> np.ndarray:
    root = np.sqrt(1.5625 - 4 * k)
    return sign * np.sqrt((1.25 + (root if outer else -root)) / 2)


def test_every_equilibrium_off_the_origin_starts_a_branch(branches):
    resting = [b for b in branches if b.name.startswith("resting_")]
    at_start = {round(float(b.state_max[0, 0]), 6) for b in resting}
    expected = {round(float(closed_form(np.array(0.2), s, o)), 6)
                for s in (1.0, -1.0) for o in (True, False)}
    assert at_start == expected
    for branch in resting:
        k, q = branch.parameters[:, 0], branch.state_max[:, 0]
        assert abs(k[-1] - (0.1 if branch.name.endswith("_down") else 0.35)) < 1e-4
        outer = abs(q[0]) > 0.8
        np.testing.assert_allclose(q, closed_form(k, np.sign(q[0]), outer), rtol=1e-6,
                                   atol=1e-8)
        np.testing.assert_array_equal(branch.stable, k + 5 * q**4 - 3.75 * q**2 > 0)


def test_no_equilibrium_is_started_twice(branches):
    """The origin (the main branch) and each equilibrium found from several starts, or as
    the mirror image of another, start one branch each (both ways)."""
    names = [b.name for b in branches]
    assert sorted(names) == sorted(["main_down", "main_up"] + [
        f"resting_{k}_{side}" for k in range(1, 5) for side in ("down", "up")])
