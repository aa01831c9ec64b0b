"""A stiffness law's coefficients make its block of the study schema: a new smooth law is one
module in whirl_cli/models/laws/, and studies, the schema reference and the model read it."""

from __future__ import annotations

from tests.package_copy import run_in_a_copy
from whirl_cli.models.laws import LAWS
from whirl_cli.study.schema import LAW_BLOCKS


def test_each_law_block_has_the_keys_of_its_laws_coefficients():
    assert list(LAW_BLOCKS) == list(LAWS)
    for name, law in LAWS.items():
        fields = LAW_BLOCKS[name].model_fields
        stiffness = [law.stiffness_key] if law.stiffness_key else []
        assert set(fields) == {"type", "dof", *stiffness, *(c.key for c in law.coefficients)}
        for coefficient in law.coefficients:
            field = fields[coefficient.key]
            assert field.is_required() == coefficient.required
            assert coefficient.doc in field.description
            if not coefficient.required and not coefficient.unset:
                assert field.default == coefficient.default


TOY = '''
from .base import Coefficient, Law


def _moment(x, k, c):
    return k * x + c["K7"] * x**7


TOY = Law("septic", "sep", "M(x) = K x + K7 x^7",
          (Coefficient("K7", 0.0, 7, "septic coefficient", doc="Septic coefficient"),
           Coefficient("width", 0.5, 0, "width", doc="Width of the toy", required=True)),
          _moment, lambda values: values.get("K7", 0.0) == 0.0,
          study_doc="restoring force K x + K7 x^7")
'''

CHECK = '''
from whirl_cli.errors import StudyError
from whirl_cli.study import schema_reference, validate_text

study = validate_text("name: t\\nmodel: classical\\n"
                      "nonlinearity: {type: septic, width: 0.1, K7: 3}\\n", "t.yaml")
print(sorted((k, v) for k, v in study.parameter_values().items() if k.endswith("_theta")))
rows = [line.split(" | ")[0] for line in schema_reference().splitlines()]
print([row for row in rows if row.startswith("| `nonlinearity[].")][-2:])
try:
    validate_text("name: t\\nmodel: classical\\nnonlinearity: {type: septic, K7: x}\\n", "t.yaml")
except StudyError as error:
    print(error)
'''


def test_a_smooth_law_added_as_one_module_is_read_from_studies(tmp_path):
    done = run_in_a_copy(tmp_path, {"models/laws/septic.py": TOY}, CHECK)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [
        "[('K7_theta', 3.0), ('width_theta', 0.1)]",
        "['| `nonlinearity[].width`', '| `nonlinearity[].K7`']",
        "t.yaml:3: nonlinearity.K7: expected a number, got 'x'",
        "t.yaml:3: nonlinearity.width: required key is missing"]
