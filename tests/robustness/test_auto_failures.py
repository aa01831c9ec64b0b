"""AUTO failure modes at the study level, on the real solver: a study whose one continuation
fails still writes its HDF5 file, with the failed runs and branches marked (status, message)
and the other continuations intact, and ``whirl run`` exits 1 naming the failed runs.

Provoked with real study settings where one exists: no convergence (MX) and a hanging run
(timeout) from too tight a Newton tolerance on the secondary branches, NaN from a continuation
that starts at zero inertia. A crash needs constants no study can write (a wrong NDIM): the
fixture extra_auto_constants (tests/conftest.py) provides them. Missing gfortran
or AUTO-07p are run through the console script with a stripped environment.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import h5py
import pytest
from click.testing import CliRunner

from whirl_cli.cli import cli
from whirl_cli.output import store

from .helpers import WHIRL, environment

pytestmark = pytest.mark.auto

HEAD = """name: failing
model: classical
parameters: {K_psi: 0.3}
"""
#: The good continuation: the main branch only (no branch switching).
GOOD = """  - {name: good, type: one-parameter, parameter: K1, start: 0.5, range: [-0.3, 0.5],
     branch_points: false}
"""


def run(tmp_path: Path, body: str, *options: str):
    """``whirl run`` (in process) on HEAD + ``body``; (result, HDF5 path)."""
    study = tmp_path / "failing.yaml"
    study.write_text(HEAD + body)
    output = tmp_path / "out" / "failing.h5"
    result = CliRunner().invoke(cli, ["run", str(study), "-o", str(output), *options])
    return result, output


def check_stored(output: Path, failed: dict[str, tuple[str, str]], good: str = "good") -> None:
    """``failed``: run name -> (status, message part). The run records and branches of those
    runs carry them; every other run and branch is ok, and the good continuation has points."""
    with h5py.File(output) as handle:
        assert handle.attrs["whirl_schema"] == store.SCHEMA
        runs = {name: dict(group.attrs) for name, group in handle["runs"].items()}
        assert set(failed) <= set(runs), runs.keys()
        for name, attrs in runs.items():
            status, message = failed.get(name, ("ok", "ok"))
            assert attrs["status"] == status, (name, attrs)
            assert message in attrs["message"], (name, attrs)
        for group in handle["continuations"].values():
            for branch_name, branch in group["branches"].items():
                run_name = branch.attrs["run"].rsplit("+", 1)[-1]
                status, message = failed.get(run_name, ("ok", ""))
                if branch.attrs["kind"] == "equilibrium":
                    assert branch.attrs["status"] == status, (branch_name, dict(branch.attrs))
                    assert message in branch.attrs["message"]
                    if status in ("error", "crashed"):  # no output: an empty branch
                        assert len(branch["point_type"]) == 0
        main = handle[f"continuations/{good}/branches/main_down"]
        assert main.attrs["status"] == "ok" and len(main["point_type"]) > 50
        assert 3 in main["point_type"][()]  # its Hopf points are there


def check_exit(result, failed: dict[str, tuple[str, str]]) -> None:
    assert result.exit_code == 1, result.output
    assert isinstance(result.exception, SystemExit)
    assert "Traceback" not in result.output and "internal error" not in result.output
    problems = result.output.strip().splitlines()[-1]
    assert problems.startswith(f"{len(failed)} problem(s); the results are stored")
    for name in failed:
        assert f"({name})" in problems, (name, problems)


def test_no_convergence_mx_is_stored_and_reported(tmp_path):
    """Newton tolerance 1e-17: the main branches converge (the trivial equilibrium is exact),
    the secondary (deflected) branches end in MX."""
    body = ("nonlinearity: {type: polynomial, K2: 10.0}\ncontinuations:\n" + GOOD
            + "  - {name: bad, type: one-parameter, parameter: K1, start: 0.5, "
              "range: [-0.3, 0.5]}\nauto: {tolerance: 1.0e-17}\nplots: []\n")
    result, output = run(tmp_path, body)
    failed = {f"bad.secondary_1{x}": ("mx", "no convergence with the minimum step size (MX)")
              for x in "ab"}
    check_exit(result, failed)
    check_stored(output, failed)
    with h5py.File(output) as handle:
        secondary = handle["continuations/bad/branches/secondary_1a"]
        assert len(secondary["point_type"]) > 10 and secondary["point_type"][-1] == -9  # MX
        assert handle["continuations/bad/branches/main_down"].attrs["status"] == "ok"


def test_a_hanging_run_times_out_and_keeps_its_points(tmp_path):
    """Tolerance 1e-15 with at most 2 Newton iterations: AUTO loops on the secondary branches
    (a real AUTO behaviour); ``auto.timeout`` ends each after 1 s, keeping what it wrote."""
    body = ("nonlinearity: {type: polynomial, K2: 10.0}\ncontinuations:\n" + GOOD
            + "  - {name: bad, type: one-parameter, parameter: K1, start: 0.5, "
              "range: [-0.3, 0.5]}\n"
              "auto: {tolerance: 1.0e-15, newton_max_iterations: 2, timeout: 1}\nplots: []\n")
    result, output = run(tmp_path, body, "--jobs", "2")
    failed = {f"bad.secondary_1{x}": ("timeout", "AUTO did not finish within 1 s") for x in "ab"}
    check_exit(result, failed)
    check_stored(output, failed)
    with h5py.File(output) as handle:
        run_record = handle["runs/bad.secondary_1a"].attrs
        assert run_record["returncode"] == -1  # killed by whirl, not ended by AUTO
        assert run_record["wall_seconds"] >= 1.0  # and not before its time was up


def test_nan_from_the_equations_is_an_error_with_an_empty_branch(tmp_path,
                                                                 extra_auto_constants):
    """The inertia I_y set to 0 in one run (extra_auto_constants; a study cannot ask for it, I_y > 0
    is its bound): 1/I_y is infinite, LAPACK refuses the Jacobian. The failed branch is stored
    empty, and the plots still work."""
    extra_auto_constants({"bad.main_up": {"PAR": {"I_y": 0.0}}})
    body = ("continuations:\n" + GOOD
            + "  - {name: bad, type: one-parameter, parameter: V, start: 0.0, "
              "range: [0.0, 10.0]}\nplots: [bifurcation]\n")
    result, output = run(tmp_path, body)
    failed = {"bad.main_up": ("error", "NaN or Inf in the equations")}
    check_exit(result, failed)
    check_stored(output, failed)
    with h5py.File(output) as handle:
        branch = handle["continuations/bad/branches/main_up"]
        assert branch["parameters"].shape == (0, 1) and branch["state_max"].shape == (0, 4)
        assert branch["parameters"].attrs["names"].tolist() == ["V"]
    assert (output.parent / "failing_good_bifurcation.png").exists()


def test_a_crash_is_stored_and_no_stale_fort2_leaks_into_later_runs(tmp_path,
                                                                    extra_auto_constants):
    """NDIM = 3 (a test fixture) makes AUTO crash with SIGSEGV on bad.main_up. The runs after it
    (the secondary branches of the same continuation) get fresh directories and their own
    constants; no fort.2 is left anywhere, nor taken from the --keep-runs directory."""
    extra_auto_constants({"bad.main_up": {"NDIM": 3}})
    keep = tmp_path / "keep"
    keep.mkdir()
    (keep / "fort.2").write_text("NDIM = 3\nIPS = 99\n")  # stale, must never be read
    body = ("continuations:\n" + GOOD
            + "  - {name: bad, type: one-parameter, parameter: K1, start: 0.1, "
              "range: [-0.3, 0.5]}\nplots: []\n")
    result, output = run(tmp_path, body, "--keep-runs", str(keep))
    failed = {"bad.main_up": ("crashed", "AUTO crashed with SIGSEGV")}
    check_exit(result, failed)
    check_stored(output, failed)
    with h5py.File(output) as handle:
        assert handle["runs/bad.main_up"].attrs["returncode"] in (-11, 139)
        assert "NDIM = 3" in handle["runs/bad.main_up"].attrs["constants"]
        records = {name: group.attrs["constants"] for name, group in handle["runs"].items()}
    assert {"bad.main_down", "bad.secondary_1a", "bad.secondary_1b"} <= set(records)
    (workroot,) = [p for p in keep.iterdir() if p.is_dir()]
    assert not list(workroot.rglob("fort.2"))
    for name, constants in records.items():
        continuation, branch = name.split(".", 1)
        (constants_file,) = (workroot / continuation / branch).glob("c.*")
        assert constants_file.name == f"c.{name}"
        assert constants_file.read_text() == constants
        if name != "bad.main_up":
            assert "NDIM = 4" in constants and "NDIM = 3" not in constants
    assert (keep / "fort.2").read_text() == "NDIM = 3\nIPS = 99\n"


@pytest.mark.parametrize("broken", ["gfortran", "auto"])
def test_missing_gfortran_or_auto_is_a_clear_message(broken, tmp_path):
    """Console script with an empty compile cache and either no gfortran on PATH or
    WHIRL_AUTO_DIR pointing at an empty directory: exit 1, what is missing and how to install
    it, no output file, no traceback; `whirl doctor` says the same."""
    empty = tmp_path / "empty"
    (empty / "bin").mkdir(parents=True)
    cache = tmp_path / "cache"
    extra = {"PATH": str(empty / "bin")} if broken == "gfortran" else {
        "WHIRL_AUTO_DIR": str(empty), "WHIRL_AUTO_ENGINE": "debian"}
    env = environment(cache, **extra)
    study = Path(__file__).parents[2] / "studies" / "thesis_ch3" / "linear_case2.yaml"
    output = tmp_path / "out" / "r.h5"
    commands = {"run": [str(WHIRL), "run", str(study), "-o", str(output)],
                "doctor": [str(WHIRL), "doctor"]}
    processes = {k: subprocess.Popen(c, env=env, cwd=tmp_path, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True)
                 for k, c in commands.items()}
    expected = ("gfortran (needed to compile AUTO equation files) is not installed"
                if broken == "gfortran" else
                f"AUTO-07p runtime objects not found in {empty / 'lib'}")
    for name, process in processes.items():
        stdout, stderr = process.communicate(timeout=120)
        assert process.returncode == 1, (name, stdout, stderr)
        assert expected in stderr, (name, stderr)
        assert "sudo apt-get install auto-07p gfortran" in stderr
        assert "Traceback" not in stdout + stderr
    assert not output.exists() and not list((tmp_path / "out").glob("*"))
    assert not list(cache.rglob("*.exe"))


@pytest.mark.parametrize("case", ["unknown", "bifpy_broken"])
def test_unavailable_engine_is_a_clear_message(case, tmp_path):
    """WHIRL_AUTO_ENGINE naming no engine, or bifpy installed without its AUTO build (a package
    ``bifpy`` without ``auto/_lib``, found first on PYTHONPATH): `whirl run` and `whirl doctor`
    exit 1 with what is wrong and how to fix it, no output file, no traceback."""
    cache = tmp_path / "cache"
    if case == "unknown":
        extra = {"WHIRL_AUTO_ENGINE": "cygwin"}
        expected = ("WHIRL_AUTO_ENGINE='cygwin' is not an AUTO engine; choose one of: "
                    "debian, bifpy")
    else:
        shadow = tmp_path / "shadow" / "bifpy"
        shadow.mkdir(parents=True)
        (shadow / "__init__.py").write_text("")
        extra = {"WHIRL_AUTO_ENGINE": "bifpy", "PYTHONPATH": str(shadow.parent)}
        expected = (f"WHIRL_AUTO_ENGINE=bifpy: main.o, libbifpy.a not found in "
                    f"{shadow / 'auto' / '_lib'}")
    env = environment(cache, **extra)
    study = Path(__file__).parents[2] / "studies" / "thesis_ch3" / "linear_case2.yaml"
    output = tmp_path / "out" / "r.h5"
    for command in ([str(WHIRL), "run", str(study), "-o", str(output)], [str(WHIRL), "doctor"]):
        done = subprocess.run(command, env=env, cwd=tmp_path, capture_output=True, text=True,
                              timeout=120, check=False)
        assert done.returncode == 1, (command, done.stdout, done.stderr)
        assert expected in done.stderr, done.stderr
        if case == "bifpy_broken":
            assert "pip install" in done.stderr and "make setup" in done.stderr
        assert "Traceback" not in done.stdout + done.stderr
    assert not output.exists()
    assert not list(cache.rglob("*.exe"))
