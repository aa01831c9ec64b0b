"""The ``whirl`` command line: a thin click layer over the library.

Exit status: 0 success; 1 bad input, a missing tool, or an AUTO run that did not succeed (the
results are still written, with each run's status); 2 usage errors (click).
"""

from __future__ import annotations

import logging
import math
import os
import sys
from pathlib import Path

import click

from .errors import OutputError, WhirlError
from .jobs import MAX_JOBS, default_jobs
from .kinds import CheckKind, RunStatus
from .plots.kinds import plot_kinds


def _version() -> str:
    from . import __version__

    return __version__


#: whirl's log: progress (INFO), notes (WARNING) and details (DEBUG), as lines on stderr;
#: ``-q`` keeps warnings and errors only, ``-v`` adds the details.
LOG = logging.getLogger("whirl")


class _ToStderr(logging.Handler):
    """Log records as plain lines on stderr, written through click (which tests capture)."""

    def emit(self, record: logging.LogRecord) -> None:
        click.echo(self.format(record), err=True)


def _configure_log(verbose: bool, quiet: bool) -> None:
    if not any(isinstance(h, _ToStderr) for h in LOG.handlers):
        LOG.addHandler(_ToStderr())
        LOG.propagate = False
    LOG.setLevel(logging.WARNING if quiet else logging.DEBUG if verbose else logging.INFO)


def _console():
    from rich.console import Console

    return Console(stderr=True, highlight=False, quiet=LOG.getEffectiveLevel() > logging.INFO)


def _say(text: str) -> None:
    """A line of progress on stderr, as written (no markup, no wrapping); not with ``-q``."""
    LOG.info(text)


def _tell(text: str, end: str = "\n") -> None:
    """A line of a command's results (files written, tables, final reports), on stdout."""
    click.echo(text + end, nl=False)


def _show_version(ctx: click.Context, _param: click.Parameter, value: bool) -> None:
    """``--version``: the installed version, looked up only when asked (whirl_cli.__version__)."""
    if value and not ctx.resilient_parsing:
        click.echo(f"whirl, version {_version()}")
        ctx.exit()


class _Whirl(click.Group):
    """whirl's commands: a reader of standard output that leaves early (``whirl models |
    head``) is no error (the command goes on to its own end and exit status, its output from
    then on going nowhere); one interrupted by SIGINT or SIGTERM says "interrupted" alone
    (click would print a blank line before its Abort) and exits with 128 + the signal's
    number."""

    def main(self, *args, **kwargs):
        if not isinstance(sys.stdout, _ReaderMayLeave):
            sys.stdout = _ReaderMayLeave(sys.stdout)
        return super().main(*args, **kwargs)

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt as interrupt:
            click.echo("interrupted", err=True)
            raise click.exceptions.Exit(128 + getattr(interrupt, "signum", 2)) from None


class _ReaderMayLeave:
    """Standard output whose reader may close it: a write or flush that finds the pipe
    closed sends everything from then on to /dev/null instead of raising."""

    def __init__(self, stream) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            _reader_left()
            return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except BrokenPipeError:
            _reader_left()
            self._stream.flush()

    def __getattr__(self, name: str):
        return getattr(self._stream, name)


def _reader_left() -> None:
    """Standard output from here on goes nowhere (its reader closed the pipe), so that no
    later write or the flush at exit fails."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, sys.stdout.fileno())
    finally:
        os.close(devnull)


#: Every option can also come from the environment: WHIRL_<COMMAND>_<OPTION>, e.g.
#: WHIRL_RUN_JOBS=4, WHIRL_SWEEP_OUTPUT=results (:func:`_environment_names`).
ENV_PREFIX = "WHIRL"


@click.group(cls=_Whirl, context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--version", is_flag=True, expose_value=False, is_eager=True,
              callback=_show_version, help="Show the version and exit.")
@click.option("-v", "--verbose", is_flag=True, envvar="WHIRL_VERBOSE",
              help="Say more: each AUTO run as it starts, with its directory.")
@click.option("-q", "--quiet", is_flag=True, envvar="WHIRL_QUIET",
              help="No progress on stderr: warnings, errors and results only.")
def cli(verbose: bool, quiet: bool) -> None:
    """Nonlinear whirl-flutter continuation studies with AUTO-07p: YAML in, HDF5 and plots out.

    STUDY_FILE may be - (the study's YAML on standard input). Every option can also be set
    in the environment as WHIRL_<COMMAND>_<OPTION> (e.g. WHIRL_RUN_JOBS=4). Shell completion:
    eval "$(_WHIRL_COMPLETE=bash_source whirl)" (zsh_source, fish_source for those shells).
    """
    _configure_log(verbose, quiet)


#: What ``-`` names as a study file: the YAML on standard input.
STDIN = "-"


def _load(study_file: Path):
    """The study at ``study_file``, or on standard input where it is ``-`` (messages name
    it ``<stdin>``; a model file it names is read relative to the working directory)."""
    from .study import load_study, validate_text

    if str(study_file) != STDIN:
        return load_study(study_file)
    from .errors import StudyError
    from .study import MAX_BYTES

    raw = sys.stdin.buffer.read(MAX_BYTES + 1)
    if len(raw) > MAX_BYTES:
        raise StudyError(f"<stdin>: the study is too large (more than {MAX_BYTES} bytes)")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as error:
        raise StudyError(f"<stdin>: not UTF-8 text (byte 0x{raw[error.start]:02x} at offset "
                         f"{error.start})") from None
    return validate_text(text, "<stdin>")


def _not_stdout(what: str, instead: str = ""):
    """An ``-o`` callback refusing ``-`` (standard output) for an option naming ``what``
    (no file or directory named ``-`` is made); ``instead``: what to use for that."""
    def callback(ctx: click.Context, param: click.Parameter, value):
        if value is not None and str(value) == STDIN:
            raise OutputError(f"-o -: whirl {ctx.info_name} writes {what}, not to standard "
                              f"output; name it{instead}")
        return value
    return callback


# ------------------------------------------------------------------------------------ run
def _jobs_option(help_text: str):
    """``-j/--jobs``: the same name, range and default in every command."""
    return click.option("-j", "--jobs", type=click.IntRange(1, MAX_JOBS),
                        default=default_jobs(), show_default=True, help=help_text)


def _output_file(ctx: click.Context, param: click.Parameter, value: str | None) -> Path | None:
    """``-o``: a file path (not empty, not an existing directory, not ``-``)."""
    if value is None:
        return None
    _not_stdout("an HDF5 file", " (e.g. -o out/study.h5)")(ctx, param, value)
    if not value.strip():
        raise OutputError(f"-o/--output: expected the path of the HDF5 file, got {value!r}")
    path = Path(value)
    if path.is_dir() or value.endswith(os.sep):
        raise OutputError(f"{value}: is a directory; -o/--output names the HDF5 file "
                          "(e.g. out/study.h5)")
    return path


@cli.command()
@click.argument("study_file", type=click.Path(dir_okay=False, path_type=Path))
@click.option("-o", "--output", callback=_output_file,
              help="HDF5 result file [default: <study name>.h5 in the current directory].")
@_jobs_option("AUTO runs (and time simulations, and plots) in parallel.")
@click.option("--overwrite", is_flag=True, help="Replace an existing output file.")
@click.option("--plots/--no-plots", default=True, show_default=True,
              help="Write the study's plots (PNG) next to the output file.")
@click.option("--keep-runs", type=click.Path(file_okay=False, path_type=Path),
              help="Keep AUTO's working directories (constants, b./s./d. files) here.")
def run(study_file: Path, output: Path | None, jobs: int, overwrite: bool, plots: bool,
        keep_runs: Path | None) -> None:
    """Run every continuation and linear analysis of STUDY_FILE (- reads it from standard
    input)."""
    study = _load(study_file)  # first: a bad study is refused fast, before any import

    output = output or Path(f"{study.name}.h5")
    from .output.guard import ready

    # before any work; the directory is made at the end
    ready(output, overwrite, study.path, plots=plots and bool(study.plots))

    runs = {"planned": 0, "done": 0}  # overall progress, shown on a terminal

    def planned(count: int) -> None:
        runs["planned"] += count

    def report(outcome) -> None:
        # an MX is only said to be a problem at the end: at a period blow-up it is expected
        mark = "ok" if outcome.success else outcome.status.upper()
        detail = {RunStatus.OK: "", RunStatus.MX: "  no convergence (MX)"}.get(
            outcome.status, f"  {outcome.message}")
        runs["done"] += 1
        width = len(str(runs["planned"]))
        count = f"[{runs['done']:>{width}}/{runs['planned']}]" if sys.stderr.isatty() else " "
        _say(f"{count} {outcome.name:<32} {mark:<8} {outcome.n_points:>6} points "
             f"{outcome.wall_seconds:7.3f} s{detail}")

    def slow(name: str, seconds: float) -> None:
        _say(f"  {name:<32} still running after {seconds:g} s")

    _say(f"whirl {_version()}: {study.path} -> {output}")
    from . import api
    from .output.summary import render
    from .plots import MODULES as PLOT_MODULES
    from .runtime import catching
    from .verdict import verdict

    with catching():  # an interrupt while plots are drawn is never lost either
        later = PLOT_MODULES if plots and study.plots else ()
        result, published = api.run_and_save(
            study, output, study.plots if plots else (), overwrite, jobs=jobs, on_run=report,
            keep_runs=keep_runs, preload=later, on_slow=slow, on_plan=planned)
    for path in published.paths:
        _tell(f"wrote {path}")
    found = verdict(result, published.plot_error)
    for note in found.notes:
        LOG.warning(f"note: {note}")
    _tell(render(result, "table"), end="")
    checks = [x for c in result.continuations for x in c.cross_checks]
    if checks:
        _tell(f"cross-checks by time simulation: {sum(x.passed for x in checks)} of "
              f"{len(checks)} passed")
    for continuation in result.continuations:
        for explored in continuation.explorations:
            frequencies = ", ".join(f"{f:.4g}" for f in explored.frequencies)
            _tell(f"{continuation.name} explore {explored.parameter} = {explored.value:g}: "
                  f"{explored.kind}" + (f" at {frequencies} Hz" if frequencies else "")
                  + f", lambda = {explored.lyapunov:.3g} +- {explored.lyapunov_error:.2g} 1/s")
    for sim in result.simulations:
        state = "ok" if sim.status == 0 else ("stopped" if sim.status > 0 else "FAILED")
        _tell(f"simulation {sim.name}: {len(sim.time)} samples to "
              f"{sim.time[-1] if len(sim.time) else 0:.6g} s, {state}"
              + ("" if sim.status == 0 else f": {sim.message}"))
    if found.problems:
        raise WhirlError(f"{len(found.problems)} problem(s); the results are stored with "
                         "their status: " + "; ".join(found.problems))


# ------------------------------------------------------------------------------------ summary
@cli.command()
@click.argument("result_file", type=click.Path(path_type=Path))
@click.option("--format", "output_format", type=click.Choice(["table", "csv", "json"]),
              default="table", show_default=True,
              help="A table per continuation to read, or CSV / JSON (one row per special "
                   "point, numbers at full precision) for scripts.")
def summary(result_file: Path, output_format: str) -> None:
    """Print the special points of a result file: type, parameters, amplitude of every dof
    (angles in degrees), period, stability, criticality, status."""
    from . import api
    from .output.summary import render

    if not result_file.exists():
        raise OutputError(f"{result_file}: no such file")
    if result_file.is_dir():
        raise OutputError(f"{result_file}: is a directory, not a result file")
    click.echo(render(api.read(result_file), output_format), nl=False)


# ------------------------------------------------------------------------------------ export
@cli.command()
@click.argument("result_file", type=click.Path(dir_okay=False, path_type=Path))
@click.option("-o", "--output", required=True, type=click.Path(path_type=Path),
              callback=_not_stdout("files", " (the special points as CSV on standard output: "
                                   "whirl summary --format csv)"),
              help="The file to write; its suffix chooses the format: .mat (MATLAB/Octave), "
                   ".nc (NetCDF-4, xarray) or .csv (the special points).")
@click.option("--branches", is_flag=True,
              help="CSV: also one file per branch, <output stem>_<continuation>_<branch>.csv.")
@click.option("--overwrite", is_flag=True, help="Replace existing output files.")
def export(result_file: Path, output: Path, branches: bool, overwrite: bool) -> None:
    """Write the contents of a result file for MATLAB/Octave, xarray/NetCDF tools or CSV."""
    from . import api
    from .export import format_of

    format_of(output)  # a suffix it cannot write: refused before the file is read
    if not result_file.exists():
        raise OutputError(f"{result_file}: no such file")
    for path in api.export(api.read(result_file), output, branches=branches,
                           overwrite=overwrite):
        _tell(f"wrote {path}")


# ------------------------------------------------------------------------------------ check
@cli.command()
@click.argument("result_file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
def check(result_file: Path) -> None:
    """Check the stable orbits and equilibria of a result file by time simulation."""
    from . import api
    from .analysis import simulate
    from .output.provenance import stored_model

    result = api.read(result_file)
    model = stored_model(result, result_file.name)
    parameters = {p.name: p.value for p in result.parameters}

    def compared(x) -> str:  # what expected and simulated are (results.CrossCheck)
        if x.kind == CheckKind.EQUILIBRIUM:
            return (f"perturbation {x.expected:.6g}, final deviation {x.simulated:.6g} "
                    "(typical amplitudes)")
        unit = model.states[model.state_names.index(x.state)].unit
        exact = f", exact law {x.exact:.6g} {unit}" if x.exact is not None else ""
        return f"max {x.state} AUTO {x.expected:.6g} {unit}, simulation {x.simulated:.6g} " \
            f"{unit}{exact}"

    wrong = 0
    for continuation in result.continuations:
        branches = continuation.branches  # canonical names, older files too (store.read)
        for x in simulate.cross_check(model, parameters, branches):
            mark = "ok  " if x.passed else "FAIL"
            click.echo(f"{mark} {continuation.name}/{x.branch}[{x.index}] {x.kind:<11} "
                       f"{branches[0].parameter_names[0]} = {x.parameter:.6g}: "
                       f"{compared(x)}")
            wrong += not x.passed
    if wrong:
        raise WhirlError(f"{wrong} cross-check(s) failed")


# ------------------------------------------------------------------------------------ validate
@cli.command()
@click.argument("study_file", type=click.Path(dir_okay=False, path_type=Path))
def validate(study_file: Path) -> None:
    """Check STUDY_FILE against the schema and the model; exit 0 if valid, 1 if not (- reads
    it from standard input)."""
    study = _load(study_file)
    click.echo(f"{study.path}: ok (model {study.variant().name}, "
               f"{len(study.continuations)} continuation(s))")


# ------------------------------------------------------------------------------------ generate
@cli.command()
@click.option("--check", is_flag=True, help="Only check; exit 1 if the files drifted.")
@click.option("--dir", "directory", type=click.Path(file_okay=False, path_type=Path),
              default=Path("auto_equations"), show_default=True,
              help="Where the generated AUTO files live.")
def generate(check: bool, directory: Path) -> None:
    """(Re)write the AUTO-07p equation and constants files of every model variant."""
    from .auto.equation_files import drifted, write_generated

    if check:
        stale = drifted(directory)
        if stale:
            raise WhirlError("generated files differ from the symbolic models "
                             "(run `whirl generate`): " + ", ".join(stale))
        click.echo(f"{directory}: up to date")
        return
    for path in write_generated(directory):
        click.echo(f"wrote {path}")
    click.echo(f"{directory}: up to date")


# ------------------------------------------------------------------------------------ models
@cli.command()
@click.argument("model_files", nargs=-1, type=click.Path(dir_okay=False, path_type=Path))
def models(model_files: tuple[Path, ...]) -> None:
    """List the model variants with their states and parameters (units, defaults, bounds);
    with MODEL_FILES, the models those files declare (each checked)."""
    from .models import FAMILIES, all_variants, get_model, load_model_file
    from .models.laws import LAWS

    if model_files:
        described = [get_model(load_model_file(path, str(path))) for path in model_files]
    else:
        shipped = all_variants()
        described = shipped + [get_model(name) for name in FAMILIES
                               if name not in {model.family.name for model in shipped}]
    click.echo("\n\n".join(model.describe() for model in described))
    lines = ["", "stiffness laws (nonlinearity type; on any dof, coefficients named "
             "<key>_<dof>):"]
    for law in LAWS.values():
        keys = [c.key for c in law.coefficients]
        keys += [f"{law.stiffness_key} (= the dof's stiffness)"] if law.stiffness_key else []
        lines.append(f"  {law.name}: {law.description}; keys {', '.join(keys)}")
    click.echo("\n".join(lines))


# ------------------------------------------------------------------------------------ plot
def _limits(ctx: click.Context, param: click.Parameter, value):
    """``--xlim``/``--ylim``: two different finite numbers (None if not given)."""
    if value is None:
        return None
    low, high = value
    if not (math.isfinite(low) and math.isfinite(high)) or low == high:
        raise click.BadParameter(f"expected two different finite numbers, got {low:g} {high:g}")
    return float(low), float(high)


def _formats(ctx: click.Context, param: click.Parameter, value: str) -> tuple[str, ...]:
    """``--format``: comma-separated file formats of :data:`whirl_cli.plots.files.FORMATS`,
    the PNG first (always written)."""
    from .plots.files import FORMATS

    named = [part.strip().lower() for part in value.split(",") if part.strip()]
    unknown = [f for f in named if f not in FORMATS]
    if unknown or not named:
        raise click.BadParameter(f"expected formats among {', '.join(FORMATS)}, got {value!r}")
    return tuple(dict.fromkeys(["png", *named]))


@cli.command()
@click.argument("result_file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--kind", "kinds", multiple=True,
              type=click.Choice(plot_kinds()),
              help="Plot kind (repeatable) [default: every kind the file has the data for]; "
                   "a kind it lacks the data for is an error.")
@click.option("-o", "--output", "--output-dir", "output_dir",
              type=click.Path(file_okay=False, path_type=Path),
              callback=_not_stdout("PNG files into a directory"),
              help="Directory for the PNG files [default: next to RESULT_FILE].")
@click.option("--state", help="State the bifurcation diagrams draw [default: the study's "
              "plot_state, else the model's first dof].")
@click.option("--xlim", nargs=2, type=float, callback=_limits, metavar="LOW HIGH",
              help="x-axis limits of every figure, in the units shown.")
@click.option("--ylim", nargs=2, type=float, callback=_limits, metavar="LOW HIGH",
              help="y-axis limits of every figure, in the units shown (degrees for angles).")
@click.option("--hz", is_flag=True, help="Frequencies in Hz instead of rad/s (linear sweeps).")
@click.option("--artefacts", is_flag=True,
              help="Also draw special points flagged as smoothing artefacts (freeplay).")
@click.option("--format", "formats", default="png", show_default=True, callback=_formats,
              metavar="png[,pdf][,svg]",
              help="File formats, comma-separated: the PNG always, and vector PDF (fonts "
                   "embedded) or SVG beside it.")
def plot(result_file: Path, kinds: tuple[str, ...], output_dir: Path | None,
         state: str | None, xlim, ylim, hz: bool, artefacts: bool,
         formats: tuple[str, ...]) -> None:
    """Draw the plots of a whirl result file."""
    from . import api
    from .plots.files import View, available_kinds, missing_data, save_study_plots

    result = api.read(result_file)
    states = {s for c in result.continuations for b in c.branches for s in b.state_names}
    if state is None:
        state = _stored_plot_state(result)
    elif states and state not in states:
        raise WhirlError(f"--state {state}: not a state of {result_file.name} (states: "
                         f"{', '.join(sorted(states))})")
    lacking = [f"--kind {kind}: {result_file.name} has {missing_data(result, kind)}"
               for kind in dict.fromkeys(kinds) if missing_data(result, kind)]
    if lacking:
        raise WhirlError("\n".join(lacking))
    kinds = kinds or available_kinds(result)
    if not kinds:
        raise WhirlError(f"{result_file.name}: nothing to plot (no continuation, linear "
                         "sweep, boundary, linear grid or simulation)")
    output_dir = output_dir or result_file.parent
    try:
        output_dir.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputError(f"{output_dir}: cannot create the output directory "
                          f"({error.strerror or error})") from None
    view = View(xlim=xlim, ylim=ylim, hz=hz, artefacts=artefacts)
    for path in save_study_plots(result, kinds, output_dir, result_file.stem, state,
                                 view=view, result_file=result_file, formats=formats):
        click.echo(f"wrote {path}")


def _stored_plot_state(result) -> str | None:
    """The ``plot_state`` of the study that made ``result`` (None if unset)."""
    return result.provenance.plot_state or None


# ------------------------------------------------------------------------------------ doctor
@cli.command()
def doctor() -> None:
    """Check gfortran and AUTO-07p: find them, compile a model, run AUTO once (with the engine
    WHIRL_AUTO_ENGINE chooses: debian or bifpy)."""
    from .auto import runner, toolchain
    from .auto.codegen import fortran_source
    from .continuation.engine import Numerics
    from .continuation.equilibria import equilibrium_constants
    from .models import get_model

    problems = []
    click.echo(f"whirl {_version()}, Python {sys.version.split()[0]}")
    try:
        click.echo(f"gfortran: {toolchain.gfortran()}")
    except WhirlError as error:
        problems.append(error.message)
    try:
        name, why = toolchain.engine_choice()
        click.echo(f"AUTO engine: {name} ({why}; {toolchain.ENGINE_VARIABLE} chooses one of "
                   f"{', '.join(toolchain.ENGINES)})")
        chosen = toolchain.engine()
        click.echo(f"AUTO-07p: {chosen.version}: {chosen.location} "
                   f"({', '.join(o.name for o in chosen.objects)})"
                   if chosen.name == "bifpy" else
                   f"AUTO-07p: {chosen.location} ({len(chosen.objects)} runtime objects, "
                   f"package {chosen.version})")
    except WhirlError as error:
        problems.append(error.message)
    if not problems:
        model = get_model("classical")
        try:
            executable = toolchain.compile_equations(fortran_source(model), model.name)
            click.echo(f"compile: ok ({executable.path})")
            constants = equilibrium_constants(model, Numerics(), model.parameters[0].name,
                                              (0.0, 0.5), -1)
            import tempfile

            with tempfile.TemporaryDirectory(prefix="whirl-doctor-") as scratch:
                outcome = runner.run(executable.path, constants, Path(scratch) / "run", "doctor",
                                   timeout=60)
            if outcome.success:
                click.echo(f"AUTO run: ok ({outcome.n_points} points, "
                           f"{outcome.wall_seconds:.3f} s)")
            else:
                problems.append(f"AUTO run failed: {outcome.message}")
        except WhirlError as error:
            problems.append(error.message)
    if problems:
        raise WhirlError("\n".join(problems))
    click.echo("everything needed is installed")


# ------------------------------------------------------------------------------------ sweep
@cli.command()
@click.argument("paths", nargs=-1, required=True,
                type=click.Path(exists=True, path_type=Path))
@click.option("-o", "--output", "--output-dir", "out_dir",
              type=click.Path(file_okay=False, path_type=Path),
              default=Path("results"), show_default=True,
              callback=_not_stdout("result files into a directory"),
              help="Directory for <study name>.h5 and the plots.")
@_jobs_option("Studies run in parallel (local worker processes).")
@click.option("--dask", "dask_address", metavar="ADDRESS",
              help="Run the studies on this Dask scheduler instead (needs whirl[dask]).")
@click.option("--force", is_flag=True, help="Rerun studies whose output is up to date.")
@click.option("--plots/--no-plots", default=True, show_default=True,
              help="Write each study's plots next to its HDF5 file.")
def sweep(paths: tuple[Path, ...], out_dir: Path, jobs: int, dask_address: str | None,
          force: bool, plots: bool) -> None:
    """Run every study in PATHS (files, or directories searched for *.yaml), in parallel.

    Resumable: a study whose output has the same study_sha256 and whirl_version is skipped.
    Exit 1 if any study failed (the others still run), 130 on Ctrl-C, 143 on SIGTERM.
    """
    from .sweep.run import run_sweep

    try:
        tally = run_sweep(paths, out_dir, jobs=jobs, dask_address=dask_address, force=force,
                          plots=plots, console=_console(), on_summary=_tell)
    except KeyboardInterrupt as error:
        click.echo("interrupted", err=True)
        raise SystemExit(128 + getattr(error, "signum", 2)) from None  # 130 SIGINT, 143 TERM
    if tally.failures:
        raise WhirlError(f"{len(tally.failures)} of {tally.total} studies failed")


# ------------------------------------------------------------------------------------ figures
def invoked_as(argv0: str, executable: str) -> str:
    """The shell words that call whirl as this process was called: the console script's path
    as typed (e.g. ``.venv/bin/whirl``), ``<python> -m whirl_cli``, else ``whirl``."""
    import shlex

    name = os.path.basename(argv0)
    if name == "whirl":
        return shlex.quote(argv0)
    if name == "__main__.py" and os.path.basename(os.path.dirname(argv0)) == "whirl_cli":
        return shlex.join([executable, "-m", "whirl_cli"])
    return "whirl"


@cli.command()
@click.argument("paths", nargs=-1, required=True, type=click.Path(path_type=Path))
@click.option("-o", "--output", "--out-dir", "out_dir",
              type=click.Path(file_okay=False, path_type=Path),
              default=Path("figures"), show_default=True,
              callback=_not_stdout("figures into a directory"),
              help="Directory for fig<n>.png and index.html.")
@click.option("--results", "results_dir", type=click.Path(file_okay=False, path_type=Path),
              default=Path("results"), show_default=True,
              help="Directory of the studies' <study name>.h5 (reused when up to date).")
@_jobs_option("Studies run in parallel (local worker processes).")
@click.option("--force", is_flag=True, help="Rerun studies whose output is up to date.")
@click.option("--format", "formats", default="png,pdf", show_default=True, callback=_formats,
              metavar="png[,pdf][,svg]",
              help="File formats of each figure, comma-separated: the PNG always (the index "
                   "shows it), and vector PDF (fonts embedded) or SVG beside it.")
def figures(paths: tuple[Path, ...], out_dir: Path, results_dir: Path, jobs: int,
            force: bool, formats: tuple[str, ...]) -> None:
    """Draw the figures of the sheets in PATHS (files, or directories searched for *.yaml):
    run the studies they name (as `whirl sweep`, reusing up-to-date results), write one PNG per
    sheet and an index.html. Exit 1 if any figure could not be drawn."""
    from .figures.build import make_figures

    try:
        outcomes = make_figures(paths, out_dir, results_dir, jobs=jobs, force=force,
                                console=_console(), formats=formats,
                                program=invoked_as(sys.argv[0], sys.executable))
    except KeyboardInterrupt as error:
        click.echo("interrupted", err=True)
        raise SystemExit(128 + getattr(error, "signum", 2)) from None
    drawn = [o for o in outcomes if o.image is not None]
    for outcome in outcomes:
        if outcome.image is None:
            click.echo(f"figure {outcome.sheet.figure}: not drawn: {outcome.problem}", err=True)
    reused = sum(o.reused for o in outcomes)
    click.echo(f"{len(drawn)} of {len(outcomes)} figures ({reused} up to date, not redrawn) -> "
               f"{out_dir / 'index.html'}")
    if len(drawn) < len(outcomes):
        raise WhirlError(f"{len(outcomes) - len(drawn)} of {len(outcomes)} figures not drawn")


# ------------------------------------------------------------------------------------ compare
def _tolerance(ctx: click.Context, param: click.Parameter, value: float | None):
    """``--rtol``/``--atol``: a finite number (>= 0 by its type; None if not given)."""
    if value is not None and not math.isfinite(value):
        raise click.BadParameter(f"expected a finite number >= 0, got {value:g}")
    return value


@cli.command()
@click.argument("file_a", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.argument("file_b", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--rtol", type=click.FloatRange(min=0), default=None, callback=_tolerance,
              help="Relative tolerance: periods, linear sweeps, special-point parameters "
                   "(fraction of the continuation's range) [default: 1e-5, 1e-9, 1e-6].")
@click.option("--atol", type=click.FloatRange(min=0), default=None, callback=_tolerance,
              help="Absolute tolerance on states (rad, rad/s) of special points and branches "
                   "[default: 1e-6, 1e-5].")
@click.option("--limit", type=click.IntRange(1), default=20, show_default=True,
              help="Differences printed at most.")
@click.option("--strict", is_flag=True,
              help="Count differences of the study text and its hash (study_yaml, "
                   "study_sha256) as drift [default: print them as notes].")
def compare(file_a: Path, file_b: Path, rtol: float | None, atol: float | None,
            limit: int, strict: bool) -> None:
    """Compare two result files on physics (special points, branches along the parameter,
    stability, linear sweeps, boundaries), not point indices. Exit 1 on drift."""
    from .output.compare import Tolerances
    from .output.compare import compare as compare_results

    found = compare_results(file_a, file_b, Tolerances.from_options(rtol, atol), strict)
    differences = found.differences
    for difference in differences[:limit]:
        click.echo(str(difference))
    if len(differences) > limit:
        click.echo(f"... and {len(differences) - limit} more")
    for note in found.notes:
        click.echo(f"note: {note}")
    if differences:
        raise WhirlError(f"{file_a} and {file_b} differ ({len(differences)} difference(s))")
    click.echo(f"{file_a} and {file_b} agree")


def _environment_names(group: click.Group) -> None:
    """Let every option of every command of ``group`` come from the environment variable
    ``WHIRL_<COMMAND>_<LONG OPTION>`` (``-`` as ``_``), e.g. ``WHIRL_SUMMARY_FORMAT=csv``,
    ``WHIRL_RUN_PLOTS=0``; the command line wins over the environment."""
    for name, command in group.commands.items():
        for param in command.params:
            if isinstance(param, click.Option) and param.envvar is None:
                option = next(o for o in param.opts if o.startswith("--")).lstrip("-")
                param.envvar = f"{ENV_PREFIX}_{name}_{option}".upper().replace("-", "_")


_environment_names(cli)


def main() -> None:
    """Console entry point: whirl errors as one message, unexpected errors without traceback.

    Once the command is over (its outputs complete or removed), SIGINT and SIGTERM take their
    default action: one arriving while the interpreter shuts down (joining the worker pools'
    threads) ends the process at once instead of printing a KeyboardInterrupt traceback."""
    try:
        _main()
    finally:
        import signal

        signal.signal(signal.SIGINT, signal.SIG_DFL)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _main() -> None:
    try:
        status = cli.main(standalone_mode=False)  # an exit status only where one is raised
    except click.exceptions.Abort as error:  # click's wrapper of a KeyboardInterrupt
        click.echo("interrupted", err=True)
        sys.exit(128 + getattr(error.__cause__, "signum", 2))  # SIGINT 130, SIGTERM 143
    except click.ClickException as error:
        error.show()
        sys.exit(error.exit_code)
    except KeyboardInterrupt as error:
        click.echo("interrupted", err=True)
        sys.exit(128 + getattr(error, "signum", 2))
    except Exception as error:  # a bug: say so plainly, traceback only on request
        from .runtime import wrapped_interrupt

        interrupt = wrapped_interrupt(error)
        if interrupt is not None:
            click.echo("interrupted", err=True)
            sys.exit(128 + getattr(interrupt, "signum", 2))
        if os.environ.get("WHIRL_DEBUG"):
            raise
        click.echo(f"whirl: internal error: {type(error).__name__}: {error} "
                   "(set WHIRL_DEBUG=1 for the traceback and please report it)", err=True)
        sys.exit(1)
    if isinstance(status, int) and status:  # click's Exit: an interrupted command (_Whirl)
        sys.exit(status)
