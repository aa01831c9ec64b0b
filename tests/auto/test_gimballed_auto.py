"""The gimballed-hub model (8 states) on the real AUTO-07p (issue 16, items 1-3 and 6 in part).

* stiff-gimbal limit: K_beta = 1e6 gives the classical Hopf and branch points in K_theta;
* the shipped studies ``studies/gimballed/``: the combined pitch law at a soft gimbal (Hopf and
  branch points against eigenvalues, +/- pairs of secondary equilibria that are equilibria of
  the model, periodic families with passing cross-checks, HDF5, plots of a gimbal state,
  compare) and the onset against K_beta (the Hopf locus against eigenvalues);
* 8-state code generation and compilation in a cold cache, the code within 4 times the
  classical model's.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from whirl_cli.analysis import linear
from whirl_cli.auto import toolchain
from whirl_cli.auto.codegen import fortran_source
from whirl_cli.cli import cli
from whirl_cli.models import get_model
from whirl_cli.models.numeric import numeric_source
from whirl_cli.output import store
from whirl_cli.pipeline import run_study
from whirl_cli.results import BranchKind, PointType, Spacing
from whirl_cli.study import load_study, validate_text

from ..conftest import ROOT

GIMBALLED_STUDIES = ROOT / "studies" / "gimballed"
MODEL = get_model("gimballed")


def k1_study(model: str, extra: str = "", law: str = "{type: linear}",
             periodic: bool = False) -> str:
    """K_psi = 0.3, K_theta from 0.5 down to -0.3 (linear springs and equilibria only unless
    ``law`` and ``periodic`` say otherwise).

    The step is capped at 0.003 of the range: with K_beta = 1e6 the Jacobian's entries reach
    ~1e7 in AUTO's units while its trace stays ~1, so AUTO takes the system for conservative
    and counts eigenvalues with real part <= 1e-5 as stable (ae.f90, STABEQ); a step landing
    within that margin of a Hopf point (as the default steps do at 0.0807) hides it."""
    return f"""\
name: k1-{model}
model: {model}
parameters: {{K_psi: 0.3{extra}}}
nonlinearity: {law}
auto: {{step_max: 0.003}}
continuations:
  - {{name: k1, type: one-parameter, parameter: K_theta, start: 0.5, range: [-0.3, 0.5],
      periodic: {str(periodic).lower()}, branch_points: true}}
"""


def points(result, kind: PointType) -> list[float]:
    (continuation,) = result.continuations
    return sorted(float(p.parameters[0]) for p in continuation.special_points
                  if p.point_type == kind and p.branch == "main_down")


def test_stiff_gimbal_hopf_and_branch_points_are_the_classical(tmp_path):
    """K_beta = 1e6: AUTO's Hopf points (0.0807, 0.2888) and pitchfork (0.03598) in K_theta
    at K_psi = 0.3 equal the classical model's AUTO points (1e-3 relative)."""
    rigid = run_study(validate_text(k1_study("gimballed", ", K_beta: 1.0e+6")),
                      tmp_path / "rigid", jobs=2)
    reference = run_study(validate_text(k1_study("classical")), tmp_path / "classical", jobs=2)
    for kind in (PointType.HB, PointType.BP):
        found, expected = points(rigid, kind), points(reference, kind)
        assert len(found) == len(expected) == (2 if kind == PointType.HB else 1)
        np.testing.assert_allclose(found, expected, rtol=1e-3)


def test_stiff_gimbal_combined_law_folds_of_cycles_are_the_classical(tmp_path):
    """K_beta = 1e6 with the combined pitch law (K2 = -10, K3 = 350) at K_psi = 0.3: the Hopf
    points of every equilibrium branch and the folds of cycles of the periodic families equal
    the classical model's (combined case 2, same AUTO settings; 1e-3 relative)."""
    law = "{type: polynomial, dof: theta, K2: -10.0, K3: 350.0}"
    rigid = run_study(validate_text(k1_study("gimballed", ", K_beta: 1.0e+6", law, True)),
                      tmp_path / "rigid", jobs=2)
    reference = run_study(validate_text(k1_study("classical", "", law, True)),
                          tmp_path / "classical", jobs=2)

    def located(result, kind):
        (continuation,) = result.continuations
        return sorted(float(p.parameters[0]) for p in continuation.special_points
                      if p.point_type == kind)

    for kind in (PointType.HB, PointType.LPC):
        found, expected = located(rigid, kind), located(reference, kind)
        assert len(found) == len(expected) >= (3 if kind == PointType.LPC else 6)
        np.testing.assert_allclose(found, expected, rtol=1e-3)


# ------------------------------------------------------------------------------ combined, soft
@pytest.fixture(scope="module")
def combined(tmp_path_factory):
    """``whirl run`` of the shipped combined study: (output path, CLI output, result)."""
    folder = tmp_path_factory.mktemp("combined")
    output = folder / "combined.h5"
    started = time.perf_counter()
    done = CliRunner().invoke(cli, ["run", str(GIMBALLED_STUDIES / "combined_case2_soft.yaml"),
                                    "-o", str(output), "--jobs", "2"])
    seconds = time.perf_counter() - started
    assert done.exit_code == 0, done.output
    print(f"\n  combined_case2_soft: {seconds:.1f} s")
    return output, done.output, store.read(output)


def test_combined_hopf_and_branch_points_against_eigenvalues(combined):
    """The origin's Hopf and branch points in K_theta by AUTO equal the eigenvalue
    analysis of the same study (1e-6 of the range)."""
    study = load_study(GIMBALLED_STUDIES / "combined_case2_soft.yaml")
    overrides = {k: v for k, v in study.parameter_values().items() if k != "K_theta"}
    expected = linear.critical_points(MODEL, overrides, "K_theta", -0.3, 0.5)
    result = combined[2]
    assert points(result, PointType.HB) == pytest.approx(
        [c.value for c in expected if c.kind == "hopf"], abs=1e-6 * 0.8)
    assert points(result, PointType.BP) == pytest.approx(
        [c.value for c in expected if c.kind == "branch_point"], abs=1e-6 * 0.8)


def test_secondary_equilibria_come_in_mirror_pairs_and_are_equilibria(combined):
    """The pitchfork's two secondary branches are each other's mirror image (all states ->
    minus, the declared symmetry), and every point of them is an equilibrium of the model
    (|f| small against the terms it balances)."""
    (continuation,) = combined[2].continuations
    secondary = sorted((b for b in continuation.branches if b.name.startswith("secondary")),
                       key=lambda b: b.name)
    assert [b.name for b in secondary] == ["secondary_1a", "secondary_1b"]
    a, b = secondary
    np.testing.assert_allclose(a.parameters, b.parameters, rtol=0, atol=1e-9)
    np.testing.assert_allclose(a.state_max, -b.state_max, rtol=1e-7, atol=1e-9)
    assert np.abs(a.state_max[:, 0]).max() > 0.1  # pitch really deflected (rad)
    study = load_study(GIMBALLED_STUDIES / "combined_case2_soft.yaml")
    values = study.parameter_values()
    for branch in (a, b):
        for row in range(0, len(branch), 10):
            params = MODEL.parameter_vector({**values, "K_theta": branch.parameters[row, 0]})
            rates = MODEL.rhs_numpy(branch.state_max[row], params)[4:]
            scale = np.abs(MODEL.jacobian_numpy(branch.state_max[row], params)[4:, :4]
                           * branch.state_max[row, :4]).max()
            assert np.abs(rates).max() <= 1e-6 * scale
    pairs = [p for p in continuation.special_points if p.branch.startswith("secondary")]
    by_value = {}
    for p in pairs:
        by_value.setdefault((p.point_type, round(float(p.parameters[0]), 9)), []).append(p)
    assert by_value and all(len(v) == 2 for v in by_value.values())
    for first, second in by_value.values():
        np.testing.assert_allclose(first.state, -second.state, atol=1e-9)


def test_combined_periodic_families_and_cross_checks(combined):
    """Periodic families from the Hopf points (each Hopf point starts a family or is reached,
    within 1e-3 of the range, by one from another: then whirl stores it once), every state
    of the 8 stored, cross-checked by time simulation."""
    output, text, result = combined
    (continuation,) = result.continuations
    families = [b for b in continuation.branches if b.kind == BranchKind.PERIODIC]
    hopfs = [p for p in continuation.special_points if p.point_type == PointType.HB]
    assert len(families) >= 4 and all(f.origin.point == PointType.HB for f in families)
    for hopf in hopfs:
        value = float(hopf.parameters[0])
        assert any(abs(f.parameters[:, 0] - value).min() < 1e-3 * 0.8 for f in families
                   if f.origin.branch == hopf.branch or hopf.branch == "main_down")
    assert continuation.cross_checks and all(c.passed for c in continuation.cross_checks)
    assert all(b.state_max.shape[1] == 8 for b in continuation.branches)
    assert "cross-checks by time simulation" in text


def test_combined_files_plots_of_a_gimbal_state_and_compare(combined, tmp_path):
    output, _, result = combined
    assert result.continuations[0].branches[0].state_names == MODEL.state_names
    assert (output.parent / "combined_k1_bifurcation.png").exists()
    done = CliRunner().invoke(cli, ["plot", str(output), "--kind", "bifurcation", "--state",
                                    "beta_y", "-o", str(tmp_path)])
    assert done.exit_code == 0, done.output
    assert list(tmp_path.glob("*bifurcation*.png"))
    done = CliRunner().invoke(cli, ["compare", str(output), str(output)])
    assert done.exit_code == 0, done.output


# ------------------------------------------------------------------------------ onset study
def test_onset_study_hopf_locus_against_eigenvalues(tmp_path):
    """studies/gimballed/linear_onset_kbeta.yaml through ``whirl sweep``: every 5th point of
    the Hopf locus in (V, K_beta) by AUTO is where the eigenvalues give the onset at that
    K_beta (1e-5 of V's range); the locus spans soft to stiff gimbals; the K_beta sweep
    stores mode groups; the sweep and the grid sample K_beta log."""
    done = CliRunner().invoke(cli, ["sweep", str(GIMBALLED_STUDIES / "linear_onset_kbeta.yaml"),
                                    "-o", str(tmp_path), "--jobs", "1"])
    assert done.exit_code == 0, done.output
    result = store.read(tmp_path / "gimballed-linear-onset-kbeta.h5")
    (boundary,) = result.boundaries
    curves = [curve for kind, curve in boundary.loci.values() if kind == "hopf"]
    assert curves
    curve = np.concatenate(curves)
    assert curve[:, 1].min() < 1.0 and curve[:, 1].max() > 40.0
    for speed, k_beta in curve[::5]:
        onset = [c.value for c in linear.critical_points(MODEL, {"K_beta": k_beta}, "V", 0.0,
                                                         12.0, points=401) if c.kind == "hopf"]
        assert min(abs(v - speed) for v in onset) < 1e-5 * 12.0
    (sweep,) = result.linear_sweeps
    assert set(np.unique(sweep.mode_group)) == {"nacelle", "gimbal"}
    # soft to rigid gimbals: K_beta sampled with a constant ratio, sweep and grid alike
    for values, spacing in ((sweep.values, sweep.spacing),
                            (result.linear_grid.x, result.linear_grid.x_spacing)):
        assert spacing == Spacing.LOG
        np.testing.assert_allclose(values[1:] / values[:-1], values[1] / values[0], rtol=1e-12)


# ------------------------------------------------------------------------------ size
def test_eight_state_code_grows_with_the_jacobian_and_compiles(tmp_path, monkeypatch):
    """Cold cache: the numeric module and the Fortran of gimballed_poly compile, and nothing
    symbolic is needed at run time afterwards. The generated code is a count of the work: the
    Jacobian of 8 states has 4 times the entries of the classical model's 4, so each file stays
    within 4 times the classical one (a mass matrix inverted symbolically, or unsimplified
    products of it, would grow far faster and take minutes to generate and compile)."""
    monkeypatch.setenv("WHIRL_CACHE_DIR", str(tmp_path))
    numeric = numeric_source(MODEL)
    fortran = fortran_source(MODEL)
    executable = toolchain.compile_equations(fortran, MODEL.name)
    assert executable.compiled and Path(executable.path).exists()
    assert "import sympy" not in numeric and "N_STATES = 8" in numeric
    classical = get_model("classical")
    assert len(fortran) < 4 * len(fortran_source(classical))
    assert len(numeric) < 4 * len(numeric_source(classical))
