"""Panel kinds only sheets draw: thesis figures that no plot kind of a study makes
(``whirl_snapshots``: :func:`whirl_cli.plots.simulations.whirl_snapshots`)."""

from __future__ import annotations

from dataclasses import replace

from ..errors import WhirlError


def _simulation(result, name: str | None):
    """The simulation named ``name`` (None: the first)."""
    found = [s for s in result.simulations if name in (None, s.name)]
    if not found:
        have = ", ".join(s.name for s in result.simulations) or "none"
        raise WhirlError(f"{result.study_name}: no simulation"
                         + (f" {name!r}" if name else "") + f" (simulations: {have})")
    return found[0]


def _snapshots_panel(result, ax, choice) -> list:
    from ..plots.captions import captions
    from ..plots.simulations import whirl_snapshots

    simulation = _simulation(result, choice.simulation)
    title = choice.title or replace(captions(result), named=False).simulation_title(
        simulation)
    whirl_snapshots(simulation, ax=ax, title=title)
    return [ax]


SHEET_PANELS = {"whirl_snapshots": _snapshots_panel}
"""Sheet-only kind -> its drawer (result, axes, choice) -> the axes drawn on."""

SHEET_KINDS = tuple(SHEET_PANELS)
