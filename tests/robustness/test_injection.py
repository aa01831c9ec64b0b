"""Nothing from a study file reaches Fortran or a shell unchecked, and output goes only where
it is asked to go.

* names in a study (parameters, models, continuations, the study) must be declared symbols or
  plain names: injection strings are refused by validation, before anything runs;
* the generated Fortran of every variant holds only numbers, keywords and intrinsics, and the
  names the model declares (states, parameters, temporaries) or AUTO's routines and arguments;
* the AUTO constants writer refuses keys and strings that could break its line format;
* subprocesses are started from argument lists: no ``shell=True``, ``os.system`` or
  ``os.popen`` anywhere in the package;
* ``-o ../../x.h5`` writes exactly there (relative to the current directory), nothing else.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import h5py
import pytest
import yaml
from click.testing import CliRunner

from whirl_cli.auto import codegen
from whirl_cli.auto.constants import START_FILE, constants_text
from whirl_cli.cli import cli
from whirl_cli.errors import CodegenError
from whirl_cli.models import all_variants, get_model, load_model_file
from whirl_cli.output import store

from .helpers import ROOT, STUDIES

INJECTIONS = [
    "; rm -rf victim",
    "$(touch pwned)",
    "`touch pwned`",
    "K1 = 0\nCALL EXIT",
    "K1\n  CALL EXECUTE_COMMAND_LINE('touch pwned')",
    "K1'",
    'K1"',
    "K1', 'K2",
    "../../etc/passwd",
    "K1\x00",
    "K1 ",
    "\u039a1",  # Greek capital kappa + 1, looks like K1
    "PAR(1)",
    "",
]

#: Study text with one slot to fill; the expected problem's key path.
SLOTS = {
    "parameters": ("parameters: {{{value}: 0.3}}\n", "parameters."),
    "continuation parameter": ("continuations:\n  - {{name: k1, type: one-parameter, "
                               "parameter: {value}, range: [-0.3, 0.5]}}\n",
                               "continuations[0].parameter"),
    "continuation name": ("continuations:\n  - {{name: {value}, type: one-parameter, "
                          "parameter: K1, range: [-0.3, 0.5]}}\n", "continuations[0].name"),
    "sweep parameter": ("linear:\n  sweeps:\n    - {{parameter: {value}, range: [0, 1]}}\n",
                        "linear.sweeps[0].parameter"),
    "dof": ("nonlinearity: {{type: polynomial, dof: {value}}}\n", "nonlinearity.dof"),
}


def quoted(value: str) -> str:
    """``value`` as a YAML double-quoted scalar (escapes for control characters)."""
    return yaml.safe_dump(value, default_style='"', allow_unicode=False).strip().removesuffix(
        "\n...")


def study_text(slot: str, value: str) -> str:
    head = "name: {name}\nmodel: {model}\n"
    if slot == "study name":
        return head.format(name=quoted(value), model="classical")
    if slot == "model":
        return head.format(name="s", model=quoted(value))
    template, _ = SLOTS[slot]
    return head.format(name="s", model="classical") + template.format(value=quoted(value))


def expected_path(slot: str, value: str) -> str:
    if slot == "study name":
        return "name"
    if slot == "model":
        return "model"
    path = SLOTS[slot][1]
    return path + value if path.endswith(".") else path


@pytest.mark.parametrize("slot", ["study name", "model", *SLOTS])
def test_injection_strings_are_refused_by_validation(slot, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "victim").write_text("still here")
    for value in INJECTIONS:
        if slot == "parameters" and value in ("K_theta", ""):
            continue
        study = tmp_path / "s.yaml"
        study.write_text(study_text(slot, value))
        result = CliRunner().invoke(cli, ["run", str(study), "-o", "out.h5"])
        assert result.exit_code == 1, (slot, value, result.output)
        assert isinstance(result.exception, SystemExit)
        first = result.output.splitlines()[0]
        if slot == "parameters":  # the key itself is the unknown name
            assert first.startswith("s.yaml:3: parameters"), (value, result.output)
        else:
            assert re.match(rf"s\.yaml:\d+: {re.escape(expected_path(slot, value))}: ",
                            first), (slot, value, result.output)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml", "victim"]
    assert (tmp_path / "victim").read_text() == "still here"


# ------------------------------------------------------------------------------ Fortran
FORTRAN_WORDS = {
    # statements and attributes the generator writes
    "subroutine", "end", "implicit", "none", "integer", "intent", "in", "out", "inout",
    "double", "precision", "external", "if", "return", "do",
    # STPNT's reading of a starting state (whirl_start.txt): numbers into U only
    "logical", "inquire", "file", "exist", "then", "open", "newunit", "status", "action",
    "read", "close",
    # intrinsics sympy's fcode may emit for these models
    "sqrt", "asinh", "max", "min", "abs", "exp", "log", "sin", "cos", "tan", "sinh", "cosh",
    "tanh", "atan", "atan2", "asin", "acos", "sign",
}
AUTO_NAMES = {
    # AUTO-07p's user routines, their arguments, and GETP (PVLS)
    "func", "stpnt", "pvls", "bcnd", "icnd", "fopt", "getp",
    "ndim", "u", "icp", "par", "ijac", "f", "dfdu", "dfdp", "t",
}
#: The fixed WHIRL_SOLVE routine of a full mass matrix (codegen's text, not the model's): its
#: name, arguments, locals and the intrinsics it calls.
SOLVER_NAMES = {"whirl_solve", "k", "nb", "wm", "b", "a", "row", "brow", "factor", "i", "j",
                "p", "maxloc", "abs", "matmul", "intent", "in", "inout", "then"}
#: The one call generated code makes (other CALLs are flagged).
_SOLVER_CALL = re.compile(r"\bCALL WHIRL_SOLVE\(", re.IGNORECASE)
_NUMBER = re.compile(r"(?<![A-Za-z0-9_])(?:\d+\.\d*|\.\d+|\d+)(?:[dDeE][+-]?\d+)?")
_STRING = re.compile(r"'[^']*'")
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def code_and_strings(source: str) -> tuple[list[str], list[str]]:
    """Lines of code (comments and string literals removed) and the string literals."""
    code, strings = [], []
    for line in source.splitlines():
        strings += _STRING.findall(line)
        line = _STRING.sub("''", line)
        code.append(line.split("!", 1)[0])
    return code, strings


def undeclared(source: str, model) -> set[str]:
    """Identifiers in the code of ``source`` that are not Fortran words, AUTO's routine and
    argument names, or names declared in it (the model's states and parameters, temporaries)."""
    code, strings = code_and_strings(source)
    # GETP's, and STPNT's start file (READ of numbers only, into U)
    assert set(strings) <= {"'MAX'", "'MIN'", f"'{START_FILE}'", "'OLD'", "'READ'"}, strings
    declared = set()
    for line in code:
        if line.strip().upper().startswith(("DOUBLE PRECISION ::", "INTEGER ::",
                                            "LOGICAL ::")):
            listed = re.sub(r"\([^)]*\)", "", line.split("::", 1)[1])  # drop array shapes
            declared |= {n.strip().lower() for n in listed.split(",")}
    names = {n.lower() for n in model.state_names + model.parameter_names}
    assert names <= declared
    temporaries = declared - names
    # mass matrix, right-hand sides, loop index; STPNT's start file: whether given, its unit
    work = {"wm", "wa", "wj", "wp", "i", "given", "unitno"}
    assert all(re.fullmatch(r"w_[fupmxyz]\d+", n) or n in work | SOLVER_NAMES
               for n in temporaries), temporaries
    code = [_SOLVER_CALL.sub("(", line) for line in code]
    return {word for line in code for word in _IDENTIFIER.findall(_NUMBER.sub(" ", line))
            if word.lower() not in FORTRAN_WORDS | AUTO_NAMES | declared | SOLVER_NAMES}


def first_order_models():
    """Model files with first-order states (tests/data): the mixed and the pure case."""
    data = Path(__file__).resolve().parents[1] / "data"
    return [get_model(load_model_file(data / name)) for name in
            ("lagged_spring.model.yaml", "lorenz.model.yaml")]


@pytest.mark.parametrize("model", all_variants() + first_order_models(), ids=lambda m: m.name)
def test_generated_fortran_holds_only_numbers_and_declared_names(model):
    source = codegen.fortran_source(model)
    assert undeclared(source, model) == set()
    # the scan would see injected code (after a statement, not in a comment)
    injected = source.replace("  IF (IJAC == 0) RETURN",
                              "  CALL EXECUTE_COMMAND_LINE('x') ! x\n  IF (IJAC == 0) RETURN")
    with pytest.raises(AssertionError):
        undeclared(injected, model)
    name = model.parameter_names[0]  # declared: only the call is new
    assert undeclared(source.replace("IF (IJAC == 0) RETURN", f"{name} = 0; CALL EXIT"),
                      model) == {"CALL", "EXIT"}


def test_generated_fortran_refuses_line_breaks_and_non_finite_numbers():
    model = all_variants()[0]
    from dataclasses import replace

    with pytest.raises(CodegenError, match="line break"):
        family = replace(model.family, description="ok\nCALL EXIT")
        codegen.fortran_source(replace(model, family=family))
    for value in (float("nan"), float("inf"), -float("inf")):
        with pytest.raises(CodegenError, match="Fortran number"):
            codegen.fortran_number(value)


@pytest.mark.parametrize("constants", [
    {"NDIM = 3\nNMX": 1},
    {"e x": "classical"},
    {"": 1},
    {"sv": "run'\nNDIM = 3"},
    {"sv": 'run"'},
    {"sv": "run\rNDIM"},
    {"parnames": {1: "K1\nNDIM"}},
    {"unames": {1: "th\u00e9ta"}},
    {"PAR": {"K1'": 0.5}},
])
def test_constants_writer_refuses_what_could_break_a_line(constants):
    with pytest.raises(CodegenError):
        constants_text(constants)


# ------------------------------------------------------------------------------ shells
def test_no_shell_anywhere_in_the_package():
    package = ROOT / "whirl_cli"
    offenders = []
    for path in sorted(package.rglob("*.py")):
        tree = ast.parse(path.read_text(), str(path))
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            name = ast.unparse(node.func)
            if name in ("os.system", "os.popen", "subprocess.getoutput",
                        "subprocess.getstatusoutput", "system", "popen"):
                offenders.append(f"{path.name}:{node.lineno}: {name}")
            for keyword in node.keywords:
                if keyword.arg == "shell" and not (isinstance(keyword.value, ast.Constant)
                                                   and keyword.value.value is False):
                    offenders.append(f"{path.name}:{node.lineno}: shell=")
            if name.split(".")[-1] in ("run", "Popen", "call", "check_call", "check_output") \
                    and name.startswith("subprocess") and node.args:
                if isinstance(node.args[0], ast.Constant | ast.JoinedStr | ast.BinOp):
                    offenders.append(f"{path.name}:{node.lineno}: a command string")
    assert not offenders, offenders
    text = "\n".join(p.read_text() for p in package.rglob("*.py"))
    assert "shell=True" not in text and "os.system(" not in text


# ------------------------------------------------------------------------------ paths
@pytest.mark.auto
def test_output_path_with_dot_dot_writes_exactly_where_asked(tmp_path, monkeypatch):
    """``-o ../../x.h5`` is the user's own path on the command line: written there, relative to
    the current directory, and nowhere else (YAML names cannot contain a path separator)."""
    cwd = tmp_path / "a" / "b"
    cwd.mkdir(parents=True)
    monkeypatch.chdir(cwd)
    study = Path("../../s.yaml")
    (tmp_path / "s.yaml").write_text((STUDIES / "linear_datum_airspeed.yaml").read_text())
    result = CliRunner().invoke(cli, ["run", str(study), "-o", "../../x.h5"])
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "a", "s.yaml", "x.h5", "x_airspeed_bifurcation.png", "x_linear_V.png"]
    assert list(cwd.iterdir()) == [] and [p.name for p in (tmp_path / "a").iterdir()] == ["b"]
    with h5py.File(tmp_path / "x.h5") as handle:
        assert handle.attrs["whirl_schema"] == store.SCHEMA
    # a directory that does not exist yet is created; a file in the way is a clear error
    (tmp_path / "file").write_text("")
    blocked = CliRunner().invoke(cli, ["run", str(study), "-o", "../../file/x.h5"])
    assert blocked.exit_code == 1 and isinstance(blocked.exception, SystemExit)
    assert "cannot create the output directory" in blocked.output
