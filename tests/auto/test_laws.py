"""Stiffness laws on any dof, several at once (issue 14, items 2 and 3), on the real AUTO."""

from __future__ import annotations

import numpy as np
import pytest

from whirl_cli.output.compare import Tolerances, compare_results
from whirl_cli.pipeline import run_study
from whirl_cli.study import validate_text

RANGE = (-0.3, 0.5)


def study(name: str, laws: str, fixed: str, continued: str) -> str:
    return (f"name: {name}\nmodel: classical\nparameters: {{{fixed}: 0.3}}\n"
            f"nonlinearity: {laws}\ncontinuations:\n"
            f"  - {{name: k, type: one-parameter, parameter: {continued}, start: 0.5, "
            f"range: [{RANGE[0]}, {RANGE[1]}], periodic: true}}\n")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    cache: dict = {}

    def get(name: str, laws: str, fixed: str, continued: str):
        if name not in cache:
            cache[name] = run_study(validate_text(study(name, laws, fixed, continued)),
                                    tmp_path_factory.mktemp(name), jobs=2)
        return cache[name]

    return get


PITCH_LAW = ("pitch", "{type: polynomial, dof: theta, K2: 10.0, K3: 50.0}", "K_psi", "K_theta")
YAW_LAW = ("yaw", "{type: polynomial, dof: psi, K2: 10.0, K3: 50.0}", "K_theta", "K_psi")


def test_a_law_on_yaw_mirrors_the_same_law_on_pitch(run):
    """models.md 2.4: the model is invariant under exchanging pitch and yaw with K_theta and
    K_psi (I_y = I_z, C_theta = C_psi); in the thesis' sign convention an equilibrium
    (theta, psi) of the pitch law is (-psi, theta) of the yaw law, and the maxima of an orbit
    swap. The same law on psi with K_theta = 0.3 continued in K_psi gives the special points
    of the law on theta with K_psi = 0.3 continued in K_theta, to 1e-6."""
    pitch, yaw = run(*PITCH_LAW), run(*YAW_LAW)
    assert yaw.continuations[0].branches[0].parameter_names == ("K_psi",)

    def points(result, mirror: bool):
        found = []
        for p in result.continuations[0].special_points:
            theta, psi = p.state[:2]
            if mirror:
                theta, psi = (psi, theta) if p.point_type == 5 else (psi, -theta)
            found.append((p.type_name, float(p.parameters[0]), theta, psi))
        return sorted(found)

    ours, mirrored = points(pitch, False), points(yaw, True)
    assert len(ours) == len(mirrored) >= 8  # pitchfork, Hopf points, folds of cycles
    width = RANGE[1] - RANGE[0]
    for a, b in zip(ours, mirrored, strict=True):
        assert a[0] == b[0]
        assert abs(a[1] - b[1]) < 1e-6 * width, (a, b)
        np.testing.assert_allclose(a[2:], b[2:], atol=1e-6)
    kinds = {a[0] for a in ours}
    assert {"BP", "HB", "LPC"} <= kinds


def test_a_second_law_with_zero_coefficients_changes_nothing(run):
    """A two-law list whose second law has zero coefficients gives the single-law results
    (whirl compare at 1e-8)."""
    single = run(*PITCH_LAW)
    double = run("pitch-and-zero-yaw",
                 "[{type: polynomial, dof: theta, K2: 10.0, K3: 50.0}, "
                 "{type: polynomial, dof: psi, K2: 0.0, K3: 0.0}]", "K_psi", "K_theta")
    strict = Tolerances(parameter=1e-8, state=1e-8, period=1e-8, branch_state=1e-8,
                        linear=1e-8, boundary=1e-8, lyapunov=1e-8)
    differences = [d for d in compare_results(single, double, strict)
                   if not d.path.startswith("/@")]  # study name and text differ
    assert differences == []
