"""A periodic family that AUTO could not continue (MX) is restarted on a finer mesh with
smaller steps, and keeps them: its later segments (from the next fold of cycles on) run on
the finer mesh too, not back on the coarse one where it failed."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from whirl_cli.continuation.engine import RunSpec
from whirl_cli.continuation.periodic import (
    MAX_REFINEMENTS,
    FamilySide,
    _next_segment,
    _retry,
    _segment_constants,
)
from whirl_cli.results import Branch, BranchKind, Origin, PointType, RunStatus

ROWS = 6


def _piece(status: RunStatus) -> Branch:
    """A piece of a family of ROWS points, labelled at its first and fourth, ending as
    ``status`` says."""
    label = np.zeros(ROWS, int)
    label[[0, 3]] = (1, 2)
    types = np.zeros(ROWS, int)
    types[-1] = PointType.MX if status == RunStatus.MX else PointType.LPC
    return Branch("periodic_1", BranchKind.PERIODIC, Origin("test"), ("V",), ("m/s",), ("x", "v"),
                  ("m", "m/s"), np.linspace(7, 8, ROWS)[:, None], np.ones((ROWS, 2)),
                  -np.ones((ROWS, 2)), np.zeros(ROWS), np.full(ROWS, 0.2), np.ones(ROWS, bool),
                  types, label, np.full((ROWS, 2), np.nan, complex), status=status,
                  runs=("a.periodic_1.0",))


def test_a_retried_family_keeps_its_finer_mesh_for_its_later_segments():
    constants = {"NTST": 40, "DSMAX": 0.01, "DS": 0.001, "UZSTOP": {}}
    family = FamilySide("periodic_1", 0.2, RunSpec("a/periodic_1.0", constants,
                                                BranchKind.PERIODIC, Origin("test"), ("V",)), [])
    family.pieces.append(_piece(RunStatus.MX))
    retried = _retry(family, family.pieces[-1])
    assert retried is not None
    assert (retried.constants["NTST"], retried.constants["DSMAX"]) == (80, 0.005)
    assert len(family.pieces[-1]) == 4  # cut back to its last good labelled point
    family.pieces.append(_piece(RunStatus.OK))  # the retry reached the next fold
    later = _segment_constants(family)
    assert (later["NTST"], later["DSMAX"]) == (80, 0.005)
    family.pieces.append(_piece(RunStatus.MX))  # and failed again further on: finer still
    again = _retry(family, family.pieces[-1])
    assert (again.constants["NTST"], again.constants["DSMAX"]) == (160, 0.0025)


def _family() -> FamilySide:
    constants = {"NTST": 40, "DSMAX": 0.01, "DS": 0.001, "UZSTOP": {}}
    return FamilySide("periodic_1", 0.2, RunSpec("a/periodic_1.0", constants,
                                                 BranchKind.PERIODIC, Origin("test"), ("V",)), [])


def _unlabelled_failure() -> Branch:
    """A retry that failed (MX) before AUTO labelled any point of it."""
    piece = _piece(RunStatus.MX)
    return replace(piece, label=np.zeros(ROWS, int), runs=("a.periodic_1.1r1",))


def test_a_retry_that_fails_before_its_first_label_restarts_further_back():
    family = _family()
    family.pieces.append(_piece(RunStatus.MX))
    first = _retry(family, family.pieces[-1])
    assert first.restart == ("a.periodic_1.0", 2) and len(family.pieces[-1]) == 4
    family.pieces.append(_unlabelled_failure())
    again = _retry(family, family.pieces[-1])
    # the failed retry is dropped; the family restarts from the label before label 2
    assert again is not None and again.restart == ("a.periodic_1.0", 1)
    assert len(family.pieces) == 1 and len(family.pieces[-1]) == 1
    assert again.constants["NTST"] == 160


def test_failures_far_apart_each_get_their_retries_up_to_a_total():
    family = _family()
    family.pieces.append(_piece(RunStatus.OK))
    retried = []
    for _ in range(MAX_REFINEMENTS + 1):
        family.pieces.append(_piece(RunStatus.MX))
        retried.append(_next_segment(family, None, [], 0.0))
        family.pieces.append(_piece(RunStatus.OK))
        family.retries = 0  # the retry reached the next fold: _next_segment's new count
    assert all(run is not None for run in retried[:MAX_REFINEMENTS])
    assert retried[-1] is None  # the mesh is not refined without end
    assert family.refinements == MAX_REFINEMENTS
