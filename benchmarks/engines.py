"""The AUTO engines compared on the same studies, interleaved (nothing here is asserted).

For each round and each engine (``WHIRL_AUTO_ENGINE=debian|bifpy``, alternating so both see
the same load) ``whirl run STUDY --no-plots`` runs in a fresh output file with a warm compile
cache of its own per engine (one untimed warm-up run first); printed per run: the load average
before it, whirl's wall time (s), the summed ``wall_seconds`` of the AUTO runs (``/runs`` of
the output), the number of runs, how many ended in MX and how many failed otherwise. Then the
median per engine and study.

Run: ``.venv/bin/python benchmarks/engines.py [--rounds 3] [--engines debian,bifpy]
[--keep DIR] [--warmup SHORT.yaml] STUDY.yaml ...``. An engine ``bifpy@DIR`` is bifpy found
first in ``DIR`` (a build of its own, e.g. with other flags); ``bifpy+ISP2`` runs the
fold-of-cycles loci with ISP=2 instead of whirl's ISP=0 (see :data:`LPC_ISP2`).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bench import launched  # benchmarks/ is this script's directory

ROOT = Path(__file__).resolve().parents[1]
WHIRL = ROOT / ".venv" / "bin" / "whirl"
WITH_CONSTANTS = Path(__file__).with_name("with_constants.py")
#: ``ENGINE+ISP2``: fold-of-cycles loci with ISP=2 (stability and bifurcation detection) instead
#: of whirl's ISP=0, through ``with_constants.py``.
LPC_ISP2 = {"*.fold_of_cycles_*": {"ISP": 2}}


def run_figures(path: Path) -> dict[str, float]:
    """AUTO seconds (sum of /runs wall_seconds), runs, MX ends and other failures of a result."""
    auto, runs, mx, failed = launched(path)
    return {"auto": auto, "runs": runs, "mx": mx, "failed": failed}


def run_once(study: Path, engine: str, out: Path, cache: Path) -> dict[str, float]:
    """One ``whirl run --no-plots`` with ``engine``: wall seconds and :func:`run_figures`.
    ``engine`` may be ``bifpy@DIR``: bifpy found on ``PYTHONPATH=DIR`` first (another build),
    and may end in ``+ISP2`` (:data:`LPC_ISP2`)."""
    name, isp2 = engine.removesuffix("+ISP2"), engine.endswith("+ISP2")
    name, _, path = name.partition("@")
    env = dict(os.environ, WHIRL_AUTO_ENGINE=name, WHIRL_CACHE_DIR=str(cache / name))
    if path:
        env["PYTHONPATH"] = path
        env["WHIRL_CACHE_DIR"] += path.replace("/", "_")
    command = [sys.executable, str(WITH_CONSTANTS), json.dumps(LPC_ISP2)] if isp2 \
        else [str(WHIRL)]
    load = os.getloadavg()[0]
    start = time.perf_counter()
    done = subprocess.run([*command, "run", str(study), "-o", str(out), "--no-plots",
                           "--overwrite"], env=env, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - start
    if not out.exists():
        sys.exit(f"{study.name} with {engine}: no output (exit {done.returncode})\n"
                 f"{done.stderr[-2000:]}")
    return {"load": load, "wall": wall, "exit": done.returncode, **run_figures(out)}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("studies", nargs="+", type=Path)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--engines", default="debian,bifpy")
    parser.add_argument("--keep", type=Path, help="keep the outputs here")
    parser.add_argument("--warmup", type=Path,
                        help="a short study of the same model to warm the caches with "
                             "(default: each study itself)")
    args = parser.parse_args(argv)
    engines = args.engines.split(",")
    scratch = Path(tempfile.mkdtemp(prefix="whirl-engines-"))
    keep = args.keep or scratch
    keep.mkdir(parents=True, exist_ok=True)
    table: dict[tuple[str, str], list[dict[str, float]]] = {}
    print(f"{'study':32} {'engine':12} {'load':>5} {'wall s':>7} {'AUTO s':>7} {'runs':>5} "
          f"{'MX':>4} {'fail':>4} exit", flush=True)
    for study in args.studies:
        for engine in engines:  # warm-up: compile the executables, fill the module caches
            run_once(args.warmup or study, engine, scratch / "warm.h5", scratch / "cache")
        for k in range(args.rounds):
            order = engines if k % 2 == 0 else engines[::-1]
            for engine in order:
                output = keep / f"{study.stem}_{engine.replace('/', '_')}_{k}.h5"
                figures = run_once(study, engine, output, scratch / "cache")
                table.setdefault((study.stem, engine), []).append(figures)
                print(f"{study.stem:32} {engine[:12]:12} {figures['load']:5.2f} "
                      f"{figures['wall']:7.2f} {figures['auto']:7.2f} {figures['runs']:5d} "
                      f"{figures['mx']:4d} {figures['failed']:4d} {figures['exit']}", flush=True)
    print("\nmedians")
    for (stem, engine), rows in table.items():
        print(f"{stem:32} {engine[:12]:12} "
              f"wall {statistics.median(r['wall'] for r in rows):7.2f} s  "
              f"AUTO {statistics.median(r['auto'] for r in rows):7.2f} s  "
              f"MX {sorted({r['mx'] for r in rows})}  runs {sorted({r['runs'] for r in rows})}")


if __name__ == "__main__":
    main()
