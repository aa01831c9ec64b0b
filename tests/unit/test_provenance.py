"""The provenance a result stores (results.Provenance): it round-trips through the file, an
older file without it reads with it recovered from its stored study, and the plots draw from
it alone (they import neither the study schema nor the models)."""

from __future__ import annotations

import ast
import math
from dataclasses import fields, replace

import numpy as np
import yaml

from whirl_cli.output import store
from whirl_cli.output.provenance import provenance
from whirl_cli.results import FixedParameter, SliceLabel, StudyResult
from whirl_cli.study import validate_text

from ..conftest import ROOT

OLD = ROOT / "tests" / "regression" / "references" / "hardening_case2.h5"
STUDY = """\
name: p
model: classical
parameters: {K_psi: 0.3, V: 6.7}
nonlinearity: {type: freeplay, dof: theta, delta: 0.02, K_out: 0.4}
continuations:
  - name: fold
    type: two-parameter
    parameters: [V, K_psi]
    range: {V: [5.5, 8.5], K_psi: [0.2, 0.42]}
    start: 6.7
    slices: [0.3, {value: 0.25, label: soft}]
    loci: [fold_of_cycles]
"""


def test_provenance_round_trips(tmp_path):
    found = provenance(validate_text(STUDY))
    assert found.fixed == (FixedParameter("K_psi", 0.3, "N m/rad"),
                           FixedParameter("V", 6.7, "m/s"))
    assert found.slices == (SliceLabel("fold", 0, ""), SliceLabel("fold", 1, "soft"))
    assert [law.linear for law in found.laws] == [False, True]
    back = store.read(store.write(StudyResult("p", "m", (), (), (), provenance=found),
                                  tmp_path / "r.h5")).provenance
    for f in fields(found):
        if f.name != "laws":
            assert getattr(back, f.name) == getattr(found, f.name), f.name
    for law, other in zip(found.laws, back.laws, strict=True):
        for f in fields(law):
            np.testing.assert_array_equal(getattr(other, f.name), getattr(law, f.name))
    assert back.slice_labels("fold") == ("", "soft")


def test_freeplay_curve_is_the_law_it_names():
    (curve,) = provenance(validate_text(STUDY)).nonlinear_laws
    assert (curve.dof, curve.law, curve.stiffness, curve.stiffness_value) == (
        "theta", "freeplay", "K_theta", 0.4)
    assert curve.breakpoints == (-0.02, 0.02)
    outside = np.abs(curve.x) >= 0.02
    expected = 0.4 * (curve.x - 0.02 * np.sign(curve.x))  # K_in = 0 inside the gap
    np.testing.assert_allclose(curve.exact[outside], expected[outside], atol=1e-15)
    np.testing.assert_array_equal(curve.exact[~outside], 0.0)
    assert math.isclose(np.max(np.abs(curve.x)), 4 * 0.02)


def test_an_older_file_reads_with_its_provenance_recovered():
    """A file written before whirl stored its provenance group: what the titles and law plots
    need is read off the study stored with it, as the study text says."""
    with store.opened(OLD) as handle:
        assert "provenance" not in handle
    result = store.read(OLD)
    written = yaml.safe_load(result.provenance.study_yaml)
    assert [(p.name, p.value) for p in result.provenance.fixed] == list(
        written["parameters"].items())
    (curve,) = result.provenance.nonlinear_laws
    law = written["nonlinearity"]
    assert (curve.dof, curve.law) == (law["dof"], law["type"])
    x = curve.x
    np.testing.assert_allclose(curve.force, curve.stiffness_value * x + law["K2"] * x**3,
                               rtol=1e-12)


def test_an_older_file_reads_with_canonical_parameter_names():
    """The legacy file stores the thesis's alias K1 (the pitch stiffness, K_theta, of the
    study's one law): read, its branches and points name K_theta, and whirl check runs."""
    from click.testing import CliRunner

    from whirl_cli.cli import cli

    legacy = ROOT / "tests" / "data" / "legacy_hardening_case2.h5"
    with store.opened(legacy) as handle:
        stored = handle["continuations/k1/branches/main_down/parameters"].attrs["names"]
        assert [str(n) for n in stored] == ["K1"]
    result = store.read(legacy)
    assert {b.parameter_names for c in result for b in c} == {("K_theta",)}
    assert {p.parameter_names for c in result for p in c.special_points} == {("K_theta",)}
    run = CliRunner().invoke(cli, ["check", str(legacy)])
    assert run.exit_code == 0, run.output
    assert "K_theta = " in run.output


def test_a_file_without_a_valid_stored_study_still_reads(tmp_path):
    """An older file whose study today's schema rejects reads with the provenance it has."""
    old = store.read(OLD)
    path = store.write(replace(old, provenance=replace(old.provenance, fixed=(), laws=())),
                       tmp_path / "r.h5")
    import h5py

    with h5py.File(path, "r+") as handle:
        del handle["provenance"]
        handle.attrs["whirl_parts"] = [p for p in handle.attrs["whirl_parts"]
                                       if p != "provenance"]
        handle.attrs["study_yaml"] = "name: ["
    found = store.read(path).provenance
    assert (found.study_yaml, found.fixed, found.laws) == ("name: [", (), ())


def imported(path) -> set[str]:
    """The modules a source file imports, absolute or relative as written (``..study``), and
    the names taken from a package (``from .. import study``: ``..study``)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = "." * node.level + (node.module or "")
            found |= {base} | {base.rstrip(".") + "." + a.name if node.module
                               else base + a.name for a in node.names}
        elif isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
    return found


def test_plots_import_neither_the_study_schema_nor_the_models():
    banned = ("..study", "..models", "whirl_cli.study", "whirl_cli.models")
    for path in sorted((ROOT / "whirl_cli" / "plots").glob("*.py")):
        assert not [m for m in imported(path) if m.startswith(banned)], path.name


def test_slice_membership_is_read_back_from_the_name_it_was_given():
    from whirl_cli.results import on_slice, slice_branch

    assert on_slice(slice_branch(1, "periodic_2.0"), 1) == "periodic_2.0"
    assert on_slice(slice_branch(10, "main_down"), 1) is None  # not slice 1's
    assert on_slice(slice_branch(1, "main_down"), 10) is None
    assert on_slice("hopf_0a", 0) is None  # a locus is on no slice
