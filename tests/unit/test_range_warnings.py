"""A boundary study warns where its range may not hold the unsafe region: an unsafe interval
ending at an edge of the first parameter's range, a fold or fold-of-cycles locus leaving it
(the intervals it bounds beyond are never formed); the ranges are stored, and a file written
before them reads as 'not known' (no warning)."""

from __future__ import annotations

import h5py
import numpy as np

from whirl_cli.output import store
from whirl_cli.output.summary import tables
from whirl_cli.results import Boundary, ContinuationResult, StudyResult, UnsafeInterval
from whirl_cli.verdict import range_warnings


def boundary(intervals, loci, first_range=(-0.3, 0.5)) -> Boundary:
    return Boundary("boundary", ("K_theta", "K_psi"), ("N m/rad", "N m/rad"), "loci", loci,
                    tuple(intervals), (), (0.3,), first_range, (0.0, 0.5))


INSIDE = UnsafeInterval(0.3, 0.2888, 0.41, "flutter")
CUT = UnsafeInterval(0.3, 0.2888, 0.5, "flutter")
#: a fold-of-cycles locus that leaves K1 = 0.5 (its last step just past it), a Hopf locus
#: ending on the edge (the stability boundary runs on: not a sign of a cut region)
LEAVING = {"fold_of_cycles_0a": ("fold_of_cycles", np.array([[0.41, 0.3], [0.5000001, 0.29]])),
           "hopf_0a": ("hopf", np.array([[0.2888, 0.3], [0.5, 0.45]]))}


def test_an_interval_at_the_edge_and_a_fold_locus_leaving_the_range_are_warned_of():
    assert range_warnings(boundary([INSIDE], {})) == ()
    (cut,) = range_warnings(boundary([CUT], {}))
    assert "0.2888 < K_theta < 0.5 at K_psi = 0.3 ends at the edge of the range" in cut
    (leaving,) = range_warnings(boundary([INSIDE], LEAVING))
    assert "fold of cycles locus fold_of_cycles_0a leaves the range of K_theta" in leaving
    assert "K_psi = 0.29" in leaving
    assert range_warnings(boundary([CUT], LEAVING, (np.nan, np.nan))) == ()


def test_the_ranges_are_stored_and_older_files_warn_of_nothing(tmp_path):
    found = boundary([CUT], LEAVING)
    result = StudyResult("s", "classical", (ContinuationResult("boundary", "two-parameter",
                                                               (), ()),), (), (),
                         {}, (found,))
    path = store.write(result, tmp_path / "new.h5")
    (read,) = store.read(path).boundaries
    assert read.first_range == (-0.3, 0.5) and read.second_range == (0.0, 0.5)
    assert range_warnings(read) == range_warnings(found)
    notes = tables(store.read(path))[0].notes
    assert len([n for n in notes if n.startswith("warning: boundary: ")]) == 2
    with h5py.File(path, "r+") as handle:  # as written before the ranges were stored
        for key in ("first_range", "second_range"):
            del handle["boundaries/boundary"].attrs[key]
    (older,) = store.read(path).boundaries
    assert np.isnan(older.first_range).all() and range_warnings(older) == ()


def test_a_fold_of_cycles_locus_leaving_where_it_bounds_no_stable_cycles_is_not_warned_of(
        tmp_path):
    """The locus's last point lies past the slices whose folds join unstable cycles to
    unstable ones: no unsafe interval is formed there inside or outside the range."""
    silent = boundary([INSIDE], LEAVING)
    silent = Boundary(**{**silent.__dict__, "bounding_ends": {"fold_of_cycles_0a": (True, False)}})
    assert range_warnings(silent) == ()
    result = StudyResult("s", "classical", (ContinuationResult("boundary", "two-parameter",
                                                               (), ()),), (), (),
                         {}, (silent,))
    (read,) = store.read(store.write(result, tmp_path / "silent.h5")).boundaries
    assert read.bounding_ends == {"fold_of_cycles_0a": (True, False)}
    assert range_warnings(read) == ()
