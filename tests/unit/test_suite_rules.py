"""Rules the test suite keeps about itself: shared helpers live in conftest.py or in helper
modules, never in a test module another one imports; no assertion on an elapsed time."""

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


CLOCKS = {"perf_counter", "monotonic", "time", "perf_counter_ns", "monotonic_ns", "time_ns"}


def _reads_a_clock(node: ast.AST) -> bool:
    return any(isinstance(call, ast.Call) and isinstance(call.func, ast.Attribute)
               and call.func.attr in CLOCKS and isinstance(call.func.value, ast.Name)
               and call.func.value.id == "time" for call in ast.walk(node))


def elapsed_time_asserts(path: Path) -> list[int]:
    """Lines of ``assert`` statements that read a name assigned a difference of clock readings
    (``seconds = time.monotonic() - started``) in the same function."""
    found = []
    for function in ast.walk(ast.parse(path.read_text(), str(path))):
        if not isinstance(function, ast.FunctionDef | ast.AsyncFunctionDef):
            continue
        elapsed = {target.id for node in ast.walk(function) if isinstance(node, ast.Assign)
                   and isinstance(node.value, ast.BinOp) and isinstance(node.value.op, ast.Sub)
                   and _reads_a_clock(node.value)
                   for target in node.targets if isinstance(target, ast.Name)}
        found += [node.lineno for node in ast.walk(function) if isinstance(node, ast.Assert)
                  and any(isinstance(name, ast.Name) and name.id in elapsed
                          for name in ast.walk(node))]
    return sorted(found)


def test_no_assertion_on_an_elapsed_time():
    """A count, an order or a state is asserted instead; a clock only bounds a wait against a
    hang (``deadline = time.monotonic() + 120``)."""
    offending = [f"{path.relative_to(TESTS)}:{line}" for path in sorted(TESTS.rglob("*.py"))
                 for line in elapsed_time_asserts(path)]
    assert offending == []


def test_the_elapsed_time_rule_sees_an_assert_on_a_clock_difference(tmp_path):
    source = tmp_path / "mod.py"
    source.write_text("import time\n\ndef f():\n    started = time.perf_counter()\n"
                      "    seconds = time.perf_counter() - started\n    assert seconds < 60\n"
                      "    deadline = time.monotonic() + 5\n"
                      "    assert time.monotonic() < deadline\n")
    assert elapsed_time_asserts(source) == [6]


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
