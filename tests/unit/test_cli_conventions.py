"""The command line's conventions: a reader that leaves early is no error, ``-`` is standard
input for a study and never an output name, options come from WHIRL_<COMMAND>_<OPTION>
variables too, and shell completion works through the console script."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from ..conftest import ROOT, STUDIES

REFERENCE = ROOT / "tests" / "regression" / "references" / "hardening_case2.h5"


def whirl(*args, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "whirl_cli", *map(str, args)],
                          capture_output=True, text=True, timeout=120, **kwargs)


@pytest.mark.parametrize("args", [("models",), ("summary", REFERENCE, "--format", "json"),
                                  ("--help",)])
def test_a_reader_that_closes_the_pipe_early_is_not_an_error(args):
    """As ``whirl models | head`` (the reader gone before whirl writes: whirl takes longer
    to start than the pipe takes to close)."""
    for _ in range(3):
        process = subprocess.Popen([sys.executable, "-m", "whirl_cli", *map(str, args)],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        process.stdout.close()
        _, errors = process.communicate(timeout=120)
        assert process.returncode == 0, errors.decode()
        assert errors == b""


def test_a_command_that_fails_still_says_so_when_its_reader_left():
    """``whirl compare A B | head``: the reader's leaving does not hide the drift."""
    airspeed = ROOT / "tests" / "regression" / "references" / "linear_datum_airspeed.h5"
    process = subprocess.Popen([sys.executable, "-m", "whirl_cli", "compare", REFERENCE,
                                airspeed], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    process.stdout.close()
    _, errors = process.communicate(timeout=120)
    assert process.returncode == 1 and b"differ (" in errors, errors


def test_a_study_on_standard_input():
    text = (STUDIES / "linear_case2.yaml").read_text()
    done = whirl("validate", "-", input=text)
    assert done.returncode == 0 and done.stdout.startswith("<stdin>: ok (model classical")
    done = whirl("validate", "-", input="name: x\nmodel: nope\n")
    assert done.returncode == 1 and done.stderr.startswith("<stdin>:2: model: unknown model")
    done = subprocess.run([sys.executable, "-m", "whirl_cli", "validate", "-"],
                          input=b"name: \xff\n", capture_output=True, timeout=120)
    assert done.returncode == 1
    assert done.stderr.decode() == "<stdin>: not UTF-8 text (byte 0xff at offset 6)\n"


@pytest.mark.parametrize("args, what", [
    (("run", STUDIES / "linear_case2.yaml", "-o", "-"), "an HDF5 file"),
    (("export", REFERENCE, "-o", "-"), "files"),
    (("plot", REFERENCE, "-o", "-"), "PNG files into a directory"),
    (("sweep", STUDIES / "linear_case2.yaml", "-o", "-"), "result files into a directory"),
    (("figures", ROOT / "sheets" / "thesis_ch3", "-o", "-"), "figures into a directory"),
])
def test_dash_is_never_an_output_name(tmp_path, args, what):
    done = whirl(*args, cwd=tmp_path)
    assert done.returncode == 1
    assert done.stderr.strip().splitlines() == [
        next(line for line in done.stderr.splitlines() if line.startswith("-o -: whirl "))]
    assert f"writes {what}, not to standard output" in done.stderr
    assert not list(tmp_path.iterdir())


def test_options_from_the_environment():
    done = whirl("summary", REFERENCE, env={**os.environ, "WHIRL_SUMMARY_FORMAT": "csv"})
    assert done.returncode == 0 and done.stdout.startswith("continuation,branch,type,")
    done = whirl("run", STUDIES / "linear_case2.yaml",
                 env={**os.environ, "WHIRL_RUN_JOBS": "0"})
    assert done.returncode == 2 and "0 is not in the range 1<=x<=64" in done.stderr
    done = whirl("plot", REFERENCE, "--kind", "law",
                 env={**os.environ, "WHIRL_PLOT_OUTPUT": "-"})
    assert done.returncode == 1 and done.stderr.startswith("-o -: whirl plot writes")
    done = whirl("summary", REFERENCE, "--format", "json",  # the command line wins
                 env={**os.environ, "WHIRL_SUMMARY_FORMAT": "csv"})
    assert done.returncode == 0 and done.stdout.startswith("[")


def test_shell_completion_through_the_console_script():
    env = {**os.environ, "_WHIRL_COMPLETE": "bash_complete", "COMP_WORDS": "whirl exp",
           "COMP_CWORD": "1"}
    done = subprocess.run([sys.executable, "-c", "import sys; sys.argv[0] = 'whirl'; "
                           "from whirl_cli.entry import main; main()"],
                          capture_output=True, text=True, timeout=60, env=env)
    assert done.returncode == 0 and done.stdout.split() == ["plain,export"]


def test_one_option_for_one_meaning_in_every_command():
    """-j/--jobs has one range and default, and the file or folder a command writes is
    -o/--output, in every command that has them."""
    import click

    from whirl_cli.cli import cli
    from whirl_cli.jobs import MAX_JOBS, default_jobs

    options = {name: {o: p for p in command.params if isinstance(p, click.Option)
                      for o in p.opts}
               for name, command in cli.commands.items()}
    jobs = {name: found["--jobs"] for name, found in options.items() if "--jobs" in found}
    assert set(jobs) == {"run", "sweep", "figures"}
    for name, option in jobs.items():
        assert "-j" in option.opts, name
        assert (option.type.min, option.type.max, option.default) == (1, MAX_JOBS,
                                                                      default_jobs()), name
    written = {name for name, found in options.items() if "-o" in found}
    assert written == {"run", "export", "plot", "sweep", "figures"}
    assert all(options[name]["-o"].opts[:2] == ["-o", "--output"] for name in written)


def test_quiet_and_verbose(tmp_path):
    """``whirl -q run``: no progress on stderr, the results still on stdout; ``whirl -v
    run``: each AUTO run's start too."""
    study = ROOT / "tests" / "data" / "lagged_spring_mu.yaml"
    runs = {flag: whirl(flag, "run", study, "-o", tmp_path / f"{flag}.h5", "--no-plots")
            for flag in ("-q", "-v")}
    assert all(r.returncode == 0 for r in runs.values()), runs
    assert runs["-q"].stderr == ""
    assert "main_up" in runs["-q"].stdout and "LP" in runs["-q"].stdout
    assert "mu.main_up" in runs["-v"].stderr and " start in " in runs["-v"].stderr
    assert runs["-v"].stdout == runs["-q"].stdout.replace("-q.h5", "-v.h5")


def test_run_counts_its_auto_runs_on_a_terminal_only(tmp_path):
    """On a terminal each AUTO run's line starts with [done/planned] (the runs planned so
    far; the last line's counts equal); piped, the lines carry no count."""
    import pty
    import re

    study = ROOT / "tests" / "data" / "lorenz_rho.yaml"
    leader, follower = pty.openpty()
    process = subprocess.Popen([sys.executable, "-m", "whirl_cli", "run", str(study), "-o",
                                str(tmp_path / "tty.h5"), "--no-plots"],
                               stdout=subprocess.DEVNULL, stderr=follower)
    os.close(follower)
    chunks = []
    while True:
        try:
            chunk = os.read(leader, 4096)
        except OSError:  # the terminal closed: the process has ended
            break
        if not chunk:
            break
        chunks.append(chunk)
    assert process.wait(timeout=120) == 0
    os.close(leader)
    counted = re.findall(r"^\[\s*(\d+)/(\d+)\] rho\.", b"".join(chunks).decode(), re.M)
    assert len(counted) == 7
    assert [int(done) for done, _ in counted] == list(range(1, 8))
    assert all(int(done) <= int(planned) for done, planned in counted)
    assert counted[-1][0] == counted[-1][1]
    piped = whirl("run", study, "-o", tmp_path / "piped.h5", "--no-plots")
    assert piped.returncode == 0
    lines = [line for line in piped.stderr.splitlines() if " rho." in line]
    assert len(lines) == 7 and not any(line.startswith("[") for line in lines)
