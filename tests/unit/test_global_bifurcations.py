"""Period blow-up (:mod:`whirl_cli.analysis.global_bifurcations`): a family's period that has
grown several times over is a global bifurcation only if its orbit lingers near a saddle for a
good share of its period; a family that has only reached a slower mode is none."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np

from whirl_cli.analysis.global_bifurcations import analyse
from whirl_cli.continuation.homoclinic import locate_homoclinics
from whirl_cli.models import FAMILIES, Model
from whirl_cli.results import Branch, BranchKind, Orbit, PointType, SpecialPoint

MODEL = Model(FAMILIES["classical"], ("polynomial",) * 2)
PARAMETERS = {"K_psi": 0.3}
ROWS = 12


def _branch(name: str, kind: str, k_theta: np.ndarray, period: np.ndarray,
            orbits: tuple[Orbit, ...] = ()) -> Branch:
    n = len(k_theta)
    states = MODEL.state_names
    maxima = np.array([o.states.max(axis=0) for o in orbits] * n) if orbits else np.zeros((n, 4))
    minima = np.array([o.states.min(axis=0) for o in orbits] * n) if orbits else np.zeros((n, 4))
    return Branch(name, kind, "test", ("K_theta",), ("N m/rad",), states,
                  tuple(s.unit for s in MODEL.states), k_theta[:, None], maxima, minima,
                  np.zeros(n), period, np.zeros(n, bool), np.zeros(n, int), np.zeros(n, int),
                  np.full((n, 4), np.nan, complex), orbits=orbits)


def _orbit(states: np.ndarray, period: float) -> Orbit:
    return Orbit(label=1, point_type=0, index=ROWS - 1, parameters=np.array([-0.2]),
                 period=period, time=np.linspace(0, period, len(states)), states=states)


def _family(states: np.ndarray) -> Branch:
    """A family whose period grows fivefold as K_theta falls to -0.2, with ``states`` its
    longest orbit."""
    period = np.linspace(0.3, 1.5, ROWS)
    return _branch("periodic_1", BranchKind.PERIODIC, np.linspace(-0.1, -0.2, ROWS), period,
                   (_orbit(states, period[-1]),))


def _analysed(states: np.ndarray):
    origin = _branch("main_down", BranchKind.EQUILIBRIUM, np.array([0.0, -0.3]),
                     np.full(2, np.nan))
    return analyse(_family(states), MODEL, PARAMETERS, [origin], 0.3, 0.8)


def test_the_undeflected_equilibrium_is_a_saddle_there():
    params = MODEL.parameter_vector({**PARAMETERS, "K_theta": -0.2})
    values = np.linalg.eigvals(MODEL.jacobian_numpy(np.zeros(4), params))
    assert np.sum((values.real > 0) & (np.abs(values.imag) < 1e-9)) == 1


def test_a_slower_cycle_around_the_saddle_is_no_blow_up():
    """A circle of radius 0.1 rad round the saddle: the period has grown fivefold, but the
    orbit never comes near the saddle."""
    angle = np.linspace(0, 2 * np.pi, 201)
    circle = 0.1 * np.column_stack([np.cos(angle), np.sin(angle), -np.sin(angle),
                                    np.cos(angle)])
    assert _analysed(circle) is None


def test_an_orbit_that_sits_at_the_saddle_is_a_homoclinic_approach():
    """The same growth with an orbit that spends 80 % of its period within 1e-4 rad of the
    saddle and makes one loop of 0.1 rad: a bracketed homoclinic approach at the saddle."""
    angle = np.linspace(0, 2 * np.pi, 41)
    loop = 0.05 * np.column_stack([1 - np.cos(angle), np.sin(angle), np.sin(angle),
                                   np.cos(angle) - 1])
    states = np.vstack([np.full((160, 4), 1e-4), loop])
    point = _analysed(states)
    assert point is not None and point.point_type == PointType.HOMOCLINIC
    assert point.status == "bracketed"
    np.testing.assert_array_equal(point.state, np.zeros(4))
    assert "80% of its period" in point.note


class _Engine:
    """Records the runs it is asked for; every run fails (no output)."""

    def __init__(self):
        self.model, self.names = MODEL, []

    def run_with_label(self, runs: str, _label: int) -> str:
        return runs

    def run_many(self, specs):
        self.names += [spec.name for spec in specs]
        return [SimpleNamespace(has_output=False, status="mx", message="stub") for _ in specs]


def test_both_sides_of_a_family_locate_their_ends_in_runs_of_their_own():
    """A family started at an orbit has two sides, each of which can end in a blow-up: each
    gets a HomCont run under a name of its own (one name for both: the second run's work
    directory collided with the first's)."""
    angle = np.linspace(0, 2 * np.pi, 201)
    lopsided = 0.05 * np.column_stack([1 + np.cos(angle), np.sin(angle), -np.sin(angle),
                                       np.cos(angle)])
    sides = []
    for k in range(2):
        side = replace(_family(lopsided), name="periodic_o1", runs=(f"run_{k}",),
                       label=np.arange(1, ROWS + 1))
        point = SpecialPoint("periodic_o1", ROWS - 1, int(PointType.HOMOCLINIC), ("K_theta",),
                             np.array([-0.2]), np.zeros(4), 1.5, False, status="bracketed")
        sides.append((side, point))
    engine = _Engine()
    located = locate_homoclinics(engine, "k1", sides, (-0.3, 0.5), PARAMETERS)
    assert len(engine.names) == 2 and len(set(engine.names)) == 2, engine.names
    assert [p.status for p in located] == ["bracketed", "bracketed"]
