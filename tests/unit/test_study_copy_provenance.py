"""The study text and hash a result stores describe the study object that ran: a study
changed with pydantic's ``model_copy`` (or built in code) is saved as its own values, not as
the file it was first read from; an unchanged study keeps its file's text and hash."""

from __future__ import annotations

import hashlib

from whirl_cli.output.provenance import provenance
from whirl_cli.results import Provenance
from whirl_cli.study import Study, load_study, stored_study

from ..conftest import STUDIES

STUDY = STUDIES / "linear_case2.yaml"


def _stored(study: Study) -> tuple[Study, Provenance]:
    found = provenance(study)
    return stored_study(found), found


def test_a_model_copy_is_saved_with_its_own_values():
    study = load_study(STUDY)
    changed = study.model_copy(update={"parameters": {"K_psi": 0.35}})
    stored, found = _stored(changed)
    assert stored.parameters == {"K_psi": 0.35}
    assert stored.parameter_values() == changed.parameter_values()
    assert stored.model_dump() == changed.model_dump()
    text = found.study_yaml
    assert found.study_sha256 == hashlib.sha256(text.encode()).hexdigest()
    assert found.study_sha256 != study.sha256


def test_a_changed_continuation_is_saved_too():
    study = load_study(STUDY)
    first = study.continuations[0].model_copy(update={"range": (-0.2, 0.5)})
    changed = study.model_copy(update={"continuations": (first,)})
    stored, _ = _stored(changed)
    assert stored.continuations[0].range == (-0.2, 0.5)


def test_an_unchanged_study_keeps_its_file_text_and_hash():
    study = load_study(STUDY)
    text = STUDY.read_text()
    for same in (study, study.model_copy(), study.model_copy(deep=True)):
        found = provenance(same)
        assert found.study_yaml == text
        assert found.study_sha256 == hashlib.sha256(text.encode()).hexdigest()


def test_a_study_built_in_code_is_saved_as_its_values():
    data = load_study(STUDY).model_dump(mode="json", exclude_defaults=True)
    built = Study.model_validate(data)
    stored, _ = _stored(built)
    assert stored.model_dump() == built.model_dump()
