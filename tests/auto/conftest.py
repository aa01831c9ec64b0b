"""Fixtures that run real AUTO-07p studies once per test session."""

from __future__ import annotations

from pathlib import Path

import pytest

from whirl_cli.pipeline import run_study
from whirl_cli.study import load_study

from ..conftest import STUDIES


@pytest.fixture(scope="session")
def run_thesis(tmp_path_factory):
    """run_thesis("hardening_case2") -> StudyResult of studies/thesis_ch3/<name>.yaml."""
    cache: dict[str, object] = {}

    def run(name: str):
        if name not in cache:
            study = load_study(STUDIES / f"{name}.yaml")
            cache[name] = run_study(study, Path(tmp_path_factory.mktemp(name)), jobs=2)
        return cache[name]

    return run
