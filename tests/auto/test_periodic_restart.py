"""Periodic families from a given orbit (issue 14, item 4), on the real AUTO-07p: a family
restarted from one of its own stored orbits retraces it, and one started from an orbit settled
by time simulation (the way to limit cycles no Hopf point leads to) finds the same family."""

from __future__ import annotations

import tempfile
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from whirl_cli.analysis import simulate
from whirl_cli.continuation.engine import Engine, Numerics
from whirl_cli.continuation.one_parameter import one_parameter
from whirl_cli.continuation.periodic import OrbitStart
from whirl_cli.pipeline import run_study
from whirl_cli.results import Orbit, Origin, PointType
from whirl_cli.study import load_study

from ..conftest import STUDIES

pytestmark = pytest.mark.auto

STUDY = STUDIES / "hardening_case2.yaml"


@cache
def hopf_result():
    """hardening case 2 as ``whirl run`` computes it: periodic_1 runs from the Hopf point at
    K_theta = 0.2888 to the one at 0.0807 over three folds of cycles."""
    study = load_study(STUDY)
    return study, run_study(study, Path(tempfile.mkdtemp(prefix="whirl-test-")))


def restarted(orbit: Orbit, value: float, origin: str):
    """The same continuation with no Hopf families, only the family through ``orbit``."""
    study, _ = hopf_result()
    spec = study.continuations[0]
    engine = Engine(study.variant(), Path(tempfile.mkdtemp(prefix="whirl-test-")))
    return one_parameter(engine, spec.name, spec.parameter, spec.start, tuple(spec.range),
                         study.parameter_values(), Numerics.from_settings(study.auto),
                         branch_points=spec.branch_points, periodic=False,
                         start_orbits=(OrbitStart(orbit, value, Origin(origin)),))


def family(result, name):
    (branch,) = [b for b in result.branches if b.name == name]
    return branch


def folds(result, branch):
    return sorted((p for p in result.special_points
                   if p.branch == branch and p.point_type == PointType.LPC),
                  key=lambda p: p.parameters[0])


def assert_same_family(original, again, tolerance):
    """Every fold of cycles of periodic_1 found again on periodic_o1 (parameter to
    ``tolerance``), none more, and both ends at periodic_1's two Hopf points. The orbit's
    largest excursions are maxima over AUTO's 161 mesh points, which it places differently in
    each run: the maximum of a sine sampled at spacing h = T/160 is low by at most
    (pi h/T)^2 / 2 ~ 2e-4 relative, so they agree to 1e-3."""
    first, second = folds(original, "periodic_1"), folds(again, "periodic_o1")
    assert len(first) == 3 and len(second) == 3
    for a, b in zip(first, second, strict=True):
        assert abs(a.parameters[0] - b.parameters[0]) < tolerance, (a.parameters, b.parameters)
        np.testing.assert_allclose(b.state, a.state, rtol=1e-3)
    hopfs = sorted(p.parameters[0] for p in original.special_points
                   if p.point_type == PointType.HB and p.branch == "main_down")
    branch = family(again, "periodic_o1")
    assert branch.end.count("returns to HB") == 2, branch.end
    ends = sorted(branch.parameters[[0, -1], 0])
    width = 0.8  # the continuation's range, -0.3 .. 0.5
    np.testing.assert_allclose(ends, hopfs, atol=2e-3 * width)


def test_a_family_restarted_from_its_own_stored_orbit_retraces_it():
    _, result = hopf_result()
    original = result.continuations[0]
    source = family(original, "periodic_1")
    orbit = min(source.orbits, key=lambda o: abs(o.index - len(source) / 2))  # mid-family
    again = restarted(orbit, float(orbit.parameters[0]), "stored orbit of periodic_1")
    assert_same_family(original, again, tolerance=1e-6)
    # the first point AUTO converged on is the stored orbit
    branch = family(again, "periodic_o1")
    start = int(np.argmin(np.abs(branch.period - orbit.period)))
    assert abs(branch.parameters[start, 0] - orbit.parameters[0]) < 1e-9
    assert abs(branch.period[start] / orbit.period - 1) < 1e-6
    assert branch.origin == Origin("stored orbit of periodic_1")
    # stability where both are stored: the same verdict on either side of every fold
    for point in (p for p in source.orbits if p.index not in (0, len(source) - 1)):
        rows = np.flatnonzero(np.isclose(branch.parameters[:, 0], point.parameters[0],
                                         atol=0, rtol=1e-9))
        for row in rows:
            assert branch.stable[row] == source.stable[point.index]


def settled_orbit(model, params, orbit: Orbit, periods: int = 400) -> Orbit:
    """One period of the motion settled from 20 % outside ``orbit``'s first point: LSODA run
    for ``periods`` periods, the last full period between two upward crossings of the first
    dof's mean, found by linear interpolation (an estimate AUTO has to correct)."""
    y0 = orbit.states[0] * 1.2
    samples_per_period = 400
    t, y = simulate.integrate(model, params, y0, periods * orbit.period,
                              samples=periods * samples_per_period)
    x = y[:, 0] - y[-20 * samples_per_period:, 0].mean()
    up = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    crossings = t[up] - x[up] * (t[up + 1] - t[up]) / (x[up + 1] - x[up])
    begin, end = crossings[-2], crossings[-1]
    times = np.linspace(begin, end, 801)
    states = np.column_stack([np.interp(times, t, y[:, k]) for k in range(y.shape[1])])
    return Orbit(label=0, point_type=0, index=0, parameters=orbit.parameters.copy(),
                 period=float(end - begin), time=times - begin, states=states)


def test_a_family_started_from_a_simulated_orbit_is_the_hopf_family():
    study, result = hopf_result()
    source = family(result.continuations[0], "periodic_1")
    size = (source.state_max - source.state_min).max(axis=1)
    stable = [o for o in source.orbits if source.stable[o.index] and 0 < o.index < len(source) - 1
              and size[o.index] > 0.3 * size.max()]  # grown well away from its Hopf point
    orbit = stable[0]
    model = study.variant()
    params = model.parameter_vector({**study.parameter_values(),
                                     study.continuations[0].parameter: orbit.parameters[0]})
    settled = settled_orbit(model, params, orbit)
    assert abs(settled.period / orbit.period - 1) < 1e-3  # the simulation found that cycle
    again = restarted(settled, float(orbit.parameters[0]), "time simulation")
    branch = family(again, "periodic_o1")
    start = int(np.argmin(np.abs(branch.parameters[:, 0] - orbit.parameters[0])
                          + np.abs(branch.period / orbit.period - 1)))
    assert abs(branch.period[start] / orbit.period - 1) < 1e-6  # AUTO corrected it onto
    assert branch.stable[start]                                  # the stable cycle
    assert_same_family(result.continuations[0], again, tolerance=1e-6)


def test_a_family_from_an_orbit_is_stored_and_read_back(tmp_path):
    """Its orbits keep distinct labels on both sides (AUTO numbers each side's run from its own
    start), so the HDF5 file holds every one of them."""
    from dataclasses import replace

    from whirl_cli.output import store

    study, result = hopf_result()
    source = family(result.continuations[0], "periodic_1")
    orbit = min(source.orbits, key=lambda o: abs(o.index - len(source) / 2))
    again = restarted(orbit, float(orbit.parameters[0]), "stored orbit of periodic_1")
    branch = family(again, "periodic_o1")
    labels = [o.label for o in branch.orbits]
    assert len(labels) == len(set(labels)) and len(labels) >= 2
    path = store.write(replace(result, continuations=(again,)), tmp_path / "restart.h5")
    stored = family(store.read(path).continuations[0], "periodic_o1")
    assert [o.label for o in stored.orbits] == labels
    np.testing.assert_array_equal(stored.parameters, branch.parameters)
