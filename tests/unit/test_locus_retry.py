"""A locus that AUTO stopped with MX is retried unless it ends at a located codimension-2
point: a GH point AUTO flags there is one only where the first Lyapunov coefficient changes
sign beside it (tests/data/bautin.model.yaml: at nu = 0.5549; its linear variant, without the
nonlinear terms, has l1 = 0 everywhere and so no Bautin point); and it is retried also when
AUTO labelled none of its points but the MX. The AUTO runs are stand-ins recording what they
are asked for: this is the recipe's decision, not a continuation result."""

from __future__ import annotations

from dataclasses import replace
from functools import partial

import numpy as np
import pytest

from whirl_cli.continuation import loci
from whirl_cli.continuation.engine import RunSpec
from whirl_cli.continuation.numerics import Numerics
from whirl_cli.models import get_model, load_model_file
from whirl_cli.results import Branch, BranchKind, Origin, PointType, RunStatus, SpecialPoint

from ..conftest import ROOT
from .locus_data import make_locus

PAIR = ("mu", "nu")
BOUNDS = {"mu": (-0.5, 0.5), "nu": (-0.5, 1.5)}
BAUTIN = ROOT / "tests" / "data" / "bautin.model.yaml"


def _linear_bautin(directory):
    """The Bautin model without its nonlinear terms (same Hopf locus, l1 = 0)."""
    text = BAUTIN.read_text().replace(" + x**2 + x*y + (nu - 0.3)*x**3", "").replace(
        " + x**2\n", "\n").replace("name: bautin\n", "name: bautin_linear\n")
    assert "x**" not in text.split("rates:")[1]
    (directory / "linear.yaml").write_text(text)
    return get_model(load_model_file(directory / "linear.yaml"))


def _hopf_locus(name: str, nu: np.ndarray, status: RunStatus, gh_row: int | None) -> Branch:
    """A Hopf locus of the Bautin model's origin along its parabola mu = nu^2/4, labelled at
    its first row, at ``gh_row`` (a GH point) and, if it ends in MX, at its last (MX) row."""
    n = len(nu)
    kinds = np.zeros(n, dtype=np.int64)
    label = np.zeros(n, dtype=np.int64)
    label[:1] = 1
    if gh_row is not None:
        kinds[gh_row], label[gh_row] = int(PointType.GH), 2
    if status == RunStatus.MX:
        kinds[-1], label[-1] = int(PointType.MX), 3
    return Branch(name=name, kind=BranchKind.HOPF_LOCUS, origin=Origin(""),
                  parameter_names=PAIR, parameter_units=("", ""), state_names=("x", "y"),
                  state_units=("", ""), parameters=np.column_stack([nu**2 / 4, nu]),
                  state_max=np.zeros((n, 2)), state_min=np.zeros((n, 2)), l2_norm=np.zeros(n),
                  period=2 * np.pi / (1 + nu**2), stable=np.zeros(n, dtype=bool),
                  point_type=kinds, label=label, eigenvalues=np.full((n, 2), np.nan),
                  status=status, runs=(f"c.{name}",))


class _Engine:
    """Records the AUTO runs it is asked for; makes none."""

    model = None

    def __init__(self) -> None:
        self.asked: list[RunSpec] = []

    def run_with_label(self, runs: tuple[str, ...], label: int) -> str:
        return runs[-1]

    def run_many(self, specs, background=False):
        self.asked += specs
        return [None] * len(specs)


def _trace(_engine, name, _pair, _bounds, _numerics, starts, background=False):
    """The locus from the one start: up the parabola to a GH point one row before an MX,
    and down it a little (ending of itself)."""
    constants = {"NTST": 20, "DSMAX": 0.05}
    up = np.r_[np.linspace(0.30, 0.53, 24), 0.54, 0.55, 0.56]
    rows = []
    for tag, nu, status, gh in (("a", up, RunStatus.MX, len(up) - 2),
                                ("b", np.linspace(0.30, 0.20, 11), RunStatus.OK, None)):
        spec = RunSpec(f"{name}/hopf_1{tag}", constants, BranchKind.HOPF_LOCUS, Origin(""),
                       PAIR)
        rows += [(k, PointType.HB, spec, _hopf_locus(f"hopf_1{tag}", nu, status, gh))
                 for k, _, _ in starts]
    return rows


def _no_output(_engine, spec, _outcome) -> Branch:
    """A retry that gave nothing (its locus stays as it was)."""
    return _hopf_locus(spec.name.split("/")[-1], np.zeros(0), RunStatus.OK, None)


@pytest.mark.parametrize("linear", [True, False])
def test_a_locus_ending_at_a_rejected_gh_point_is_retried(monkeypatch, tmp_path, linear):
    model = _linear_bautin(tmp_path) if linear else get_model(load_model_file(BAUTIN))
    monkeypatch.setattr(loci, "_trace", _trace)
    monkeypatch.setattr(loci, "read_run", _no_output)
    engine = _Engine()
    start = SpecialPoint("slice_0.main", 5, int(PointType.HB), PAIR, np.array([0.0225, 0.3]),
                         np.zeros(2), 2 * np.pi / 1.09, False)
    traced = loci._loci(engine, "c", PAIR, BOUNDS, Numerics(), [(start, ("c.main",))],
                        partial(loci.locus_points, model, pair=PAIR, parameters={}))
    up = next(curve for curve, _ in traced if curve.name == "hopf_1a")
    gh = next(p for curve, found in traced for p in found if p.point_type == PointType.GH)
    if linear:  # l1 vanishes beside it: no Bautin point, so the MX is a failure to retry
        assert gh.status == loci.LocateStatus.REJECTED
        assert [(spec.name, spec.restart) for spec in engine.asked] == [
            ("c/hopf_1ar", ("c.hopf_1a", 2))]
        assert up.end == "no convergence (MX)" and up.status == RunStatus.MX
    else:  # l1 changes sign there: the locus ends at the Bautin point, not retried
        assert gh.status == loci.LocateStatus.LOCATED
        assert engine.asked == []
        assert up.end.startswith("GH at") and up.status == RunStatus.OK


def test_a_locus_of_cycles_labelled_only_at_its_mx_end_is_retried_from_its_start(monkeypatch):
    """A fold-of-cycles locus's second stage that ends in MX within its first chunk carries no
    label but the MX's: it is retried from the point its run started from, on twice the mesh,
    and what the retry gives replaces it after that point."""
    steps = 8
    failed = replace(make_locus(np.column_stack([np.full(steps, 0.5),
                                                 np.linspace(0.2, 0.3, steps)])),
                     name="fold_of_cycles_1a2", status=RunStatus.MX,
                     point_type=np.r_[np.zeros(steps - 1, int), int(PointType.MX)],
                     label=np.r_[np.zeros(steps - 1, int), 9], runs=("c.fold_of_cycles_1a2",))
    spec = RunSpec("c/fold_of_cycles_1a2", {"NTST": 20, "DSMAX": 0.05, "NMX": 100},
                   BranchKind.FOLD_OF_CYCLES_LOCUS, Origin(""), ("p", "q"),
                   restart=("c.fold_of_cycles_1a", 5))

    def trace(_engine, _name, _pair, _bounds, _numerics, starts, background=False):
        return [(k, PointType.LPC, spec, failed) for k, _, _ in starts]

    def retry_run(_engine, spec, _outcome) -> Branch:
        """The retry: from the same start, on to q = 0.45, ending of itself."""
        return replace(make_locus(np.column_stack([np.full(12, 0.5), np.linspace(0.2, 0.45, 12)])),
                       name="fold_of_cycles_1a2r", runs=(spec.name.replace("/", "."),))

    monkeypatch.setattr(loci, "_trace", trace)
    monkeypatch.setattr(loci, "read_run", retry_run)
    engine = _Engine()
    start = SpecialPoint("slice_0.periodic_1", 5, int(PointType.LPC), ("p", "q"),
                         np.array([0.5, 0.2]), np.zeros(1), 1.0, False)
    ((curve, _),) = loci._loci(engine, "c", ("p", "q"), {"p": (0.0, 1.0), "q": (0.0, 1.0)},
                               Numerics(), [(start, ("c.slice_0.periodic_1",))])
    assert [(s.name, s.restart, s.constants["NTST"]) for s in engine.asked] == [
        ("c/fold_of_cycles_1a2r", ("c.fold_of_cycles_1a", 5), 40)]
    assert len(curve) == 12 and curve.parameters[-1, 1] == 0.45
    assert curve.status == RunStatus.OK
