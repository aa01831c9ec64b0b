"""Mirror images of a symmetric model (:mod:`whirl_cli.continuation.mirror`): which Hopf points
mirror which, and a family mapped onto its mirror image."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np

from whirl_cli.continuation import shrinking
from whirl_cli.continuation.mirror import mirror_sources, mirrored_branch, mirrored_point
from whirl_cli.continuation.persistence import Recomputed
from whirl_cli.models import FAMILIES, Model
from whirl_cli.results import (
    Branch,
    BranchKind,
    ContinuationKind,
    ContinuationResult,
    Orbit,
    PointType,
    SpecialPoint,
)

MODEL = Model(FAMILIES["classical"], ("polynomial",) * 2)
PARAMETERS = {"K_psi": 0.3, "K2_theta": 10.0}
STATE = np.array([0.1, 0.03, 0.0, 0.0])


def hopf(branch: str, state, value: float = 0.09, period: float = 0.26) -> SpecialPoint:
    return SpecialPoint(branch, 3, int(PointType.HB), ("K_theta",), np.array([value]),
                        np.asarray(state, dtype=float), period, False)


def test_the_hopf_point_of_a_mirror_branch_maps_onto_the_earlier_one():
    """secondary_1b's Hopf point (opposite state, same K_theta and period) is secondary_1a's
    image; the origin's (its own image) and one at another K_theta are nobody's."""
    points = [hopf("main_down", np.zeros(4), 0.29), hopf("secondary_1a", STATE),
              hopf("secondary_1b", -STATE), hopf("secondary_1b", -STATE, 0.08)]
    assert mirror_sources(MODEL, points, 0.8, PARAMETERS) == {2: 1}


def test_no_mirror_where_the_right_hand_side_is_not_odd():
    """A model declared symmetric whose right-hand side has an even term maps nothing."""
    even = SimpleNamespace(symmetric=True, n_states=4, dofs=MODEL.dofs,
                           typical_amplitudes=MODEL.typical_amplitudes,
                           parameter_vector=MODEL.parameter_vector,
                           rhs_numpy=lambda y, p: MODEL.rhs_numpy(y, p) + y[0] ** 2)
    points = [hopf("secondary_1a", STATE), hopf("secondary_1b", -STATE)]
    assert mirror_sources(MODEL, points, 0.8, PARAMETERS) == {1: 0}
    assert mirror_sources(even, points, 0.8, PARAMETERS) == {}


def test_a_mirrored_family_negates_its_states_and_keeps_the_rest():
    rows = 3
    maxima = np.array([[0.2, 0.1, 1.0, 2.0]] * rows)
    minima = np.array([[0.05, -0.02, -1.0, -2.5]] * rows)
    orbit = Orbit(1, 0, 1, np.array([0.1]), 0.3, np.linspace(0, 0.3, 5),
                  np.arange(20.0).reshape(5, 4))
    source = Branch("periodic_3", BranchKind.PERIODIC, "HB at K_theta = 0.09 on secondary_1a",
                    ("K_theta",), ("N m/rad",), MODEL.state_names, ("rad",) * 2 + ("rad/s",) * 2,
                    np.array([[0.09], [0.1], [0.11]]), maxima, minima, np.ones(rows),
                    np.array([0.26, 0.3, 0.4]), np.array([False, True, True]),
                    np.array([3, 0, 5]), np.array([1, 2, 3]), np.zeros((rows, 4), complex),
                    orbits=(orbit,), end="range")
    image = mirrored_branch(source, "periodic_5", "HB at K_theta = 0.09 on secondary_1b",
                            source.end)
    np.testing.assert_array_equal(image.state_max, -minima)
    np.testing.assert_array_equal(image.state_min, -maxima)
    np.testing.assert_array_equal(image.orbits[0].states, -orbit.states)
    np.testing.assert_array_equal(image.period, source.period)
    np.testing.assert_array_equal(image.stable, source.stable)
    assert (image.name, image.end) == ("periodic_5", "range")
    assert "mirror image (y -> -y) of periodic_3" in image.message
    fold = SpecialPoint("periodic_3", 2, int(PointType.LPC), ("K_theta",), np.array([0.11]),
                        maxima[2], 0.4, True)
    saddle = SpecialPoint("periodic_3", 2, int(PointType.HOMOCLINIC), ("K_theta",),
                          np.array([0.111]), STATE, 0.4, False, note="saddle (0.1, 0.03)")
    np.testing.assert_array_equal(mirrored_point(fold, image).state, -minima[2])
    moved = mirrored_point(saddle, image)
    np.testing.assert_array_equal(moved.state, -STATE)
    assert moved.branch == "periodic_5" and moved.note.startswith("mirror image of the point")


def test_a_mapped_familys_points_share_their_sources_shrinking_restarts(monkeypatch):
    """The short runs at reduced smoothing restart from a point's labelled AUTO solution; a
    mapped family holds its source's runs, so its fold would restart from the source's (the
    other well's) orbit: it is recomputed once, for the source's fold, and its image takes
    those values. (Runs are stand-ins recording what they are asked for.)"""
    rows = 3
    source = Branch("periodic_1", BranchKind.PERIODIC, "HB", ("V",), ("m/s",),
                    MODEL.state_names, ("rad",) * 2 + ("rad/s",) * 2,
                    np.array([[7.5], [7.4], [7.3]]), np.full((rows, 4), 0.1),
                    np.full((rows, 4), 0.05), np.ones(rows), np.full(rows, 0.3),
                    np.ones(rows, bool), np.array([3, 0, 5]), np.array([1, 2, 3]),
                    np.zeros((rows, 4), complex), runs=("a.periodic_1.0",))
    image = mirrored_branch(source, "periodic_2", "HB", source.end)
    fold = SpecialPoint("periodic_1", 2, int(PointType.LPC), ("V",), np.array([7.3]),
                        source.state_max[2], 0.3, True, label=3)
    other = replace(fold, label=2, index=1, parameters=np.array([7.4]))  # another solution
    points = (fold, other, mirrored_point(fold, image))
    asked = []

    def restarted(_engine, _name, todo, _runs, _widths, factors, _numerics):
        asked.extend(todo)
        return {k: Recomputed(p.parameters[0] + np.array([1e-4, 2e-4]), shrinking.RESTART)
                for k, p in todo.items()}

    monkeypatch.setattr(shrinking, "_restarted", restarted)
    monkeypatch.setattr(shrinking, "_by_locus", lambda *args: {})
    model = SimpleNamespace(parameters=[SimpleNamespace(name="epsilon")],
                            parameter_vector=lambda values: np.array([values["epsilon"]]))
    continuation = ContinuationResult("airspeed", ContinuationKind.ONE_PARAMETER,
                                      (source, image), points)
    found = shrinking.recompute(SimpleNamespace(model=model), "airspeed", continuation,
                                {"epsilon": 1e-3}, ("epsilon",), (0.5, 0.25),
                                frozenset({int(PointType.LPC)}), (6.0, 9.0), None, 0.01)
    assert asked == [0, 1]
    assert set(found) == {0, 1, 2}
    np.testing.assert_array_equal(found[2].values, found[0].values)
