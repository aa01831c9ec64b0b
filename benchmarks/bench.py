"""whirl performance figures, printed in one run (``make bench``). Nothing here is asserted.

(a) overhead: wall time of a full chapter-3 sweep (every study in studies/thesis_ch3, one
    worker) against the summed ``wall_seconds`` of the AUTO runs it launched (``/runs`` of
    the outputs), with and without plots and time-simulation cross-checks, and where the rest
    goes (start-up and imports, cross-checks, plots, the remaining Python).
(b) parallel sweep: the same sweep (``--no-plots``) with 1 and 2 worker processes.
(c) recompilations: a cold compile cache, then a ``--force`` re-run: new cache entries
    (compiled executables, ``Executable.compiled``) on the re-run.
(d) linear analysis: ``whirl_cli.analysis.linear.sweep`` over 2000 airspeeds at once against a
    Python loop calling it point by point, and ``linear.grid`` over 400 x 400 (K_theta, K_psi)
    against a per-point loop.
(e) one row per study (chapter 3, gimballed, freeplay, peers): ``whirl run`` wall time (plots
    and cross-checks as the study asks, warm cache), the summed wall time of the AUTO runs it
    launched, their ratio, the runs and how many ended in MX, and for one-parameter studies
    with a bifurcation diagram the time of redrawing it from the result file (``whirl plot``:
    start-up, imports, one figure; a floor of the run's wall time); and a linear-only study
    (``--no-plots``) against a bare ``python -c "import numpy"``, beside the time of importing
    alone what that run imports.
(f) a fold of cycles: the LPC of softening case 2 by continuation (``run_study``, and the AUTO
    runs of its periodic family) against bisection on time simulations.

    Bisection method: the stable limit cycle (LCO) born at the fold exists for K1 below the
    fold K1_LPC and not above it, where the origin is the only attractor nearby. A test at K1
    starts on the stable LCO found at the last K1 known to have one (its point of maximum
    pitch; in max-pitch terms just inside the stable orbit at K1, which grows towards the
    fold) and integrates with ``whirl_cli.analysis.simulate.integrate`` (LSODA, rtol 1e-8) in chunks
    of 10 periods: "decays" as soon as the pitch amplitude over a chunk falls below half the
    start's, "ends on an LCO" if it survives ``D`` periods. Near the fold the decay lingers in
    the ghost of the vanished cycles (150 periods at 1e-4 above it), so ``D`` bounds the
    accuracy and is a parameter. The only input from continuation is the seed: one point of
    AUTO's stable orbit at K1 ~ 0.398 (what a user would take from a phase portrait).
    Because the basin between the unstable and stable cycle is thin near the fold, a bracket
    is first found by marching up from the seed in steps of 0.005 (short runs, the upper end
    confirmed with the full ``D``), then bisected to ``--fold-tol``.
(g) the 8-state gimballed model: code generation (numeric module and Fortran) and compilation
    of ``gimballed_poly`` in a cold cache (target: under 60 s), then ``whirl run`` of every
    study in studies/gimballed (target: under 20 s each).
(h) freeplay: ``whirl run`` of the airspeed studies in studies/freeplay (seeds, simulation, AUTO,
    persistence in epsilon, plots; warm cache; target: under 10 s; wall, CPU, AUTO seconds, and
    how each special point was recomputed as epsilon shrinks) beside the time a time-marching sweep
    at 0.025 m/s steps would take for one branch of the same cycles.
(i) the airspeed diagram of combined_airspeed by continuation against time marching at
    0.025 m/s steps from a large initial condition (which only brackets the fold of cycles).

(j) the ``explore`` classifier (``whirl_cli.analysis.motion.classify_model``): CPU seconds per
    parameter value of the gimballed studies' ``explore`` lists (target: under 2 s), then each
    list with 2 forked workers (wall per value).

Run: ``.venv/bin/python benchmarks/bench.py [--only abcdefghij] [--exclude GLOB] [--fold-tol 1e-5]
[--fold-periods 3000]``. With all 26 chapter-3 studies it takes about 35 minutes on two cores,
most of it in the two-parameter ``boundary_*`` studies (``--exclude 'boundary_*.yaml'`` leaves
them out); other load on the machine shows in the numbers (the load average is printed).
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CHAPTER3 = ROOT / "studies" / "thesis_ch3"
WHIRL = [sys.executable, "-m", "whirl_cli"]


# ------------------------------------------------------------------------------ helpers
@dataclass(frozen=True)
class Timed:
    """A command and its wall time [s]."""

    command: str
    seconds: float
    returncode: int
    cpu: float = float("nan")  # user + sys of the command and its children [s]


def cpu_seconds(children: bool = False) -> float:
    """User + system CPU seconds of this process (``children``: of its finished children)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN if children else resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def run(arguments: Sequence[str], env: dict[str, str]) -> Timed:
    """Run a command (output discarded) and time it (wall and CPU)."""
    start, cpu = time.perf_counter(), cpu_seconds(children=True)
    done = subprocess.run(list(arguments), cwd=ROOT, env=env, stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True, check=False)
    seconds = time.perf_counter() - start
    if done.returncode not in (0, 1):
        raise RuntimeError(f"{' '.join(arguments)} failed ({done.returncode}):\n"
                           f"{done.stderr[-2000:]}")
    return Timed(" ".join(arguments[2:]), seconds, done.returncode,
                 cpu_seconds(children=True) - cpu)


def launched(path: Path) -> tuple[float, int, int, int]:
    """(summed wall_seconds, runs, runs ending in MX, runs that failed otherwise) of the AUTO
    runs recorded in the result file ``path``."""
    with h5py.File(path, "r") as handle:
        runs = [group.attrs for group in handle.get("runs", {}).values()]
        statuses = [str(r["status"]) for r in runs]
        total = float(sum(float(r["wall_seconds"]) for r in runs))
    return total, len(runs), statuses.count("mx"), sum(s not in ("ok", "mx") for s in statuses)


def auto_seconds(directory: Path) -> tuple[float, int]:
    """(summed wall_seconds, count) of the AUTO runs recorded in every .h5 of ``directory``."""
    found = [launched(path) for path in sorted(directory.glob("*.h5"))]
    return sum(f[0] for f in found), sum(f[1] for f in found)


def cache_entries(cache: Path) -> int:
    """Compiled AUTO executables in a whirl cache directory."""
    return len(list((cache / "exe").glob("*/*.exe"))) if (cache / "exe").is_dir() else 0


def load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def best_of(function: Callable[[], object], repeats: int = 3) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def heading(text: str) -> None:
    print(f"\n== {text}", flush=True)


# ------------------------------------------------------------------------------ (a) (b) (c)
@dataclass
class SweepFigures:
    """Wall times [s] of the chapter-3 sweeps and what they launched."""

    cold_2: Timed | None = None
    warm_2: Timed | None = None
    warm_1: Timed | None = None
    plots_1: Timed | None = None
    no_checks_1: Timed | None = None
    auto_total: float = 0.0
    auto_runs: int = 0
    auto_no_checks: float = 0.0
    compiled_cold: int = 0
    compiled_rerun: int = 0
    studies: int = 0


def selected_studies(target: Path, exclude: Sequence[str]) -> Path:
    """Copies of the chapter-3 studies whose file names match none of ``exclude`` (globs)."""
    target.mkdir(parents=True)
    for path in sorted(CHAPTER3.glob("*.yaml")):
        if not any(path.match(pattern) for pattern in exclude):
            shutil.copyfile(path, target / path.name)
    return target


def no_cross_check_copies(source: Path, target: Path) -> Path:
    """The studies of ``source`` with ``cross_check: false``."""
    target.mkdir(parents=True)
    for path in sorted(source.glob("*.yaml")):
        (target / path.name).write_text(path.read_text().replace("cross_check: true",
                                                                 "cross_check: false"))
    return target


def sweeps(studies: Path, scratch: Path, env: dict[str, str], cache: Path) -> SweepFigures:
    """The sweeps of (a), (b) and (c) over ``studies``, cold cache first."""
    figures = SweepFigures(studies=len(list(studies.glob("*.yaml"))))
    out = scratch / "sweep"
    figures.cold_2 = run(WHIRL + ["sweep", str(studies), "-o", str(out), "-j", "2",
                                  "--no-plots"], env)
    figures.compiled_cold = cache_entries(cache)
    print(f"cold cache, 2 workers, no plots: {figures.cold_2.seconds:7.1f} s "
          f"({figures.compiled_cold} executables compiled)", flush=True)
    figures.warm_2 = run(WHIRL + ["sweep", str(studies), "-o", str(out), "-j", "2",
                                  "--no-plots", "--force"], env)
    figures.compiled_rerun = cache_entries(cache) - figures.compiled_cold
    print(f"re-run, 2 workers, no plots:     {figures.warm_2.seconds:7.1f} s "
          f"({figures.compiled_rerun} new executables)", flush=True)
    figures.warm_1 = run(WHIRL + ["sweep", str(studies), "-o", str(out), "-j", "1",
                                  "--no-plots", "--force"], env)
    figures.auto_total, figures.auto_runs = auto_seconds(out)
    print(f"re-run, 1 worker, no plots:      {figures.warm_1.seconds:7.1f} s", flush=True)
    figures.plots_1 = run(WHIRL + ["sweep", str(studies), "-o", str(out), "-j", "1",
                                   "--force"], env)
    print(f"re-run, 1 worker, with plots:    {figures.plots_1.seconds:7.1f} s", flush=True)
    unchecked = no_cross_check_copies(studies, scratch / "no-checks")
    figures.no_checks_1 = run(WHIRL + ["sweep", str(unchecked), "-o",
                                       str(scratch / "no-checks-out"), "-j", "1",
                                       "--no-plots"], env)
    figures.auto_no_checks, _ = auto_seconds(scratch / "no-checks-out")
    print(f"1 worker, no plots, no checks:   {figures.no_checks_1.seconds:7.1f} s", flush=True)
    return figures


def startup_seconds(env: dict[str, str]) -> tuple[float, float]:
    """(``whirl --version``, importing what a worker needs) wall times [s], best of 3."""
    cli = best_of(lambda: run(WHIRL + ["--version"], env))
    imports = best_of(lambda: run([sys.executable, "-c", "import whirl_cli.pipeline, "
                                   "whirl_cli.analysis.simulate, whirl_cli.output.store"], env))
    return cli, imports


def report_sweeps(figures: SweepFigures, env: dict[str, str]) -> None:
    heading(f"(a) whirl wall time vs AUTO wall time: {figures.studies} studies of "
            "studies/thesis_ch3, 1 worker")
    auto = figures.auto_total
    rows = [("with cross-checks and plots (what the studies ask)", figures.plots_1, auto),
            ("with cross-checks, --no-plots", figures.warm_1, auto),
            ("without cross-checks, --no-plots", figures.no_checks_1, figures.auto_no_checks)]
    print(f"AUTO runs launched: {figures.auto_runs}, summed wall_seconds {auto:.1f} s")
    for label, timed, auto_part in rows:
        print(f"  {label:<52} {timed.seconds:7.1f} s   ratio {timed.seconds / auto_part:5.2f}"
              f"   (target <= 1.2)")
    cli, imports = startup_seconds(env)
    checks = figures.warm_1.seconds - figures.no_checks_1.seconds
    plots = figures.plots_1.seconds - figures.warm_1.seconds
    rest = figures.no_checks_1.seconds - figures.auto_no_checks - imports
    print("where the time goes (1 worker):")
    print(f"  AUTO-07p runs                                        {auto:7.1f} s")
    print(f"  time-simulation cross-checks (with - without)        {checks:7.1f} s")
    print(f"  plots (with - without)                               {plots:7.1f} s")
    print(f"  start-up: `whirl --version` {cli:.2f} s; worker imports (sympy, scipy, h5py) "
          f"{imports:.2f} s")
    print(f"  rest without checks/plots (model set-up, parsing, HDF5, pool)  {rest:7.1f} s")

    heading("(b) sweep with 1 vs 2 workers (--no-plots, warm cache)")
    speedup = figures.warm_1.seconds / figures.warm_2.seconds
    print(f"  1 worker {figures.warm_1.seconds:.1f} s, 2 workers {figures.warm_2.seconds:.1f} s:"
          f" speed-up {speedup:.2f}x (target >= 1.8x; {os.cpu_count()} CPUs)")

    heading("(c) recompilations on a re-run")
    print(f"  cold cache: {figures.compiled_cold} executable(s) compiled; --force re-run: "
          f"{figures.compiled_rerun} new (target 0)")


def recompilations_in_process() -> int:
    """``Executable.compiled`` count of a second in-process run of one study (warm cache)."""
    from whirl_cli.auto import toolchain
    from whirl_cli.pipeline import run_study
    from whirl_cli.study import load_study

    compiled = []
    original = toolchain.compile_equations

    def counting(*args, **kwargs):
        executable = original(*args, **kwargs)
        compiled.append(executable.compiled)
        return executable

    toolchain.compile_equations = counting
    try:
        study = load_study(CHAPTER3 / "linear_case2.yaml")
        for _ in range(2):
            with tempfile.TemporaryDirectory() as work:
                run_study(study, Path(work))
    finally:
        toolchain.compile_equations = original
    return sum(compiled[1:])


# ------------------------------------------------------------------------------ (d)
def linear_figures(points: int = 2000) -> None:
    from whirl_cli.analysis import linear
    from whirl_cli.study import load_study

    heading(f"(d) linear analysis over {points} airspeeds: vectorised vs a per-point loop")
    study = load_study(CHAPTER3 / "linear_datum_airspeed.yaml")
    model, overrides = study.variant(), study.parameter_values()
    values = np.linspace(0.0, 10.0, points)
    vectorised = best_of(lambda: linear.sweep(model, overrides, "V", values))
    looped = best_of(lambda: [linear.sweep(model, overrides, "V", values[k:k + 1])
                              for k in range(points)], repeats=1)
    print(f"  linear.sweep over all points {vectorised * 1e3:8.1f} ms; loop "
          f"{looped * 1e3:8.1f} ms: {looped / vectorised:.0f}x")
    grid_figures(model, overrides)


def grid_figures(model, overrides, size: int = 400) -> None:
    """``linear.grid`` (max real part over a size x size K_theta-K_psi grid, one batched
    eigenvalue call, and its zero contour) against a per-point loop computing the same max
    real part (Jacobian and ``numpy.linalg.eigvals`` at each point)."""
    from whirl_cli.analysis import linear

    axis = np.linspace(0.0, 0.6, size)
    vectorised = best_of(lambda: linear.grid(model, overrides, "K_theta", axis, "K_psi", axis))
    x_index = model.parameter_names.index(model.canonical("K_theta"))
    y_index = model.parameter_names.index(model.canonical("K_psi"))
    base = model.parameter_vector(overrides)
    zero = np.zeros(model.n_states)

    def loop() -> np.ndarray:
        out = np.empty((size, size))
        params = base.copy()
        for i, k_psi in enumerate(axis):
            params[y_index] = k_psi
            for j, k_theta in enumerate(axis):
                params[x_index] = k_theta
                out[i, j] = np.linalg.eigvals(model.jacobian_numpy(zero, params)).real.max()
        return out

    start = time.perf_counter()
    looped_values = loop()
    looped = time.perf_counter() - start
    grid = linear.grid(model, overrides, "K_theta", axis, "K_psi", axis)
    agree = np.allclose(grid.max_real, looped_values, rtol=1e-9, atol=1e-9)
    print(f"  linear.grid {size}x{size} (with contour) {vectorised * 1e3:8.1f} ms; loop "
          f"{looped * 1e3:8.1f} ms: {looped / vectorised:.0f}x (same values: {agree})")


# ------------------------------------------------------------------------------ (e)
@dataclass(frozen=True)
class StudyFigures:
    """One study's ``whirl run`` (as it asks, warm cache) and the AUTO runs it launched."""

    name: str
    wall: float  # s
    auto: float  # s, summed wall_seconds of /runs
    runs: int
    mx: int  # runs that ended in MX
    returncode: int
    redraw: float = float("nan")  # s, `whirl plot --kind bifurcation` of its file (or NaN)


def study_figures(path: Path, scratch: Path, env: dict[str, str]) -> StudyFigures:
    """``whirl run`` of the study; for a one-parameter study that draws a bifurcation diagram,
    also the wall time of redrawing that diagram from its result file (no AUTO, no checks,
    one process): a floor of its run's wall time, whatever AUTO takes."""
    out = scratch / "cases" / f"{path.parent.name}-{path.stem}.h5"
    timed = run(WHIRL + ["run", str(path), "-o", str(out), "--overwrite"], env)
    auto, runs, mx, _ = launched(out) if out.exists() else (0.0, 0, 0, 0)
    redraw = float("nan")
    if auto > 0 and not path.stem.startswith("boundary_"):
        from whirl_cli.study import load_study

        if "bifurcation" in load_study(path).plots:
            redraw = run(WHIRL + ["plot", str(out), "--kind", "bifurcation", "-o",
                                  str(scratch / "redrawn")], env).seconds
    return StudyFigures(path.stem, timed.seconds, auto, runs, mx, timed.returncode, redraw)


#: What ``whirl run --no-plots`` of a linear-only study imports, ending as ``whirl`` does
#: (without the interpreter's teardown: :func:`whirl_cli.entry.leave`).
RUN_IMPORTS = ("import whirl_cli.cli, whirl_cli.study, whirl_cli.api, whirl_cli.pipeline, "
               "whirl_cli.publish, whirl_cli.output.summary, whirl_cli.verdict; "
               "import os; os._exit(0)")


def per_case(studies: Path, scratch: Path, env: dict[str, str]) -> None:
    heading("(e) one row per study: `whirl run` wall time (plots and cross-checks as the study "
            "asks, warm cache, --jobs 2) and the AUTO runs it launched")
    groups = [("thesis_ch3", sorted(studies.glob("*.yaml")))] + [
        (group, sorted((ROOT / "studies" / group).glob("*.yaml")))
        for group in ("gimballed", "freeplay", "peers")]
    print(f"  {'study':<34} {'wall s':>8} {'AUTO s':>8} {'wall/AUTO':>9} {'runs':>5} "
          f"{'MX':>4} {'redraw s':>9}")
    rows = []
    for group, paths in groups:
        print(f"  {group}/")
        for path in paths:
            row = study_figures(path, scratch, env)
            rows.append(row)
            ratio = f"{row.wall / row.auto:9.2f}" if row.auto > 0 else f"{'-':>9}"
            failed = "" if row.returncode == 0 else f"   exit {row.returncode}"
            redraw = f"{row.redraw:9.2f}" if np.isfinite(row.redraw) else f"{'-':>9}"
            print(f"    {row.name:<32} {row.wall:8.2f} {row.auto:8.2f} {ratio} {row.runs:5d} "
                  f"{row.mx:4d} {redraw}{failed}", flush=True)
    one_parameter = [r for r in rows if r.auto > 0 and not r.name.startswith("boundary_")]
    ratios = [r.wall / r.auto for r in one_parameter]
    if ratios:
        worst = max(one_parameter, key=lambda r: r.wall / r.auto)
        print(f"  studies with AUTO runs, boundaries aside: median wall/AUTO "
              f"{np.median(ratios):.2f}, max {worst.wall / worst.auto:.2f} ({worst.name}); "
              f"target <= 2")
    redrawn = [r for r in one_parameter if np.isfinite(r.redraw)]
    if redrawn:
        out_of_reach = [r for r in redrawn if r.redraw > 2 * r.auto]
        print(f"  redrawing the bifurcation diagram from the file (one figure, no AUTO, no "
              f"checks; 'redraw s') takes over 2x the study's AUTO time for "
              f"{len(out_of_reach)} of {len(redrawn)} such studies: for them wall <= 2x AUTO "
              f"is below what drawing alone costs")
    linear = CHAPTER3 / "linear_datum_airspeed.yaml"
    wall = best_of(lambda: run(WHIRL + ["run", str(linear), "-o", str(scratch / "linear.h5"),
                                        "--no-plots", "--overwrite"], env))
    bare = best_of(lambda: run([sys.executable, "-c", "import numpy"], env))
    imports = best_of(lambda: run([sys.executable, "-c", RUN_IMPORTS], env))
    print(f"  linear-only study ({linear.stem}, --no-plots, best of 3) {wall:.2f} s vs bare "
          f"`python -c 'import numpy'` {bare:.2f} s: {wall / bare:.1f}x (target <= 3x); "
          f"the modules such a run imports, alone (numpy, h5py, pydantic and the study "
          f"schema, click, PyYAML, whirl's): {imports:.2f} s = {imports / bare:.1f}x")


# ------------------------------------------------------------------------------ (f)
@dataclass
class Bisection:
    """Outcome of the simulation bisection: bracket [N m/rad], cost."""

    lower: float
    upper: float
    simulations: int
    periods: float
    seconds: float


class FoldBySimulation:
    """Bisection for the fold of cycles on time simulations (see the module docstring)."""

    def __init__(self, model, overrides: dict[str, float], period: float) -> None:
        self.model, self.overrides, self.period = model, overrides, period
        self.simulations, self.periods = 0, 0.0

    def ends_on_cycle(self, k1: float, start: np.ndarray, periods: int
                      ) -> tuple[bool, np.ndarray]:
        """(True, a state of maximum pitch on the cycle) if the trajectory from ``start`` at
        ``k1`` survives ``periods`` periods; (False, start) once it decays."""
        from whirl_cli.analysis.simulate import integrate

        params = self.model.parameter_vector({**self.overrides, "K_theta": k1})
        amplitude, state, chunk = abs(start[0]), start, 10
        for _ in range(max(1, periods // chunk)):
            _, states = integrate(self.model, params, state, chunk * self.period,
                                  samples=chunk * 40)
            self.simulations += 1
            self.periods += chunk
            half = states[len(states) // 2:]
            if np.abs(half[:, 0]).max() < 0.5 * amplitude:
                return False, start
            state = states[-1]
        return True, half[int(np.argmax(half[:, 0]))]

    def locate(self, seed_k1: float, seed: np.ndarray, tol: float, periods: int,
               step: float = 0.005, march_periods: int = 200, upper: float = 0.5
               ) -> Bisection:
        start_time = time.perf_counter()
        found, state = self.ends_on_cycle(seed_k1, seed, periods)
        assert found, "the seed is not on a stable cycle"
        lower = seed_k1
        while True:  # march to a bracket of width ``step``
            trial = min(lower + step, upper)
            found, cycle = self.ends_on_cycle(trial, state, march_periods)
            if found:
                lower, state = trial, cycle
                continue
            found, cycle = self.ends_on_cycle(trial, state, periods)  # confirm with full D
            if found:
                lower, state = trial, cycle
                continue
            high = trial
            break
        while high - lower > tol:
            middle = 0.5 * (lower + high)
            found, cycle = self.ends_on_cycle(middle, state, periods)
            if found:
                lower, state = middle, cycle
            else:
                high = middle
        return Bisection(lower, high, self.simulations, self.periods,
                         time.perf_counter() - start_time)


def fold_figures(scratch: Path, tol: float, periods: int) -> None:
    from whirl_cli.pipeline import run_study
    from whirl_cli.results import PointType
    from whirl_cli.study import load_study

    heading("(f) fold of cycles (LPC) of softening case 2: continuation vs simulation bisection")
    study = load_study(CHAPTER3 / "softening_case2.yaml")
    quick = study.model_copy(update={"cross_check": False})
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(dir=scratch) as work:
        result = run_study(quick, Path(work))
    continuation_seconds = time.perf_counter() - start
    (continuation,) = result.continuations
    (lpc,) = [p for p in continuation.special_points if p.point_type == PointType.LPC]
    family = next(b for b in continuation.branches if b.name == lpc.branch)
    family_auto = sum(r.wall_seconds for r in result.runs
                      if r.name.startswith(f"{continuation.name}.{family.name}"))
    k1_lpc = float(lpc.parameters[0])
    print(f"  continuation: K1_LPC = {k1_lpc:.8f} N m/rad; whole study (no cross-check) "
          f"{continuation_seconds:.2f} s, AUTO runs of its periodic family {family_auto:.2f} s")

    stable = [o for o in family.orbits if family.stable[o.index] and o.states.shape[0] > 1]
    seed_orbit = min(stable, key=lambda o: abs(o.parameters[0] - 0.4))
    seed = seed_orbit.states[int(np.argmax(seed_orbit.states[:, 0]))]
    model = study.variant()
    search = FoldBySimulation(model, study.parameter_values(), float(lpc.period))
    found = search.locate(float(seed_orbit.parameters[0]), seed, tol, periods)
    estimate = 0.5 * (found.lower + found.upper)
    print(f"  bisection: K1 in [{found.lower:.8f}, {found.upper:.8f}] (width "
          f"{found.upper - found.lower:.1e}, D = {periods} periods), estimate {estimate:.8f}, "
          f"{estimate - k1_lpc:+.1e} from AUTO's LPC; {found.simulations} simulation chunks, "
          f"{found.periods:.0f} periods simulated, {found.seconds:.1f} s")
    print(f"  bisection / continuation (whole study): "
          f"{found.seconds / continuation_seconds:.0f}x slower")


# ------------------------------------------------------------------------------ main
def gimballed_figures(scratch: Path, env: dict[str, str]) -> None:
    """(g): cold-cache codegen + compile of the 8-state variant, then its studies."""
    from whirl_cli.auto import toolchain
    from whirl_cli.auto.codegen import fortran_source
    from whirl_cli.models import get_model
    from whirl_cli.models.numeric import numeric_source

    heading("(g) gimballed model (8 states)")
    model = get_model("gimballed")
    cold = scratch / "gimballed-cache"
    previous = os.environ.get("WHIRL_CACHE_DIR")
    os.environ["WHIRL_CACHE_DIR"] = str(cold)
    try:
        started = time.perf_counter()
        numeric_source(model)
        generated = time.perf_counter()
        toolchain.compile_equations(fortran_source(model), model.name)
        done = time.perf_counter()
    finally:
        if previous is not None:
            os.environ["WHIRL_CACHE_DIR"] = previous
    print(f"  {model.name}: numeric module {generated - started:.2f} s, Fortran + compile "
          f"{done - generated:.2f} s, total {done - started:.2f} s (target < 60 s)", flush=True)
    for path in sorted((ROOT / "studies" / "gimballed").glob("*.yaml")):
        timed = run(WHIRL + ["run", str(path), "-o", str(scratch / f"{path.stem}.h5"),
                             "--overwrite"], env)
        print(f"  whirl run {path.stem:<24} {timed.seconds:6.2f} s  exit {timed.returncode}"
              f"{'' if timed.seconds < 20 else '  (over 20 s)'}", flush=True)


def freeplay_figures(scratch: Path, env: dict[str, str], step: float = 0.025) -> None:
    """(h): the freeplay airspeed studies, ``*_airspeed.yaml`` (seeds, simulation, AUTO,
    persistence, plots) against the time a time-marching sweep at ``step`` m/s would take for
    the same curve (one seed settled per airspeed, measured at the study's start)."""
    import numpy as np

    from whirl_cli.analysis import seeds
    from whirl_cli.output import store
    from whirl_cli.study import load_study

    heading("(h) freeplay: continuation from seeds vs a time-marching sweep (warm cache)")
    for path in sorted((ROOT / "studies" / "freeplay").glob("*_airspeed.yaml")):
        output = scratch / f"{path.stem}.h5"
        # warm: the executable, and the numpy modules generated ahead (the linear model's for
        # the onset and the describing-function estimate, the exact law's for the cross-check)
        run(WHIRL + ["run", str(path), "-o", str(output), "--overwrite", "--no-plots"], env)
        timed = run(WHIRL + ["run", str(path), "-o", str(output), "--overwrite"], env)
        study = load_study(path)
        spec = study.continuations[0]
        model = study.variant()
        values = {**study.parameter_values(), spec.parameter: spec.start}
        seed = seeds.auto_seeds(model, values)[1]  # 4 half-gaps: on the cycle
        params = model.parameter_vector(values)
        started, cpu = time.perf_counter(), time.process_time()
        seeds.settle(model, params, seed)
        one, one_cpu = time.perf_counter() - started, time.process_time() - cpu
        speeds = int(np.ceil((spec.range[1] - spec.range[0]) / step)) + 1
        auto, runs, mx, _ = launched(output)
        paths = [p.refined_by for c in store.read(output).continuations
                 for p in c.special_points if p.refined_by]
        print(f"  whirl run {path.stem:<16} {timed.seconds:6.2f} s wall, {timed.cpu:6.2f} s CPU"
              f"  exit {timed.returncode}{'' if timed.seconds < 10 else '  (over 10 s)'}; "
              f"AUTO {auto:.2f} s in {runs} runs ({mx} MX); special points recomputed by "
              f"{', '.join(f'{paths.count(w)} {w}' for w in sorted(set(paths))) or 'none'}",
              flush=True)
        print(f"    time marching at {step} m/s: {speeds} airspeeds x {one:.2f} s "
              f"({one_cpu:.2f} s CPU) = {speeds * one:.1f} s ({speeds * one / timed.seconds:.1f}"
              f" x the study's wall), one branch of cycles only", flush=True)


def airspeed_figures(scratch: Path, env: dict[str, str], step: float = 0.025,
                     pitch_degrees: float = 15.0, peer_periods: int = 300) -> None:
    """(i): the airspeed diagram of combined_airspeed (the stable cycles above their fold)
    by continuation (``whirl run --no-plots``, warm cache) against the same curve by time
    marching: at every ``step`` m/s across the study's range, one simulation from a large
    initial condition (``pitch_degrees`` on the first dof) until it settles
    (:func:`whirl_cli.analysis.seeds.settle`), its amplitude recorded; the fold is then only
    bracketed between the last airspeed that decayed and the first that kept a cycle.
    Then as a peer without a settling test would: ``peer_periods`` periods (of the slowest
    linear mode) at every airspeed, the pitch amplitude of the last 20 periods recorded (a
    cycle if it keeps over 1% of the start)."""
    from whirl_cli.analysis import seeds, simulate
    from whirl_cli.output.store import read
    from whirl_cli.results import PointType
    from whirl_cli.study import load_study

    heading("(i) airspeed diagram (combined_airspeed): continuation vs time marching at "
            f"{step} m/s steps")
    path = CHAPTER3 / "combined_airspeed.yaml"
    out = scratch / "airspeed.h5"
    continuation = best_of(lambda: run(WHIRL + ["run", str(path), "-o", str(out), "--no-plots",
                                                "--overwrite"], env), repeats=2)
    (result,) = read(out).continuations
    folds = [float(p.parameters[0]) for p in result.special_points
             if p.point_type == PointType.LPC]
    study = load_study(path)
    spec = study.continuations[0]
    model = study.variant()
    seed = np.zeros(model.n_states)
    seed[0] = np.radians(pitch_degrees)
    speeds = np.arange(spec.range[0], spec.range[1] + step / 2, step)
    started = time.perf_counter()
    kinds = []
    for speed in speeds:
        params = model.parameter_vector({**study.parameter_values(), spec.parameter: speed})
        kinds.append(seeds.settle(model, params, seed).kind)
    marching = time.perf_counter() - started
    cycles = [v for v, kind in zip(speeds, kinds, strict=True) if kind == "periodic"]
    decayed = [v for v, kind in zip(speeds, kinds, strict=True)
               if kind == "equilibrium" and (not cycles or v < min(cycles))]
    bracket = (f"[{max(decayed):.3f}, {min(cycles):.3f}] m/s" if cycles and decayed
               else "not bracketed")
    print(f"  continuation: {continuation:.2f} s (whole study, --no-plots); fold of cycles at "
          + ", ".join(f"{v:.5f}" for v in folds) + " m/s")
    print(f"  time marching: {len(speeds)} airspeeds, {marching:.1f} s "
          f"({', '.join(f'{kinds.count(k)} {k}' for k in sorted(set(kinds)))}); fold bracketed "
          f"in {bracket}")
    print(f"  time marching / continuation: {marching / continuation:.0f}x (target >= 100x)")
    started, kept = time.perf_counter(), []
    for speed in speeds:
        params = model.parameter_vector({**study.parameter_values(), spec.parameter: speed})
        period = seeds.reference_period(model, params)
        _, y = simulate.integrate(model, params, seed, peer_periods * period,
                                  samples=peer_periods * 20 + 1)
        kept.append(np.ptp(y[-20 * 20:, 0]) / 2 > 1e-2 * seed[0])
    peer = time.perf_counter() - started
    above = [v for v, cycle in zip(speeds, kept, strict=True) if cycle]
    below = [v for v, cycle in zip(speeds, kept, strict=True)
             if not cycle and (not above or v < min(above))]
    bracket = (f"[{max(below):.3f}, {min(above):.3f}] m/s" if above and below
               else "not bracketed")
    print(f"  time marching, {peer_periods} periods per airspeed (no settling test): "
          f"{peer:.1f} s, {sum(kept)} cycles of {len(speeds)}; fold bracketed in {bracket}")
    print(f"  that marching / continuation: {peer / continuation:.0f}x (target >= 100x)")


# ------------------------------------------------------------------------------ (j)
#: The gimballed studies whose ``explore`` values (j) classifies.
EXPLORED = ("explore_combined_case2_soft.yaml", "torus_airspeed.yaml")


def classifier_figures() -> None:
    """CPU seconds per ``explore`` value (``whirl_cli.pipeline.explorations`` of one value,
    in this process), then all of a study's values with 2 forked workers (wall, and CPU of
    parent and workers)."""
    from whirl_cli import pipeline
    from whirl_cli.study import load_study

    heading("(j) explore classifier: CPU seconds per parameter value (target: under 2 s)")
    for name in EXPLORED:
        study = load_study(ROOT / "studies" / "gimballed" / name)
        spec = next(c for c in study.continuations if c.explore)
        model = study.variant()
        values = study.parameter_values()
        model.field_at(model.parameter_vector(values))  # the generated module, loaded once
        for value in spec.explore:
            one = spec.model_copy(update={"explore": (value,)})
            started = cpu_seconds()
            (found,) = pipeline.explorations(model, values, one)
            doubled = " (window doubled)" if "window doubled" in found.evidence else ""
            print(f"  {name} {spec.parameter} = {value:g}: {cpu_seconds() - started:.2f} s CPU, "
                  f"{found.kind}{doubled}", flush=True)
        started, wall = cpu_seconds() + cpu_seconds(True), time.perf_counter()
        pipeline.explorations(model, values, spec, jobs=2)
        wall = time.perf_counter() - wall
        spent = cpu_seconds() + cpu_seconds(True) - started
        print(f"  {name}: {len(spec.explore)} values, --jobs 2: {wall:.2f} s wall "
              f"({wall / len(spec.explore):.2f} s per value), {spent:.2f} s CPU", flush=True)


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--only", default="abcdefghij",
                        help="letters of the figures to produce, e.g. 'ad' [default: all]")
    parser.add_argument("--fold-tol", type=float, default=1e-5,
                        help="bracket width at which the bisection of (f) stops [N m/rad]")
    parser.add_argument("--fold-periods", type=int, default=3000,
                        help="periods a start must survive to count as a cycle in (f)")
    parser.add_argument("--exclude", action="append", default=[], metavar="GLOB",
                        help="leave out chapter-3 study files matching GLOB (repeatable), "
                        "e.g. 'boundary_*.yaml'")
    options = parser.parse_args(argv)
    only = set(options.only.replace(",", ""))
    print(f"whirl benchmarks: {os.cpu_count()} CPUs, load average {load()} at start")
    scratch = Path(tempfile.mkdtemp(prefix="whirl-bench-"))
    cache = scratch / "cache"
    env = dict(os.environ, WHIRL_CACHE_DIR=str(cache))
    os.environ["WHIRL_CACHE_DIR"] = str(cache)
    studies = selected_studies(scratch / "studies", options.exclude)
    print(f"studies: {len(list(studies.glob('*.yaml')))} of studies/thesis_ch3"
          + (f" (excluding {', '.join(options.exclude)})" if options.exclude else ""))
    try:
        if only & set("abc"):
            figures = sweeps(studies, scratch, env, cache)
            report_sweeps(figures, env)
            print(f"  in-process second run of linear_case2: "
                  f"{recompilations_in_process()} Executable.compiled")
        if "d" in only:
            linear_figures()
        if "e" in only:
            per_case(studies, scratch, env)
        if "f" in only:
            fold_figures(scratch, options.fold_tol, options.fold_periods)
        if "g" in only:
            gimballed_figures(scratch, env)
        if "h" in only:
            freeplay_figures(scratch, env)
        if "i" in only:
            airspeed_figures(scratch, env)
        if "j" in only:
            classifier_figures()
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    print(f"\nload average at the end: {load()}")


if __name__ == "__main__":
    main()
