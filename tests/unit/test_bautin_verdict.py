"""The verdict on a GH (Bautin) point AUTO flags on a Hopf locus: kept only where the first
Lyapunov coefficient changes sign between the locus's rows either side of it. The locus rows
here lie on the Hopf parabola mu = nu^2/4 of tests/data/bautin.model.yaml, whose l1 has the
sign of 3 (nu - 0.3) (1 + nu^2) - 1 (Guckenheimer and Holmes' planar formula, worked by hand
from its rates): negative below nu = 0.5549, positive above."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from whirl_cli.continuation.criticality import with_bautin_verdict
from whirl_cli.models import get_model, load_model_file
from whirl_cli.results import Branch, BranchKind, LocateStatus, Origin, PointType, SpecialPoint

from ..conftest import ROOT

PAIR = ("mu", "nu")


def _model():
    return get_model(load_model_file(ROOT / "tests" / "data" / "bautin.model.yaml"))


def _locus(nu: np.ndarray) -> tuple[Branch, SpecialPoint]:
    """A Hopf locus of three rows at ``nu`` on the parabola, a GH flagged on the middle one."""
    n = len(nu)
    parameters = np.column_stack([nu**2 / 4, nu])
    kinds = np.zeros(n, dtype=np.int64)
    kinds[1] = int(PointType.GH)
    period = 2 * np.pi / (1 + nu**2)
    locus = Branch(name="hopf_1a", kind=BranchKind.HOPF_LOCUS, origin=Origin(""),
                   parameter_names=PAIR, parameter_units=("", ""), state_names=("x", "y"),
                   state_units=("", ""), parameters=parameters, state_max=np.zeros((n, 2)),
                   state_min=np.zeros((n, 2)), l2_norm=np.zeros(n), period=period,
                   stable=np.zeros(n, dtype=bool), point_type=kinds,
                   label=np.zeros(n, dtype=np.int64), eigenvalues=np.full((n, 2), np.nan))
    point = SpecialPoint(branch="hopf_1a", index=1, point_type=int(PointType.GH),
                         parameter_names=PAIR, parameters=parameters[1], state=np.zeros(2),
                         period=float(period[1]), stable=False)
    return locus, point


@pytest.mark.parametrize("nu, status", [
    ((0.50, 0.555, 0.60), LocateStatus.LOCATED),      # l1 changes sign: a Bautin point
    ((0.20, 0.25, 0.30), LocateStatus.REJECTED),      # negative on both sides
    ((1.00, 1.05, 1.10), LocateStatus.REJECTED),      # positive on both sides
])
def test_a_gh_point_is_located_only_where_l1_changes_sign(nu, status):
    locus, point = _locus(np.array(nu))
    judged = with_bautin_verdict(_model(), locus, point, PAIR, {})
    assert judged.status == status
    assert ("does not change sign" in judged.note) == (status == LocateStatus.REJECTED)


def test_at_a_locus_end_a_gh_point_is_rejected_where_l1_vanishes_beside_it(tmp_path):
    """The last row of a locus of a model without a nonlinear term (the Bautin model's
    rates with their nonlinear terms left out): l1 is zero on the one side there is."""
    path = ROOT / "tests" / "data" / "bautin.model.yaml"
    text = path.read_text().replace(" + x**2 + x*y + (nu - 0.3)*x**3", "").replace(
        " + x**2\n", "\n").replace("name: bautin\n", "name: bautin_linear\n")
    assert "x**" not in text.split("rates:")[1]
    (tmp_path / "linear.yaml").write_text(text)
    linear = get_model(load_model_file(tmp_path / "linear.yaml"))
    locus, point = _locus(np.array([0.2, 0.25, 0.3]))
    point = replace(point, index=2)
    judged = with_bautin_verdict(linear, locus, point, PAIR, {})
    assert judged.status == LocateStatus.REJECTED and "vanishes beside it" in judged.note
    nonlinear = with_bautin_verdict(_model(), locus, point, PAIR, {})
    assert nonlinear.status == LocateStatus.LOCATED  # one side only: cannot be refuted
