"""Torus (TR) loci without AUTO: the constants (AUTO's rule for which parameters are free),
which TR points start a locus, the torus angle read from a b-file, kept by the branch operations
and stored in HDF5. The loci themselves, on the real AUTO: tests/auto/test_torus_locus.py."""

from __future__ import annotations

import numpy as np
import pytest

from whirl_cli import results
from whirl_cli.results import BranchKind, Origin, PointType


def test_a_torus_locus_frees_the_period_and_the_torus_angle():
    """AUTO 0.9.2 (periodic.f90, INITPS) restarts a torus locus with ICP(3) = 11 and ICP(4) =
    12 only if fewer than 4 ICP are given; whirl lists its PVLS outputs after them, so it must
    name both itself (else the 4th free parameter is a PVLS output and the angle is frozen)."""
    from whirl_cli.continuation.engine import Numerics
    from whirl_cli.continuation.loci import locus_constants
    from whirl_cli.models import get_model

    model = get_model("gimballed")
    bounds = {"V": (8.0, 12.0), "K_beta": (0.6, 0.75)}
    torus = locus_constants(model, Numerics(), ("V", "K_beta"), bounds, 1, PointType.TR)
    assert torus["ICP"][:4] == ["V", "K_beta", "PERIOD", 12]
    assert (torus["IPS"], torus["ISW"], torus["ISP"], torus["ILP"]) == (2, 2, 0, 0)
    assert torus["UZSTOP"]["K_beta"] == [0.6, 0.75]
    cycles = locus_constants(model, Numerics(), ("V", "K_beta"), bounds, 1, PointType.LPC)
    assert 12 not in cycles["ICP"] and cycles["ICP"][:3] == ["V", "K_beta", "PERIOD"]


def _point(angle: float, status: str = "located") -> results.SpecialPoint:
    return results.SpecialPoint("slice_0.periodic_1", 3, int(PointType.TR), ("V", "K_beta"),
                                np.array([11.0, 0.67]), np.zeros(8), 0.04, True,
                                status=status, torus_angle=angle)


def test_only_torus_points_with_a_pair_on_the_unit_circle_start_a_locus():
    from whirl_cli.continuation.loci import _starts_locus

    assert _starts_locus(_point(0.5))
    assert not _starts_locus(_point(float("nan")))  # a neutral saddle, or no multipliers
    assert not _starts_locus(_point(0.5, status="bracketed"))
    hopf = results.SpecialPoint("slice_0.main_up", 1, int(PointType.HB), ("V", "K_beta"),
                                np.array([8.8, 0.67]), np.zeros(8), 0.1, True)
    assert _starts_locus(hopf)  # no angle needed


STATES = ("theta", "psi", "beta_y", "beta_z", "dtheta", "dpsi", "dbeta_y", "dbeta_z")
COLUMNS = ["V", "L2-NORM", "K_beta", "PERIOD", "PAR(12)",
           *(f"{m}_{s}" for m in ("max", "min") for s in STATES)]


def _locus_file(angles: list[float], columns: list[str] = COLUMNS) -> str:
    """A b-file of a torus locus in AUTO's layout (title: 20 characters, then 19 per column)."""
    title = "   0    PT  TY  LAB " + "".join(f"{c:>14}     " for c in columns)
    lines = ["   0   NDIM=  24   IPS =   2   IRS =   5   ILP =   0", title]
    for k, angle in enumerate(angles, 1):
        values = {"V": 11.0 + 0.01 * k, "K_beta": 0.6 + 0.001 * k, "PERIOD": 1.6,
                  "PAR(12)": angle}
        lines.append(f"   3{k:6d}   0    0" + "".join(f"  {values.get(c, 0.001):.10E}"
                                                     for c in columns))
    return "\n".join(lines) + "\n"


def _read(tmp_path, text: str) -> results.Branch:
    from whirl_cli.auto.parse import read_branch
    from whirl_cli.auto.runner import RunOutcome
    from whirl_cli.models import get_model

    (tmp_path / "b.t.torus_1a2").write_text(text)
    outcome = RunOutcome("t.torus_1a2", "ok", "ok", tmp_path, "", 0, 0.1, text.count("\n"))
    model = get_model("gimballed")
    assert model.state_names == STATES
    return read_branch(outcome, model, name="torus_1a",
                       kind=BranchKind.TORUS_LOCUS, origin=Origin("TR"),
                       parameter_names=("V", "K_beta"))


def test_the_torus_angle_is_read_from_par_12_in_zero_to_pi(tmp_path):
    """AUTO's PAR(12) may leave (0, pi) (the pair is exp(+-i theta)): stored as the angle of
    the pair's upper member."""
    branch = _read(tmp_path, _locus_file([0.5, -0.5, 2 * np.pi + 0.25, np.pi + 0.25]))
    assert branch.status == "ok" and len(branch) == 4
    np.testing.assert_allclose(branch.torus_angle, [0.5, 0.5, 0.25, np.pi - 0.25], atol=1e-9)
    assert branch.orbits == ()  # no s-file here
    assert not branch.stability_known.any()  # a locus


def test_a_torus_locus_without_its_angle_column_fails_with_a_message(tmp_path):
    columns = [c for c in COLUMNS if c != "PAR(12)"]
    branch = _read(tmp_path, _locus_file([0.5, 0.5], columns))
    assert branch.status == "error" and len(branch) == 0 and len(branch.torus_angle) == 0
    assert "PAR(12)" in branch.message


def _locus(n: int, start: float = 0.0) -> results.Branch:
    rows = np.arange(n, dtype=float) + start
    return results.Branch(
        name="torus_1a", kind=BranchKind.TORUS_LOCUS, origin=Origin("TR"),
        parameter_names=("V", "K"),
        parameter_units=("m/s", "N m/rad"), state_names=("q", "dq"), state_units=("m", "m/s"),
        parameters=np.column_stack([rows, rows]), state_max=np.zeros((n, 2)),
        state_min=np.zeros((n, 2)), l2_norm=rows, period=rows, stable=np.zeros(n, bool),
        point_type=np.zeros(n, np.int64), label=np.zeros(n, np.int64),
        eigenvalues=np.zeros((n, 2), complex), torus_angle=0.1 * (rows + 1))


def test_branch_operations_keep_the_torus_angle_with_its_rows():
    from whirl_cli.continuation.branches import head, join, reverse

    first, second = _locus(4), _locus(3, start=3.0)
    joined = join(first, second, "torus_1a")
    assert len(joined) == 6
    np.testing.assert_allclose(joined.torus_angle, 0.1 * np.arange(1, 7))
    np.testing.assert_allclose(head(joined, 2).torus_angle, [0.1, 0.2])
    np.testing.assert_allclose(reverse(first).torus_angle, [0.4, 0.3, 0.2, 0.1])
    plain = results.Branch(**{**first.__dict__, "kind": BranchKind.HOPF_LOCUS,
                              "torus_angle": None})
    assert head(plain, 2).torus_angle is None and join(plain, plain, "x").torus_angle is None


def test_the_torus_angle_round_trips_through_hdf5_and_only_torus_loci_store_it(tmp_path):
    import h5py

    from whirl_cli.output import store

    torus = _locus(3)
    hopf = results.Branch(**{**torus.__dict__, "name": "hopf_1a",
                             "kind": BranchKind.HOPF_LOCUS, "torus_angle": None})
    result = results.StudyResult("s", "m", (results.ContinuationResult(
        "c", "two-parameter", (torus, hopf), ()),), (), (), {})
    path = store.write(result, tmp_path / "r.h5")
    back = store.read(path)
    (continuation,) = back.continuations
    read_torus, read_hopf = continuation.branches
    np.testing.assert_array_equal(read_torus.torus_angle, torus.torus_angle)
    assert read_hopf.torus_angle is None
    with h5py.File(path) as handle:
        branches = handle["continuations/c/branches"]
        assert branches["torus_1a/torus_angle"].attrs["units"] == "rad"
        assert "torus_angle" not in branches["hopf_1a"]


@pytest.mark.parametrize("theta", [0.3, 3.0])
def test_principal_angle_is_that_of_the_upper_multiplier(theta):
    from whirl_cli.auto.parse import _principal_angle

    for turns in (-2, 0, 1):
        for sign in (1, -1):
            (angle,) = _principal_angle(np.array([sign * theta + 2 * np.pi * turns]))
            assert angle == pytest.approx(theta, abs=1e-12)
