"""Rules the test suite keeps about itself: shared helpers live in conftest.py or in helper
modules, never in a test module another one imports."""

from __future__ import annotations

import ast
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]


def imported_modules(path: Path) -> list[tuple[int, str]]:
    """(line, last dotted component) of every module an ``import`` or ``from`` statement of
    ``path`` names, ``from . import x`` counting ``x`` as the module."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name.rsplit(".", 1)[-1]) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.module:
                found.append((node.lineno, node.module.rsplit(".", 1)[-1]))
            else:
                found += [(node.lineno, alias.name) for alias in node.names]
    return found


def test_no_test_module_imports_another():
    test_modules = {path.stem for path in TESTS.rglob("test_*.py")}
    offending = [f"{path.relative_to(TESTS)}:{line}: imports {name}"
                 for path in sorted(TESTS.rglob("*.py"))
                 for line, name in imported_modules(path) if name in test_modules]
    assert offending == []


def test_the_rule_sees_each_import_form(tmp_path):
    source = tmp_path / "mod.py"
    source.write_text("import tests.unit.test_a\nfrom .test_b import x\n"
                      "from ..unit.test_c import y\nfrom . import test_d\nfrom .helpers import z\n")
    assert [name for _, name in imported_modules(source)] == [
        "test_a", "test_b", "test_c", "test_d", "helpers"]
