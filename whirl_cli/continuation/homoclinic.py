"""HomCont (AUTO IPS=9): locating the homoclinic end of a periodic family whose period blows
up, from the family's longest stored orbit.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..auto import runner
from ..auto.constants import base_constants
from ..auto.parse import parse_b
from ..models import Model
from ..results import Branch, BranchKind, LocateStatus, Origin, SpecialPoint
from .branches import joined_notes, typical_amplitudes
from .engine import Engine, RunSpec

#: HomCont: a homoclinic orbit counts as located when the principal parameter varies by less
#: than this fraction of the range while the truncation period grows (it converges
#: exponentially in the period).
HOMOCLINIC_SPREAD = 1e-6
#: HomCont run length (steps in the truncation period) and mesh intervals.
HOMOCLINIC_STEPS = 30
HOMOCLINIC_MESH = 100


def homoclinic_constants(model: Model, parameter: str, bounds: tuple[float, float],
                         period_tau: float, n_unstable: int) -> dict:
    """Constants of a HomCont run (IPS=9) from a long-period orbit: the homoclinic orbit to
    an equilibrium (solved for, IEQUIB=1) continued in ``parameter`` and the truncation
    period at fixed other parameters, so the parameter converges to its homoclinic value.
    ISTART=5 phase-shifts the orbit so that it starts and ends at the equilibrium."""
    return base_constants(model) | {
        "IPS": 9, "ISW": 1, "ICP": [parameter, "PERIOD"], "IEQUIB": 1, "ISTART": 5,
        "NUNSTAB": n_unstable, "NSTAB": model.n_states - n_unstable, "ITWIST": 0,
        "ILP": 0, "ISP": 0, "MXBF": 0, "NMX": HOMOCLINIC_STEPS, "NPR": HOMOCLINIC_STEPS,
        "IID": 2, "NTST": HOMOCLINIC_MESH, "NCOL": 4, "IAD": 3,
        "DS": 1e-3 * period_tau, "DSMIN": 1e-9, "DSMAX": 0.02 * period_tau,
        "EPSL": 1e-8, "EPSU": 1e-8, "EPSS": 1e-6, "ITMX": 30, "ITNW": 7, "NWTN": 3,
        "RL0": bounds[0], "RL1": bounds[1],
        "UZSTOP": {"PERIOD": [0.5 * period_tau, 4.0 * period_tau]},
    }


def locate_homoclinics(engine: Engine, name: str, ends: list[tuple[Branch, SpecialPoint]],
                       bounds: tuple[float, float], parameters: dict[str, float]
                       ) -> list[SpecialPoint]:
    """Try to locate the bracketed homoclinic ends of families with AUTO's HomCont (the runs
    in parallel), each restarted from its family's longest labelled orbit. On success a
    point's parameter becomes the HomCont value and its status "located"; otherwise it stays
    bracketed and its note says why."""
    points = [point for _, point in ends]
    runs = []
    for k, (family, point) in enumerate(ends):
        # both sides of a family started at an orbit can end at one: each run its own name
        side = sum(f.name == family.name for f, _ in ends[:k])
        planned = _homoclinic_run(engine, f"{name}/{family.name}.homoclinic"
                                  f"{side + 1 if side else ''}", family, point, bounds,
                                  parameters)
        if isinstance(planned, str):
            points[k] = replace(point, note=joined_notes(point.note, planned))
        else:
            runs.append((k, planned))
    outcomes = engine.run_many([spec for _, spec in runs])
    for (k, spec), outcome in zip(runs, outcomes, strict=True):
        points[k] = _homoclinic_verdict(outcome, points[k], spec.parameter_names[0], bounds,
                                        engine.model.time_scale)
    return points


def _homoclinic_run(engine: Engine, run: str, family: Branch, point: SpecialPoint,
                    bounds: tuple[float, float], parameters: dict[str, float]
                    ) -> RunSpec | str:
    """The HomCont run (named ``run``) for one homoclinic end, or why none is tried. A
    symmetric orbit passing the saddle twice per period (a pair of homoclinic loops of a
    symmetric model) is not: HomCont follows one loop."""
    model = engine.model
    parameter = family.parameter_names[0]
    labelled = [k for k in np.flatnonzero(family.label) if np.isfinite(family.period[k])]
    if not labelled:
        return "HomCont not tried: no stored orbit"
    row = max(labelled, key=lambda k: family.period[k])
    amplitudes = typical_amplitudes(model)
    if model.symmetric and np.allclose(family.state_max[row] / amplitudes,
                                       -family.state_min[row] / amplitudes, rtol=1e-6,
                                       atol=1e-9):
        return "HomCont not tried: the orbit is symmetric and passes the saddle twice per period"
    saddle_params = model.parameter_vector({**parameters, parameter: point.parameters[0]})
    n_unstable = int((np.linalg.eigvals(model.jacobian_numpy(point.state, saddle_params)).real
                      > 0).sum())
    if not n_unstable:
        return "HomCont not tried: no saddle"
    label = int(family.label[row])
    period_tau = float(family.period[row]) * model.time_scale
    return RunSpec(run,
                   homoclinic_constants(model, parameter, bounds, period_tau, n_unstable),
                   BranchKind.HOMOCLINIC, Origin(point.note), (parameter,),
                   restart=(engine.run_with_label(family.runs, label), label))


def _homoclinic_verdict(outcome: runner.RunOutcome, point: SpecialPoint, parameter: str,
                        bounds: tuple[float, float], time_scale: float) -> SpecialPoint:
    """The special point after a HomCont run: located if the parameter converged."""
    width = bounds[1] - bounds[0]
    values = periods = np.empty(0)
    if outcome.has_output:
        segments = parse_b(outcome.file("b").read_text(errors="replace"))
        if segments:
            values = np.concatenate([s.column(parameter) for s in segments])
            periods = np.concatenate([s.column("PERIOD") for s in segments])
    if len(values) < 5:
        return replace(point, note=joined_notes(
            point.note, f"HomCont (IPS=9) did not converge ({outcome.status}: "
            f"{outcome.message})"))
    tail = values[len(values) // 2:]
    spread = float(np.ptp(tail))
    if spread > HOMOCLINIC_SPREAD * width:
        return replace(point, note=joined_notes(
            point.note, f"HomCont (IPS=9): {parameter} did not settle (spread {spread:.2g} "
            f"over {len(tail)} points)"))
    value = float(values[-1])
    span = periods[len(values) // 2:] / time_scale
    return replace(point, parameters=np.array([value]), status=LocateStatus.LOCATED,
                   note=joined_notes(point.note, (
                       f"located by HomCont (IPS=9): {parameter} = {value:.10g}, spread "
                       f"{spread:.2g} while the truncation period runs "
                       f"{span.min():.4g}-{span.max():.4g} s")))

