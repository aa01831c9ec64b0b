"""Any plot kind drawn onto a given matplotlib Axes: the panels of a sheet (``whirl figures``)
and of a notebook.

:func:`draw` draws one result's figure of one kind into an Axes (a kind with several panels
of its own, ``linear`` and ``projections``, splits that Axes' place in its figure);
:func:`draw_overlay` draws several results' bifurcation diagrams into one Axes, one colour per
result, labelled by what differs between them (:func:`differing_labels`). What a kind picks
from a result (which continuation, branch, sweep, slice) is said by :class:`PanelChoice`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from ..errors import WhirlError
from ..results import Branch, ContinuationKind, ContinuationResult, LinearSweep, StudyResult
from .captions import Fixed, captions
from .key import drawn_points
from .kinds import overlay_kinds, panel_kinds, registry

if TYPE_CHECKING:
    from matplotlib.axes import Axes


@dataclass(frozen=True)
class PanelChoice:
    """What a panel takes from its result; None everywhere: the first that fits.

    ``continuation``: a continuation's name; ``branch``: a periodic branch's name (``phase``);
    ``state``: the state drawn (``bifurcation``, ``overhang``; a phase plane's y, x being the
    first state); ``sweep``: a linear sweep's parameter; ``slice``: a boundary slice index
    from 0 (``overhang``); ``orbits``: AUTO labels of the orbits a phase plane draws;
    ``simulation``: a simulation's name (``time_history``, ``hub_path``); ``hz``:
    frequencies in Hz; ``title``: replaces the study's title; ``cuts``: parameter values at
    which a ``phase`` panel draws every solution (:mod:`whirl_cli.plots.cuts`) and a
    ``bifurcation`` panel draws lines."""

    continuation: str | None = None
    branch: str | None = None
    state: str | None = None
    sweep: str | None = None
    slice: int | None = None
    orbits: tuple[int, ...] | None = None
    simulation: str | None = None
    hz: bool = False
    title: str | None = None
    cuts: tuple[float, ...] | None = None


def draw(result: StudyResult, kind: str, ax: Axes, choice: PanelChoice = PanelChoice()
         ) -> list[Axes]:
    """Draw ``result``'s figure of ``kind`` (:data:`PANEL_KINDS`) onto ``ax``; return the
    axes drawn on (``linear``, ``projections``, ``damping_multiples`` and ``time_history``
    replace ``ax`` by their own panels in its place). Titles name the study's fixed
    parameters (not the study: a figure's caption says what it shows) unless
    ``choice.title`` is set. A result without what the kind needs is a :class:`WhirlError`
    saying what is missing."""
    found = registry().get(kind)
    if found is None:
        raise WhirlError(f"unknown panel kind {kind!r}; choose from {', '.join(panel_kinds())}")
    return found.panel(drawn_points(result), ax, choice,
                       replace(captions(result), named=False))


def continuation_title(continuation: ContinuationResult, choice: PanelChoice, caption
                        ) -> str:
    """``choice.title``, else the study's title over what ``continuation`` does not vary."""
    if choice.title is not None:
        return choice.title
    varied = {n for b in continuation.branches for n in b.parameter_names}
    if continuation.explorations:
        varied.add(continuation.explorations[0].parameter)
    return caption.title(varied)


def replaced(ax: Axes, make) -> list[Axes]:
    """Remove ``ax`` and let ``make(region)`` draw into its place; the new axes."""
    figure, region = ax.figure, ax.get_subplotspec()
    before = set(figure.axes)
    ax.remove()
    make(region)
    return [a for a in figure.axes if a not in before]


def pick_continuation(result: StudyResult, name: str | None, kind: str = "bifurcation"
                      ) -> ContinuationResult:
    """The one-parameter continuation named ``name`` (None: the first one that has what
    ``kind`` draws: periodic branches for ``period``, freeplay amplitudes for ``amplitude``)."""
    one = [c for c in result.continuations if c.kind == ContinuationKind.ONE_PARAMETER]
    if name is not None:
        found = [c for c in one if c.name == name]
        if not found:
            raise WhirlError(f"{result.study_name}: no one-parameter continuation {name!r} "
                             f"(continuations: {', '.join(c.name for c in one) or 'none'})")
        return found[0]
    wanted = registry().get(kind)
    fits = wanted.fits if wanted is not None and wanted.fits is not None else None
    found = [c for c in one if fits is None or fits(c)]
    if not found:
        need = wanted.need if wanted is not None else "one-parameter continuation"
        raise WhirlError(f"{result.study_name}: nothing to draw as {kind}: no {need}")
    return found[0]


def pick_branch(result: StudyResult, choice: PanelChoice) -> Branch:
    """The periodic branch with stored orbits named ``choice.branch`` (None: the first)."""
    candidates = [b for c in result.continuations
                  if choice.continuation in (None, c.name) for b in c.branches
                  if b.is_periodic and b.orbits]
    if choice.branch is not None:
        candidates = [b for b in candidates if b.name == choice.branch]
    if not candidates:
        raise WhirlError(f"{result.study_name}: no periodic branch with stored orbits"
                         + (f" named {choice.branch!r}" if choice.branch else ""))
    return candidates[0]


def pick_sweep(result: StudyResult, parameter: str | None) -> LinearSweep:
    """The linear sweep of ``parameter`` (None: the first)."""
    sweeps = [s for s in result.linear_sweeps if parameter in (None, s.parameter)]
    if not sweeps:
        have = ", ".join(s.parameter for s in result.linear_sweeps) or "none"
        raise WhirlError(f"{result.study_name}: no linear sweep"
                         + (f" of {parameter!r}" if parameter else "") + f" (sweeps: {have})")
    return sweeps[0]


def differing_labels(results: Sequence[StudyResult]) -> list[str]:
    """One label per result naming the parameters whose values differ between them
    (``"K2 = 5 N m/rad^3"``; the study's name where nothing differs or a result has no stored
    parameter set)."""
    tables = [{p.name: p for p in r.parameters} for r in results]
    if not all(tables):
        return [r.study_name for r in results]
    names = [n for n in tables[0] if all(n in t for t in tables)
             and len({t[n].value for t in tables}) > 1]
    if not names:
        return [r.study_name for r in results]
    return [", ".join(str(Fixed(n, t[n].value, t[n].unit)) for n in names) for t in tables]


def draw_overlay(results: Sequence[StudyResult], kind: str, ax: Axes,
                 labels: Sequence[str | None] = (), choice: PanelChoice = PanelChoice(),
                 title: str | None = None) -> list[Axes]:
    """Several results' diagrams of ``kind`` (:data:`OVERLAY_KINDS`) on one Axes: for
    ``bifurcation`` each result in its own colour, stable branches solid and unstable dotted,
    special points with the markers of :data:`PLOT_KEY`; for ``damping_multiples`` each
    parameter in its own colour, each result in its own line style (the Axes split in
    damping and frequency); for ``law`` each result's stiffness law in its own colour and
    line style beside the linear spring. The legend names each result by
    ``labels`` (missing or None: :func:`differing_labels`). Title: ``title`` (None: the
    parameters off their datum that every result shares and the diagram does not vary)."""
    found = registry().get(kind)
    if found is None or found.overlay is None:
        raise WhirlError(f"kind {kind!r} cannot be overlaid; choose from "
                         f"{', '.join(overlay_kinds())}")
    if not results:
        raise WhirlError("an overlay needs at least one result")
    auto = differing_labels(results)
    names = [labels[k] if k < len(labels) and labels[k] else auto[k]
             for k in range(len(results))]
    return found.overlay([drawn_points(r) for r in results], names, ax, choice, title)


PANEL_KINDS = panel_kinds()
"""Kinds :func:`draw` accepts (:mod:`whirl_cli.plots.kinds`; ``overhang``: one slice of a
boundary, its unsafe intervals shaded; ``blowup``: the period of a family near its global
bifurcation, the fitted asymptote)."""

OVERLAY_KINDS = overlay_kinds()
"""Kinds :func:`draw_overlay` accepts."""
