"""The registry of continuation types is the only list of them: the study schema's union, the
model-dependent defaults, the meaning checks, the pipeline and the cost estimate read it, and a
type added as two files (its spec, its recipe) appears in all of them."""

from __future__ import annotations

from typing import get_args

from tests.package_copy import loaded_after, run_in_a_copy
from whirl_cli.study import continuations


def test_the_schema_union_is_the_registry():
    from whirl_cli.study.schema import Continuation

    assert get_args(get_args(Continuation)[0]) == continuations.specs()
    for name, kind in continuations.registry().items():
        assert get_args(kind.spec.model_fields["type"].annotation) == (name,)
    ranks = [kind.rank for kind in continuations.registry().values()]
    assert ranks == sorted(set(ranks))  # one order, no two at one place


def test_the_registry_is_light():
    """Listing the types imports no recipe, AUTO or numerical code (``whirl validate`` reads
    them)."""
    assert loaded_after("from whirl_cli.study import continuations; continuations.registry()",
                        {"numpy", "whirl_cli.pipeline", "whirl_cli.continuation.engine"}) == []


SPEC = '''
from pydantic import Field

from ...kinds import ContinuationKind
from ...documents.values import Number, Text
from . import ContinuationSpec, ContinuationType
from typing import Literal


class ToyContinuation(ContinuationSpec):
    """A toy type."""

    type: Literal["toy"] = Field(description="`toy`")
    parameter: Text = Field(description="a parameter")
    value: Number = Field(description="a value")


def _recipe(stage, spec):
    from ...continuation.toy import toy

    return toy(stage, spec)


def _cost(spec, study):
    return 5 * int(spec.value)


def _resolved(item, names, values):
    name = item.get("parameter")
    if isinstance(name, str) and name in names.known_parameter_names():
        return {**item, "parameter": names.canonical(name)}
    return item


def _problems(loc, item, names, family, values):
    value = item.get("value")
    return [(loc + ("value",), "must be >= 0 for a toy")] if value < 0 else []


TOY = ContinuationType("toy", 30, ToyContinuation, _recipe, _cost, _resolved, _problems)
'''

RECIPE = '''
from ..results import ContinuationKind, ContinuationResult


def toy(stage, spec):
    name = f"{spec.name}:{spec.parameter}={stage.parameters[spec.parameter]:g}"
    return ContinuationResult(name, ContinuationKind.ONE_PARAMETER, (), ()), None
'''

CHECK = '''
import sys
from pathlib import Path
from types import SimpleNamespace

import whirl_cli
from whirl_cli import pipeline
from whirl_cli.errors import StudyError
from whirl_cli.study import validate_text
from whirl_cli.sweep.execute import expected_cost

TEXT = """name: t
model: classical
parameters: {K1: 1234.5}
continuations:
  - name: a
    type: toy
    parameter: K1
    value: 2
"""


class NoAuto:
    """An engine that runs nothing (the toy recipe makes no AUTO run)."""

    def __init__(self, model, workroot, **options):
        self.model = model

    def records(self):
        return ()


print("copy", Path(whirl_cli.__file__).is_relative_to(sys.argv[1]))
study = validate_text(TEXT, "t.yaml")
spec = study.continuations[0]
print("spec", type(spec).__name__, spec.parameter)
try:
    validate_text(TEXT.replace("value: 2", "value: -1"), "t.yaml")
except StudyError as error:
    print("check", str(error).splitlines()[-1])
print("cost", expected_cost(SimpleNamespace(study=study)))
pipeline.Engine = NoAuto
result = pipeline.run_study(study, Path(sys.argv[1]) / "work")
print("run", [c.name for c in result.continuations])
'''


def test_a_type_added_as_two_files_validates_and_runs(tmp_path):
    """A copy of the package with a toy type's spec and recipe dropped in: a study of it
    validates (defaults and checks its own), costs what it says and runs its recipe."""
    done = run_in_a_copy(tmp_path, {"study/continuations/toy.py": SPEC,
                                    "continuation/toy.py": RECIPE}, CHECK, str(tmp_path))
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [
        "copy True", "spec ToyContinuation K_theta",
        "check t.yaml:8: continuations[0].value: must be >= 0 for a toy",
        "cost 11", "run ['a:K_theta=1234.5']"]
