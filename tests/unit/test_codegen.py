"""Code generation: deterministic Fortran, AUTO's constants limits, the committed files."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from click.testing import CliRunner

from whirl_cli.auto import codegen
from whirl_cli.auto.constants import auto_name, constants_text, par_layout
from whirl_cli.auto.parse import BSegment
from whirl_cli.cli import cli
from whirl_cli.errors import CodegenError
from whirl_cli.models import get_model

from ..conftest import ROOT


@pytest.fixture(scope="module")
def model():
    return get_model("classical")


def test_fortran_is_deterministic_and_complete(model):
    first, second = codegen.fortran_source(model), codegen.fortran_source(model)
    assert first == second
    for routine in ("FUNC", "STPNT", "BCND", "ICND", "FOPT", "PVLS"):
        assert f"SUBROUTINE {routine}" in first and f"END SUBROUTINE {routine}" in first
    assert "WJ(1,1)" in first and "DFDU(3,1:4)" in first  # analytic Jacobians
    assert "DFDP(4," in first and "WP(2," in first
    assert "GETP('MAX', 1, U)" in first
    assert codegen.model_hash(model) in first


def test_par_layout_avoids_auto_reserved_slots(model):
    layout = par_layout(model)
    used = [*layout.parameters.values(), *layout.state_max.values(), *layout.state_min.values(),
            layout.amplitude]
    assert len(set(used)) == len(used)
    assert not set(used) & set(range(10, 37))  # PAR(11) period, HomCont 10..36
    assert layout.parameters["K_theta"] == 1 and layout.npar == max(used)


@pytest.mark.parametrize("value", [0.4, 1e-16, 2.0 * 3.141592653589793, 4.0, -10.0, 1.78e-4])
def test_fortran_number_round_trips(value):
    text = codegen.fortran_number(value)
    assert "d" in text and float(text.replace("d", "e")) == value


def test_constants_text_format_and_limits(model):
    text = constants_text({"NDIM": 4, "DS": -0.01, "ICP": ["K1", "PERIOD"],
                                   "UZSTOP": {"K1": [-0.3, 0.5]}, "e": "x"})
    assert text == ("NDIM = 4\nDS = -0.01\nICP = ['K1', 'PERIOD']\n"
                    "UZSTOP = {'K1': [-0.3, 0.5]}\ne = 'x'\n")
    with pytest.raises(CodegenError, match="<= 13 characters"):
        constants_text({"parnames": {1: "not-a-name"}})


def test_names_longer_than_auto_reads_reach_it_shortened_everywhere():
    """A name over AUTO's 13 characters (freeplay's epsilon_beta_y on the gimballed model) is
    written as its auto_name in parnames, ICP and every mapping's keys, and a b-file column of
    that name is read back by whirl's name."""
    long = "epsilon_beta_y"
    short = auto_name(long)
    assert len(short) <= 13 and short != long and auto_name("K_in_beta_y") == "K_in_beta_y"
    text = constants_text({"parnames": {43: long, 1: "V"}, "ICP": [long, "V", 11],
                           "UZR": {long: [1.0]}, "PAR": {long: 2.0, "V": 7.0}})
    assert long not in text and text.count(f"'{short}'") == 4, text
    segment = BSegment(columns=("V", short), active=(), br=np.ones(1), pt=np.ones(1),
                       ty=np.zeros(1), lab=np.zeros(1), values=np.array([[7.0, 2.0]]))
    assert segment.has(long) and segment.column(long)[0] == 2.0
    with pytest.raises(CodegenError, match="cannot hold"):
        constants_text({"e": "x'; rm"})
    with pytest.raises(CodegenError, match="2048"):
        constants_text({"UZR": {"K1": [0.1] * 400}})


def test_committed_files_match_the_models():
    """`whirl generate --check` on the repository's auto_equations/ (exit 0)."""
    result = CliRunner().invoke(cli, ["generate", "--check", "--dir",
                                      str(ROOT / "auto_equations")])
    assert result.exit_code == 0, result.output
    assert "up to date" in result.output


def test_generate_check_detects_drift(tmp_path):
    copy = tmp_path / "auto_equations"
    shutil.copytree(ROOT / "auto_equations", copy)
    target = copy / "classical_poly" / "classical_poly.f90"
    target.write_text(target.read_text().replace("F(1) =", "F(1) = 2*"))
    result = CliRunner().invoke(cli, ["generate", "--check", "--dir", str(copy)])
    assert result.exit_code == 1
    assert "classical_poly/classical_poly.f90" in result.output
    repaired = CliRunner().invoke(cli, ["generate", "--dir", str(copy)])
    assert repaired.exit_code == 0 and "wrote" in repaired.output
    assert CliRunner().invoke(cli, ["generate", "--check", "--dir", str(copy)]).exit_code == 0


def test_every_shipped_study_validates_and_its_variant_is_committed():
    """auto_equations/ holds the variants the shipped studies use (SHIPPED), and every study
    under studies/ is valid."""
    from whirl_cli.models import SHIPPED
    from whirl_cli.study import load_study

    shipped = {get_model(family, laws).name for family, laws in SHIPPED}
    studies = sorted(p for p in (ROOT / "studies").rglob("*.yaml")
                     if not p.name.endswith(".model.yaml"))
    assert len(studies) >= 30
    variants = [load_study(path).variant() for path in studies]
    assert any(v.family.key for v in variants)  # a study of a model file (generated on use)
    used = {v.name for v in variants if not v.family.key}
    assert used <= shipped, used - shipped
