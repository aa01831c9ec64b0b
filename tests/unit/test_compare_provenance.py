"""``whirl compare`` and the study text: a study that differs only by a comment gives results
that agree (the text and hash differences are printed as notes, exit 0); ``--strict`` counts
them as drift (exit 1). Study name and model are what was computed: always drift."""

from __future__ import annotations

import hashlib
import shutil

import h5py
from click.testing import CliRunner

from whirl_cli.cli import cli
from whirl_cli.output.compare import compare, compare_results

from ..conftest import ROOT
from .compare_data import make_result

REFERENCE = ROOT / "tests" / "regression" / "references" / "hardening_case2.h5"


def commented_copy(tmp_path):
    """The reference with a comment added to its study text (and the hash to match)."""
    copy = tmp_path / "commented.h5"
    shutil.copyfile(REFERENCE, copy)
    with h5py.File(copy, "r+") as handle:
        text = handle.attrs["study_yaml"]
        text = text.decode() if isinstance(text, bytes) else str(text)
        lines = text.splitlines(keepends=True)
        lines.insert(1, "# rerun for the review\n")
        text = "".join(lines)
        handle.attrs["study_yaml"] = text
        handle.attrs["study_sha256"] = hashlib.sha256(text.encode()).hexdigest()
    return copy, lines[1].rstrip("\n")


def test_a_comment_in_the_study_is_a_note_not_drift(tmp_path):
    copy, comment = commented_copy(tmp_path)
    found = compare(REFERENCE, copy)
    assert found.differences == []
    assert sorted(n.path for n in found.notes) == ["/@study_sha256", "/@study_yaml"]
    (text,) = [n for n in found.notes if n.path == "/@study_yaml"]
    assert text.b == f"line 2: {comment!r}" and text.a.startswith("line 2: ")

    result = CliRunner().invoke(cli, ["compare", str(REFERENCE), str(copy)])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert lines[-1] == f"{REFERENCE} and {copy} agree"
    assert sorted(line.split(":")[0:2] for line in lines[:-1]) == [
        ["note", " /@study_sha256"], ["note", " /@study_yaml"]]
    assert all(line.endswith("(provenance, not drift; --strict counts it)")
               for line in lines[:-1])


def test_strict_counts_the_study_text_as_drift(tmp_path):
    copy, comment = commented_copy(tmp_path)
    found = compare(REFERENCE, copy, strict=True)
    assert sorted(d.path for d in found.differences) == ["/@study_sha256", "/@study_yaml"]
    assert found.notes == []
    result = CliRunner().invoke(cli, ["compare", str(REFERENCE), str(copy), "--strict"])
    assert result.exit_code == 1
    assert "/@study_yaml: line 2: " in result.output and repr(comment) in result.output
    assert "differ (2 difference(s))" in result.output and "note:" not in result.output


def test_identical_files_have_no_notes():
    found = compare(REFERENCE, REFERENCE)
    assert found.differences == [] and found.notes == []


def test_study_name_and_model_are_drift_in_both_modes():
    base = make_result()
    other = make_result(study_name="y", model="other")
    for strict in (False, True):
        paths = sorted(d.path for d in compare_results(base, other, strict=strict))
        assert paths == ["/@model", "/@study_name"]
    # an attribute whirl does not know is not provenance either
    unknown = make_result()
    unknown.attributes["extra"] = "1"
    assert [d.path for d in compare_results(base, unknown)] == ["/@extra"]
