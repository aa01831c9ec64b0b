"""HDF5 references: fresh real-AUTO runs must match the committed files under ``references/``
(``whirl compare``), and the comparison must catch physical drift.

The references are regenerated deliberately with ``make references`` (``whirl run ...
--no-plots --overwrite``); review ``whirl compare OLD NEW`` before committing new ones.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import h5py
import pytest
from click.testing import CliRunner

from whirl_cli.cli import cli
from whirl_cli.output import store
from whirl_cli.output.compare import compare_files
from whirl_cli.pipeline import run_study
from whirl_cli.study import load_study

from ..conftest import STUDIES

REFERENCES = Path(__file__).parent / "references"
NAMES = sorted(p.stem for p in REFERENCES.glob("*.h5"))
MAX_BYTES = 512 * 1024  # references are committed: keep them small


def test_references_exist_and_are_small():
    assert NAMES == ["hardening_case2", "linear_datum_airspeed"]
    for name in NAMES:
        assert (REFERENCES / f"{name}.h5").stat().st_size < MAX_BYTES


@pytest.mark.parametrize("name", NAMES)
def test_fresh_run_matches_reference(name, tmp_path):
    reference = REFERENCES / f"{name}.h5"
    study = load_study(STUDIES / f"{name}.yaml")
    stored = store.read(reference)
    assert stored.provenance.study_sha256 == study.sha256, (
        f"studies/thesis_ch3/{name}.yaml changed since the reference was made: check the "
        "change, then run `make references`")
    fresh = store.write(run_study(study, tmp_path / "work", jobs=2), tmp_path / f"{name}.h5")
    differences = compare_files(reference, fresh)
    assert differences == [], "drift from the reference (`make references` regenerates it):\n" \
        + "\n".join(map(str, differences[:20]))


@pytest.fixture
def reference_copy(tmp_path) -> tuple[Path, Path]:
    source = REFERENCES / "hardening_case2.h5"
    copy = tmp_path / "copy.h5"
    shutil.copyfile(source, copy)
    return source, copy


def compare_cli(a: Path, b: Path):
    return CliRunner().invoke(cli, ["compare", str(a), str(b)])


def test_reference_agrees_with_itself(reference_copy):
    result = compare_cli(*reference_copy)
    assert result.exit_code == 0, result.output
    assert "agree" in result.output


def test_compare_catches_a_moved_hopf_point(reference_copy):
    source, copy = reference_copy
    with h5py.File(copy, "r+") as handle:
        table = handle["continuations/k1/special_points"]
        row = [t.decode() if isinstance(t, bytes) else t
               for t in table["type_name"][()]].index("HB")
        parameters = table["parameters"][()]
        parameters[row, 0] += 1e-3
        table["parameters"][...] = parameters
    result = compare_cli(source, copy)
    assert result.exit_code == 1
    assert f"/continuations/k1/special_points/parameters[{row}]: K_theta = " in result.output
    assert "HB on main_down" in result.output


def test_compare_catches_flipped_stability_on_a_branch(reference_copy):
    source, copy = reference_copy
    with h5py.File(copy, "r+") as handle:
        stable = handle["continuations/k1/branches/main_down/stable"]
        flags = stable[()]
        flags[120:150] = ~flags[120:150]  # K1 ~ -0.08 .. 0.03, away from special points
        stable[...] = flags
    result = compare_cli(source, copy)
    assert result.exit_code == 1
    assert "/continuations/k1/branches/main_down/stable:" in result.output
