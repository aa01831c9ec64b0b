"""AUTO output parsing on hand-written file fragments (edge cases of AUTO's Fortran output).
The round trip on files AUTO has just written is in tests/auto/test_parser_roundtrip.py."""

from __future__ import annotations

import math

import numpy as np
import pytest

from whirl_cli.auto.parse import fortran_float, parse_b, parse_d, parse_s
from whirl_cli.results import Origin, PointType


@pytest.mark.parametrize(("text", "value"), [
    ("1.5E+000", 1.5), ("-2.05071-106", -2.05071e-106), ("3.0D-02", 0.03),
    ("1.0+100", 1e100), ("-1.7976+308", -1.7976e308), ("0.0000000000E+000", 0.0),
])
def test_fortran_float(text, value):
    assert fortran_float(text) == value


def test_fortran_float_garbage_is_nan():
    assert math.isnan(fortran_float("*******"))


B_TEXT = """\
   0  -1.7976+308  1.7976+308 -1.7976+308  1.7976+308
   0   NDIM=   4   IPS =   1   IRS =   0   ILP =   1
   0   User-specified parameters:       'K1' 'max_theta'
   0   Active continuation parameter:   'K1'
   0
   0    PT  TY  LAB       K1              L2-NORM           max_theta
   1    -1   9    1  4.0000000000E-001  0.0000000000E+000  0.0000000000E+000
   1    -2   0    0  3.9599999960E-001  1.2345000000-101  1.0000000000E-003
   1     3   3    2  2.8876870044E-001  0.0000000000E+000  0.0000000000E+000
   0  -1.7976+308  1.7976+308 -1.7976+308  1.7976+308
   0   Active continuation parameter:   'K1'
   0    PT  TY  LAB       K1              L2-NORM           max_theta
  -2     1   9    3  1.0000000000E-001  5.0000000000E-001  2.0000000000E-001
"""


def test_parse_b_segments_columns_and_flags():
    first, second = parse_b(B_TEXT)
    assert first.columns == ("K1", "L2-NORM", "max_theta")
    assert first.active == ("K1",)
    assert list(first.pt < 0) == [True, True, False]
    assert first.column("L2-NORM")[1] == pytest.approx(1.2345e-101)
    assert [PointType.from_auto(int(t)) for t in first.ty] == [
        PointType.EP, PointType.REGULAR, PointType.HB]
    assert second.br[0] == -2 and second.column("max_theta")[0] == 0.2


def test_point_type_codes_on_loci():
    assert PointType.from_auto(30) is PointType.REGULAR  # regular point on a Hopf locus
    assert PointType.from_auto(-32) is PointType.GH
    assert PointType.from_auto(5) is PointType.LPC
    assert PointType.from_auto(-4) is PointType.UZ and PointType.from_auto(-9) is PointType.MX
    assert PointType.from_auto(23) is PointType.LTR


S_HEADER = ("     1     9     3     2     1     1       1     5      {rows}"
            "    1    0    3    0    4    1    0")
S_PROFILE = ("      0.0000000000E+000  1.0000000000E-001  2.0000000000E-001"
             "  3.0000000000E-001  4.0000000000E-001")
S_PAR = "      2.8876870044E-001  1.0000000000E+000  9.1442032475E+000"


def test_parse_s_with_and_without_direction_information():
    direction = ["    1", "      1.0000000000E+000",
                 "      0.0000000000E+000  0.0000000000E+000  1.0000000000E+000  0.0000000000E+000"]
    with_direction = "\n".join([S_HEADER.format(rows=5), S_PROFILE, *direction, S_PAR]) + "\n"
    without = "\n".join([S_HEADER.format(rows=2), S_PROFILE, S_PAR]) + "\n"
    for text in (with_direction, without, with_direction + without):
        solutions = parse_s(text)
        assert solutions[0].lab == 2 and solutions[0].ty == 3
        np.testing.assert_allclose(solutions[0].u, [[0.1, 0.2, 0.3, 0.4]])
        np.testing.assert_allclose(solutions[0].par, [0.28876870044, 1.0, 9.1442032475])
    assert len(parse_s(with_direction + without)) == 2


D_TEXT = """\
   1     1         Eigenvalues  :   Stable:   4
   1     1         Eigenvalue  1:  -1.54599E-02  -7.67261E-01
   1     1         Eigenvalue  2:  -1.54599E-02   7.67261E-01

  BR    PT  TY  LAB       K1
   1    -1  EP    1   4.00000E-01
===============================================
   2     5         Multiplier   1   9.99000E-01   0.00000E+00  Abs. Val.   9.99000E-01
   2     5         Multiplier   2   5.00000E-01   1.00000E-01  Abs. Val.   5.09902E-01
   2     5         Multiplier   1   1.00000E+00   0.00000E+00  Abs. Val.   1.00000E+00
   2     5         Multiplier   2   4.00000E-01   0.00000E+00  Abs. Val.   4.00000E-01
 NOTE:Multiplier inaccurate
   2     5         Multipliers:     Stable:   2
  BR    PT  TY  LAB       K1
  -2    -5  LP    2   4.00000E-01
"""


def test_parse_d_takes_the_last_block_and_late_stable_lines():
    (eig, mult), notes = parse_d(D_TEXT)
    assert eig.kind == "eigenvalues" and eig.n_stable == 4 and eig.pt == -1
    np.testing.assert_allclose(eig.values, [-0.0154599 - 0.767261j, -0.0154599 + 0.767261j])
    assert mult.kind == "multipliers" and mult.n_stable == 2 and (mult.br, mult.pt) == (-2, -5)
    np.testing.assert_allclose(mult.values, [1.0, 0.4])  # the accepted (last) block
    assert notes == ["NOTE:Multiplier inaccurate"]


# --------------------------------------------------------------- segments of unequal columns
STATE_COLUMNS = [f"{m}_{s}" for m in ("max", "min") for s in ("theta", "psi", "dtheta", "dpsi")]


def b_segment(br: int, columns: list[str], rows: list[tuple[int, float]]) -> str:
    """A b-file segment in AUTO's layout (title: 20 characters, then 19 per column); each row
    (PT, K_theta) has the value k/1000 in the k-th column after K_theta and L2-NORM = 0.5."""
    title = "   0    PT  TY  LAB " + "".join(f"{c:>14}     " for c in columns)
    lines = ["   0   NDIM=   4   IPS =   1   IRS =   0   ILP =   1",
             "   0   Active continuation parameter:   'K_theta'", title]
    for pt, k1 in rows:
        values = {"K_theta": k1, "L2-NORM": 0.5, **{c: (k + 1) / 1000 for k, c in enumerate(
            c for c in columns if c not in ("K_theta", "L2-NORM"))}}
        lines.append(f"{br:4d}{pt:6d}   0    0" + "".join(f"  {values[c]:.10E}"
                                                        for c in columns))
    return "\n".join(lines) + "\n"


def read_fragment(tmp_path, text: str):
    from whirl_cli.auto.parse import read_branch
    from whirl_cli.auto.runner import RunOutcome
    from whirl_cli.models import get_model

    (tmp_path / "b.k1.main").write_text(text)
    outcome = RunOutcome("k1.main", "ok", "ok", tmp_path, "", 0, 0.1, text.count("\n"))
    return read_branch(outcome, get_model("classical"), name="main", kind="equilibrium",
                       origin=Origin("start"), parameter_names=("K_theta",))


def test_segments_with_different_columns_keep_every_row(tmp_path):
    """A second segment with one more column (and its columns in another order): all rows
    are read, each shared column by its name."""
    first = b_segment(1, ["K_theta", "L2-NORM", *STATE_COLUMNS], [(-1, 0.4), (-2, 0.39)])
    second = b_segment(2, ["K_theta", "L2-NORM", "PERIOD", *reversed(STATE_COLUMNS)],
                       [(3, 0.2), (4, 0.1), (5, 0.0)])
    (a, b) = parse_b(first + second)
    assert a.columns != b.columns
    branch = read_fragment(tmp_path, first + second)
    assert branch.status == "ok" and len(branch) == 5
    np.testing.assert_allclose(branch.parameter("K_theta"), [0.4, 0.39, 0.2, 0.1, 0.0])
    assert list(branch.stable) == [True, True, False, False, False]
    # max_theta is the 1st state column of the first segment, the 9th of the second
    np.testing.assert_allclose(branch.state("theta"), [0.001, 0.001, 0.009, 0.009, 0.009])
    np.testing.assert_allclose(branch.state("dpsi", "min"),  # rates: 40 rad/s per unit
                               40 * np.array([0.008, 0.008, 0.002, 0.002, 0.002]))


def test_a_segment_without_a_column_whirl_needs_fails_the_branch_with_a_message(tmp_path):
    first = b_segment(1, ["K_theta", "L2-NORM", *STATE_COLUMNS], [(-1, 0.4), (-2, 0.39)])
    second = b_segment(2, ["K_theta", "L2-NORM", *STATE_COLUMNS[:-1]], [(3, 0.2)])
    branch = read_fragment(tmp_path, first + second)
    assert branch.status == "error" and len(branch) == 0
    assert branch.message == "AUTO's b-file lacks column(s) min_dpsi in some of its 2 segments"
