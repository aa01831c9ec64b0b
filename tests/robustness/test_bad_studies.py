"""Bad study files through the real CLI: every mutation of a valid study is refused before any
AUTO run with exit status 1, no traceback, a message naming the file, line and key path (or
one of the whole-file forms of whirl_cli/study), and no output file.

The seeds are the thesis studies (studies/thesis_ch3/*.yaml); hypothesis picks a seed, a kind
of mutation and where to apply it. The number of cases tried is printed with the test.
"""

from __future__ import annotations

import copy
import math
import re
import subprocess
import tempfile
from collections import Counter
from pathlib import Path
from typing import Any

import pytest
import yaml
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from whirl_cli import pipeline
from whirl_cli.cli import cli
from whirl_cli.study import MAX_BYTES

from .helpers import STUDIES, WHIRL, environment

SEEDS = sorted(STUDIES.glob("*.yaml"))
Path_ = tuple[str | int, ...]

# ------------------------------------------------------------------------------ the data
WRONG_TYPES: dict[type, list[Any]] = {
    float: ["ten", [1, 2], {"a": 1}, True],
    int: ["ten", [1], {"a": 1}, False, 2.5],
    str: [5, [1, 2], {"a": 1}, True],
    bool: ["yes", 1, [True]],
}
#: (key path under a study, values outside the documented range); parents are created.
OUT_OF_RANGE: list[tuple[Path_, list[Any]]] = [
    (("auto", "max_steps"), [0, -1, 2**31, 10**15]),
    (("auto", "mesh_intervals"), [1, 0, -4, 2**31]),
    (("auto", "collocation_points"), [1, 8, 100]),
    (("auto", "newton_max_iterations"), [0, -2, 2**40]),
    *[(("auto", key), [0.0, -1.0, -1e-300])
      for key in ("tolerance", "timeout", "step_initial", "step_min", "step_max",
                  "max_amplitude")],
]
#: Keys a study cannot do without, by where they live.
REQUIRED_ROOT = ("name", "model")
REQUIRED_ITEM = ("name", "type", "range", "parameter", "parameters")
PATH_LINE = re.compile(r"^(?P<file>[^:\s]+):(?P<line>\d+): (?P<path>[^:\s]+): (?P<reason>.+)$")
LINE_ONLY = re.compile(r"^(?P<file>[^:\s]+):(?P<line>\d+): (?P<reason>(YAML|a study must).+)$")
WHOLE_FILE = re.compile(r"^(?P<file>[^:\s]+): (?P<reason>not UTF-8 text|the study file is "
                        r"too large|the study file is empty).*$")


def walk(data: Any, path: Path_ = ()):
    """(path, value) of every node below the root, depth first."""
    if isinstance(data, dict):
        for key, value in data.items():
            yield path + (key,), value
            yield from walk(value, path + (key,))
    elif isinstance(data, list):
        for index, value in enumerate(data):
            yield path + (index,), value
            yield from walk(value, path + (index,))


def get(data: Any, path: Path_) -> Any:
    for part in path:
        data = data[part]
    return data


def put(data: dict, path: Path_, value: Any) -> None:
    for part in path[:-1]:
        if isinstance(data, dict) and not isinstance(data.get(part), dict | list):
            data[part] = {}
        data = data[part]
    data[path[-1]] = value


def dotted(path: Path_) -> str:
    return "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in path).lstrip(".")


def scalar_type(value: Any) -> type | None:
    if isinstance(value, bool):
        return bool
    if isinstance(value, int):
        return int
    if isinstance(value, float):
        return float
    if isinstance(value, str):
        return str
    return None


def is_range(path: Path_, value: Any) -> bool:
    return ("range" in path and isinstance(value, list) and len(value) == 2
            and all(scalar_type(v) in (int, float) for v in value))


# ------------------------------------------------------------------------------ mutations
# Each returns (file bytes, what to expect): ("path", key paths one of which must be reported
# (their prefixes count too)), ("line", reason start) or ("file", reason start).
def mutate(kind: str, data: dict, draw) -> tuple[bytes, tuple]:
    nodes = list(walk(data))
    if kind == "wrong_type":
        leaves = [(p, v) for p, v in nodes if scalar_type(v) is not None]
        path, value = draw(st.sampled_from(leaves))
        put(data, path, draw(st.sampled_from(WRONG_TYPES[scalar_type(value)])))
        return dump(data), ("path", path)
    if kind == "container_as_scalar":
        containers = [(p, v) for p, v in nodes if isinstance(v, dict | list) and v]
        path, _ = draw(st.sampled_from(containers))
        put(data, path, draw(st.sampled_from([5, "text", True])))
        return dump(data), ("path", path)
    if kind == "unknown_key":
        mappings = [()] + [p for p, v in nodes if isinstance(v, dict)]
        parent = draw(st.sampled_from(mappings))
        key = draw(st.sampled_from(["bogus", "Name", "max-steps", "K_9", "unknown_key"]))
        get(data, parent)[key] = 1.0
        return dump(data), ("path", parent + (key,))
    if kind == "missing_key":
        present = [(k,) for k in REQUIRED_ROOT if k in data]
        if isinstance(data.get("nonlinearity"), dict) and "type" in data["nonlinearity"]:
            present.append(("nonlinearity", "type"))
        for i, item in enumerate(data.get("continuations") or []):
            present += [("continuations", i, k) for k in REQUIRED_ITEM if k in item]
        for i, _ in enumerate((data.get("linear") or {}).get("sweeps") or []):
            present += [("linear", "sweeps", i, k) for k in ("parameter", "range")]
        path = draw(st.sampled_from(present))
        del get(data, path[:-1])[path[-1]]
        return dump(data), ("path", path)
    if kind == "out_of_range":
        choices = list(OUT_OF_RANGE)
        for i, _ in enumerate((data.get("linear") or {}).get("sweeps") or []):
            choices.append((("linear", "sweeps", i, "points"), [1, 0, 100001]))
        for i, item in enumerate(data.get("continuations") or []):
            if is_range((), item.get("range")):  # one-parameter
                lower, upper = item["range"]
                choices.append((("continuations", i, "start"),
                                [upper + (upper - lower), lower - 1e-3 * (upper - lower)]))
            choices.append((("continuations", i, "range"),
                            [[-1e308, 1e308], [-1.7e308, 1.7e308]]))
            if "parameter" in item:
                choices.append((("continuations", i, "orbits_at"), [[0.1] * 65, [0.0] * 500]))
                choices.append((("continuations", i, "explore"), [[0.1] * 65]))
                choices.append((("continuations", i, "explore_transient"), [0, -1.0]))
        path, values = draw(st.sampled_from(choices))
        put(data, path, draw(st.sampled_from(values)))
        return dump(data), ("path", path)
    if kind == "non_finite":
        numbers = [(p, v) for p, v in nodes if scalar_type(v) in (int, float)]
        path, _ = draw(st.sampled_from(numbers))
        put(data, path, draw(st.sampled_from([math.nan, math.inf, -math.inf])))
        return dump(data), ("path", path)
    if kind == "empty_range":
        ranges = [(p, v) for p, v in nodes if is_range(p, v)]
        path, (lower, upper) = draw(st.sampled_from(ranges))
        put(data, path, draw(st.sampled_from(
            [[], [lower], [lower, lower], [upper, lower], [lower, upper, upper], "[0, 1]"])))
        return dump(data), ("path", path)
    if kind == "unknown_name":
        choices: list[tuple[Path_, Any]] = [
            (("model",), "classicall"), (("model",), "../classical"),
            (("nonlinearity", "type"), "cubic"), (("nonlinearity", "dof"), "phi"),
            (("parameters", "K9"), 1.0), (("parameters", "k1"), 0.3),
            (("plots",), ["bifurcation", "nosuch"]), (("name",), "bad name"),
        ]
        for i, item in enumerate(data.get("continuations") or []):
            key = "parameter" if "parameter" in item else "parameters"
            value = "K_phi" if key == "parameter" else ["K_theta", "K_phi"]
            choices += [(("continuations", i, key), value),
                        (("continuations", i, "type"), "three-parameter"),
                        (("continuations", i, "name"), "-dash")]
        for i, _ in enumerate((data.get("linear") or {}).get("sweeps") or []):
            choices.append((("linear", "sweeps", i, "parameter"), "Vee"))
        path, value = draw(st.sampled_from(choices))
        if path == ("nonlinearity", "dof") and not isinstance(data.get("nonlinearity"), dict):
            data["nonlinearity"] = {"type": "linear"}
        put(data, path, value)
        return dump(data), ("path", path + ((1,) if isinstance(value, list) else ()))
    if kind == "duplicate_continuation":
        items = data["continuations"]
        k = draw(st.integers(0, len(items) - 1))
        items.append(copy.deepcopy(items[k]))
        return dump(data), ("path", ("continuations", len(items) - 1, "name"))
    if kind == "non_utf8":
        raw = dump(data)
        at = draw(st.integers(0, len(raw)))
        bad = draw(st.sampled_from([b"\xff", b"\xfe", b"\x80", b"\xc3(", b"\xed\xa0\x80",
                                    b"\xf8\x88\x80\x80\x80"]))
        return raw[:at] + bad + raw[at:], ("file", "not UTF-8 text")
    if kind == "anchor":
        text = dump(data).decode()
        text = text.replace("model: classical", "model: &m classical", 1) + "description: *m\n"
        return text.encode(), ("line", "YAML anchors and aliases are not allowed")
    if kind == "tag":
        tag = draw(st.sampled_from(["!!python/object/apply:os.system", "!!python/name:os.system",
                                    "!custom", "!!binary", "!!set", "!!timestamp"]))
        text = dump(data).decode().replace("model: ", f"model: {tag} ", 1)
        return text.encode(), ("line", f"YAML tag '{tag}' is not allowed")
    if kind == "huge":
        padding = draw(st.sampled_from(["#" + "x" * 99 + "\n", "  \n"]))
        raw = dump(data) + (padding * (MAX_BYTES // len(padding) + 2)).encode()
        return raw, ("file", "the study file is too large")
    if kind == "empty":
        raw = draw(st.sampled_from([b"", b"\n\n", b"# only a comment\n", b"---\n"]))
        return raw, ("file", "the study file is empty")
    if kind == "syntax":
        text = dump(data).decode()
        text = text.replace("model: classical", draw(st.sampled_from(
            ["model: [classical", "model: {classical", "model: 'classical", "model:\tclassical\n"
             "  - x"])), 1)
        return text.encode(), ("line", "YAML syntax error")
    raise AssertionError(kind)


KINDS = ["wrong_type", "container_as_scalar", "unknown_key", "missing_key", "out_of_range",
         "non_finite", "empty_range", "unknown_name", "duplicate_continuation", "non_utf8",
         "anchor", "tag", "huge", "empty", "syntax"]


class _Dumper(getattr(yaml, "CSafeDumper", yaml.SafeDumper)):
    def ignore_aliases(self, data: Any) -> bool:  # never write anchors unless asked to
        return True


def dump(data: dict) -> bytes:
    return yaml.dump(data, Dumper=_Dumper, sort_keys=False, allow_unicode=True,
                     default_flow_style=False).encode()


# ------------------------------------------------------------------------------ the check
def check_refused(name: str, raw: bytes, expected: tuple, output: str,
                  data: Any = None) -> None:
    """The messages ``output`` of a refused study: forms, and the expected problem."""
    assert "Traceback" not in output and "internal error" not in output, output
    lines = [line for line in output.splitlines() if line.strip()]
    assert lines, "no message"
    text_lines = raw.decode("utf-8", errors="replace").splitlines()
    parsed = []
    for line in lines:
        found = PATH_LINE.match(line) or LINE_ONLY.match(line) or WHOLE_FILE.match(line)
        assert found, f"not a file:line: path: reason message: {line!r}"
        assert found["file"] == name, line
        if "line" in found.groupdict():
            assert 1 <= int(found["line"]) <= max(1, len(text_lines) + 1), line
        parsed.append(found)
    form, what = expected
    if form == "path":
        wanted = {dotted(what[:n]) for n in range(1, len(what) + 1)}
        inside = (dotted(what) + ".", dotted(what) + "[")  # a mapping put where a number was
        hits = [m for m in parsed if m.re is PATH_LINE and (
            m["path"] in wanted or m["path"].startswith(inside))]  # may be a form of its own
        assert hits, f"expected a problem at {dotted(what)} (or a parent):\n{output}"
        # the line is the key's own line (a missing key: its parent's, not checked here)
        hit = hits[0]
        last = hit["path"].rsplit(".", 1)[-1]
        if not last.endswith("]") and "required key is missing" not in hit["reason"]:
            assert last in text_lines[int(hit["line"]) - 1], (hit.string, text_lines)
    elif form == "line":
        assert any(m.re is LINE_ONLY and m["reason"].startswith(what) for m in parsed), output
    else:
        assert any(m.re is WHOLE_FILE and m["reason"].startswith(what) for m in parsed), output


def refuse(seed: Path, raw: bytes, expected: tuple, data: Any = None) -> None:
    """``whirl run`` on ``raw`` (named like ``seed``): exit 1, the messages, no output."""
    with tempfile.TemporaryDirectory(prefix="whirl-bad-") as scratch:
        study = Path(scratch) / seed.name
        study.write_bytes(raw)
        out = Path(scratch) / "out"
        result = CliRunner().invoke(cli, ["run", str(study), "-o", str(out / "r.h5")])
        assert result.exit_code == 1, (result.exit_code, result.output, result.exception)
        assert isinstance(result.exception, SystemExit), result.exception
        check_refused(seed.name, raw, expected, result.output, data)
        assert not out.exists(), "an output was created for a refused study"


def test_mutated_studies_are_refused_before_any_run(capsys, monkeypatch):
    def accepted(study, *args, **kwargs):
        raise AssertionError(f"a mutated study was accepted:\n{study.source}")

    monkeypatch.setattr(pipeline, "run_and_draw", accepted)  # never reach AUTO (nor run_study)
    counts: Counter[str] = Counter()
    seeds = {seed: yaml.safe_load(seed.read_text()) for seed in SEEDS}

    @settings(max_examples=450, deadline=None, derandomize=True, database=None,
              suppress_health_check=list(HealthCheck))
    @given(seed=st.sampled_from(SEEDS), kind=st.sampled_from(KINDS), data=st.data())
    def check(seed: Path, kind: str, data) -> None:
        study = copy.deepcopy(seeds[seed])
        if kind == "duplicate_continuation" and not study.get("continuations"):
            kind = "unknown_key"
        if kind == "empty_range" and not any(is_range(p, v) for p, v in walk(study)):
            kind = "unknown_key"  # a study of simulations alone has no range
        raw, expected = mutate(kind, study, data.draw)
        refuse(seed, raw, expected, study)
        counts[kind] += 1

    check()
    assert set(counts) == set(KINDS), counts
    with capsys.disabled():
        print(f"\n  {sum(counts.values())} mutated studies refused by `whirl run` "
              f"({len(SEEDS)} seeds): " + ", ".join(f"{k} {n}" for k, n in sorted(counts.items())))


def test_the_console_script_refuses_bad_studies_without_traceback(tmp_path):
    """The real entry point (``main()``): message on stderr, exit 1, no output, no traceback."""
    seed = STUDIES / "hardening_case2.yaml"
    text = seed.read_text()
    cases = {
        "type.yaml": (text.replace("K2: 10.0", "K2: ten"),
                      "type.yaml:9: nonlinearity.K2: expected a number, got 'ten'"),
        "bytes.yaml": (text.encode()[:40] + b"\xff" + text.encode()[40:],
                       "bytes.yaml: not UTF-8 text (byte 0xff at offset 40)"),
        "tag.yaml": (text.replace("model: classical",
                                  "model: !!python/object/apply:os.system [touch pwned]"),
                     "tag.yaml:4: YAML tag '!!python/object/apply:os.system' is not allowed"),
    }
    processes = {}
    for name, (content, _) in cases.items():
        path = tmp_path / name
        path.write_bytes(content if isinstance(content, bytes) else content.encode())
        processes[name] = subprocess.Popen(
            [str(WHIRL), "run", str(path), "-o", str(tmp_path / "out" / f"{name}.h5")],
            cwd=tmp_path, env=environment(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
            text=True)
    for name, process in processes.items():
        stdout, stderr = process.communicate(timeout=60)
        assert process.returncode == 1, (name, stdout, stderr)
        assert stderr.startswith(cases[name][1]), (name, stderr)
        assert "Traceback" not in stdout + stderr
    assert not (tmp_path / "out").exists() and not (tmp_path / "pwned").exists()


def test_two_parameter_range_problems_name_the_key_as_written(tmp_path):
    text = (STUDIES / "boundary_linear.yaml").read_text()
    assert "K_theta: [0.0, 0.5], K_psi" in text
    path = tmp_path / "b.yaml"
    path.write_text(text.replace("K_theta: [0.0, 0.5], K_psi", "K_theta: [0.5, 0.0], K_psi"))
    result = CliRunner().invoke(cli, ["validate", str(path)])
    assert result.exit_code == 1
    assert result.output.startswith(
        "b.yaml:13: continuations[0].range.K_theta: expected [lower, upper] with lower < "
        "upper, got [0.5, 0.0]"), result.output


def test_bad_multiples_sweeps_are_refused_at_their_keys(tmp_path):
    """A sweep in multiples of a datum of 0, or with a multiple <= 0, is refused before any
    run at the key's own line (whirl run, exit 1, no output)."""
    text = (STUDIES / "linear_multiples_rotor.yaml").read_text()
    assert "{parameter: R, range: [0.25, 5.0]" in text
    line = next(k for k, row in enumerate(text.splitlines(), 1) if "parameter: R," in row)
    cases = {
        "zero.yaml": (text.replace("model: classical", "model: gimballed").replace(
            "parameter: R,", "parameter: C_beta,"), f"zero.yaml:{line}: linear.sweeps[2]."
            "multiples: the datum of C_beta is 0 N m s/rad: it has no multiples"),
        "negative.yaml": (text.replace("{parameter: R, range: [0.25, 5.0]",
                                       "{parameter: R, range: [-0.5, 5.0]"),
                          f"negative.yaml:{line}: linear.sweeps[2].range: with multiples: "
                          "true the range is in multiples of the datum of R (0.152) and must "
                          "be > 0, got -0.5"),
    }
    for name, (content, expected) in cases.items():
        path = tmp_path / name
        path.write_text(content)
        out = tmp_path / "out" / f"{name}.h5"
        result = CliRunner().invoke(cli, ["run", str(path), "-o", str(out)])
        assert result.exit_code == 1, result.output
        assert result.output.startswith(expected), result.output
        assert not out.parent.exists()


# ------------------------------------------------------------------------------ named cases
HEAD = "name: s\nmodel: classical\n"
ONE = "  - {name: %s, type: one-parameter, parameter: K1, range: [-0.3, 0.5]}\n"
PAIR = ("  - {name: b, type: two-parameter, parameters: [K1, K_psi],\n"
        "     range: {K1: [0.0, 0.5], K_psi: [0.0, 0.5]}}\n")
SIM = "  - {name: %s, initial: {theta: 1}, duration: 1}\n"
FREEPLAY = "nonlinearity: {type: freeplay, delta: 0.01}\n"
#: (study text, the first message line): stored names that would collide, AUTO steps out of
#: order, and reasons that name the value at fault.
NAMED_CASES = {
    "sweep_twice": (HEAD + "linear:\n  sweeps:\n    - {parameter: V, range: [10, 20]}\n"
                    "    - {parameter: V, range: [30, 40]}\n",
                    "s.yaml:6: linear.sweeps[1].parameter: a second sweep of V, the first is "
                    "linear.sweeps[0]"),
    "sweep_alias": (HEAD + "linear:\n  sweeps:\n    - {parameter: K1, range: [0.1, 0.5]}\n"
                    "    - {parameter: K_theta, range: [0.6, 0.9]}\n",
                    "s.yaml:6: linear.sweeps[1].parameter: a second sweep of K_theta "
                    "('K_theta' and 'K1' both name K_theta)"),
    "grid_alias": (HEAD + "linear:\n  grid:\n    x: {parameter: K1, range: [0.1, 0.5]}\n"
                   "    y: {parameter: K_theta, range: [0.1, 0.5]}\n",
                   "s.yaml:6: linear.grid.y.parameter: the same parameter as x ('K_theta' and "
                   "'K1' both name K_theta); a grid needs two different parameters"),
    "slice_run_names": (HEAD + "continuations:\n" + PAIR + ONE % "b.slice_0",
                        "s.yaml:6: continuations[1].name: 'b.slice_0' would share AUTO run "
                        "names with continuation 'b' (its runs are named b.<run>)"),
    "repetition_names": (HEAD + FREEPLAY + "continuations:\n"
                         + (ONE % "k_eps1" + ONE % "k").replace("-0.3", "0.1"),
                         "s.yaml:5: continuations[0].name: 'k_eps1' would share AUTO run names "
                         "with continuation 'k' (with a smoothed law its repetitions are named "
                         "k_eps<k>)"),
    "unnamed_simulation": (HEAD + "simulations:\n" + SIM % "sim_2" + SIM % "null",
                           "s.yaml:5: simulations[1].name: duplicate simulation name 'sim_2' "
                           "(an unnamed simulation's name, from its position)"),
    "step_initial_over_max": (HEAD + "auto: {step_initial: 0.1, step_max: 0.01}\n",
                              "s.yaml:3: auto.step_initial: must be <= step_max (0.01), got "
                              "0.1"),
    "step_min_over_max": (HEAD + "auto: {step_min: 0.1, step_max: 0.01}\n",
                          "s.yaml:3: auto.step_min: must be <= step_max (0.01), got 0.1"),
    "step_max_under_default": (HEAD + "auto: {step_max: 0.001}\n",
                               "s.yaml:3: auto.step_max: must be >= step_initial (0.002, "
                               "whirl's default), got 0.001"),
    "step_over_range": (HEAD + "auto: {step_initial: 1.5, step_max: 1}\n",
                        "s.yaml:3: auto.step_initial: must be <= 1, got 1.5"),
    "seed_nan": (HEAD + "continuations:\n" + (ONE % "k")[:-2] + ", seeds: [{theta: .nan}]}\n",
                 "s.yaml:4: continuations[0].seeds[0].theta: expected a finite number, got "
                 ".nan"),
    "initial_inf": (HEAD + "simulations:\n  - {initial: {theta: .inf}, duration: 1}\n",
                    "s.yaml:4: simulations[0].initial.theta: expected a finite number, got "
                    ".inf"),
    "range_inf": (HEAD + "continuations:\n" + (ONE % "k").replace("-0.3", "-.inf"),
                  "s.yaml:4: continuations[0].range[0]: expected a finite number, got -.inf"),
    "range_quoted": (HEAD + "continuations:\n" + (ONE % "k").replace("0.5]", "'0.5']"),
                     "s.yaml:4: continuations[0].range[1]: expected a number, got '0.5'"),
    "pair_too_short": (HEAD + "continuations:\n" + PAIR.replace("[K1, K_psi]", "[K1]"),
                       "s.yaml:4: continuations[0].parameters: expected 2 items, got ['K1']"),
}


@pytest.mark.parametrize("case", sorted(NAMED_CASES))
def test_named_bad_studies_are_refused_with_their_reason(case, tmp_path, monkeypatch):
    """Each refused before any run (``whirl run``: exit 1, no output) with the reason at the
    key at fault; before, the collisions crashed after all the work (``name already
    exists``), the steps out of order ran and returned less, and the reasons blamed the
    container ("expected a list of mappings, got a list")."""
    def accepted(study, *args, **kwargs):
        raise AssertionError(f"accepted:\n{study.source}")

    monkeypatch.setattr(pipeline, "run_and_draw", accepted)
    text, expected = NAMED_CASES[case]
    path = tmp_path / "s.yaml"
    path.write_text(text)
    out = tmp_path / "out" / "r.h5"
    result = CliRunner().invoke(cli, ["run", str(path), "-o", str(out)])
    assert result.exit_code == 1, result.output
    assert isinstance(result.exception, SystemExit), result.exception
    lines = result.output.splitlines()
    assert lines[0].startswith(expected), result.output
    assert len(lines) == 1, result.output  # one reason, no second one for the container
    assert not out.parent.exists()
