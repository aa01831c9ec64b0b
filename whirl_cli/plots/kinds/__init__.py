"""The registry of plot kinds: one :class:`PlotKind` per kind, declared in a module of this
package beside the glue to its drawing code (a new kind is a new module here).

Everything that lists or dispatches plot kinds reads it: ``whirl plot --kind``, a study's
``plots:``, a sheet's panel kinds, :mod:`~whirl_cli.plots.files` and
:mod:`~whirl_cli.plots.panels`. The modules are light: they import the drawing code (numpy,
matplotlib) inside their functions, so the command line can list the kinds at start-up.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import TYPE_CHECKING, Any, NamedTuple

from ...kinds import ContinuationKind

if TYPE_CHECKING:
    from ...results import ContinuationResult, StudyResult
    from ..captions import Captions
    from ..files import View

#: (file name, figure factory): one figure a kind writes, drawn when the factory is called.
FigureJob = tuple[str, Callable[[], Any]]


class Figures(NamedTuple):
    """What a kind's files are drawn from: the result (without the special points flagged as
    artefacts unless the view asks for them), the file names' stem, the state bifurcation
    diagrams draw (None: the first), the view, and the study's captions (read when first
    called)."""

    result: StudyResult
    stem: str
    state: str | None
    view: View
    caption: Callable[[], Captions]

    def one_parameter(self) -> list[ContinuationResult]:
        """The result's one-parameter continuations."""
        return [c for c in self.result.continuations if c.kind == ContinuationKind.ONE_PARAMETER]

    def title(self, continuation: ContinuationResult) -> str:
        """The study's title over the parameters ``continuation`` does not vary."""
        return self.caption().title({name for branch in continuation.branches
                                     for name in branch.parameter_names})


class PlotKind(NamedTuple):
    """One plot kind.

    ``rank``: its place in every list of kinds (the order of the ``plots:`` and ``--kind``
    choices, and of a result's figures). ``missing(result)``: what ``result`` lacks to draw the
    kind's files, a sentence ("" if nothing). ``figures(figures)``: the (file name, figure
    factory) pairs of its files. Both None: a panel-only kind (no files of its own).
    ``panel(result, ax, choice, caption)``: draws one panel, returns the axes drawn on;
    ``overlay(results, labels, ax, choice, title)``: several results on one panel (None: the
    kind cannot be overlaid). ``fits(continuation)``: whether a one-parameter continuation has
    what the kind draws (a panel picks the first that fits), ``need`` naming it. (Named
    tuples, not dataclasses: the command line builds these classes at start-up.)"""

    name: str
    rank: int
    panel: Callable[..., list]
    missing: Callable[[StudyResult], str] | None = None
    figures: Callable[[Figures], list[FigureJob]] | None = None
    overlay: Callable[..., list] | None = None
    fits: Callable[[ContinuationResult], bool] | None = None
    need: str = "one-parameter continuation"

    @property
    def has_files(self) -> bool:
        """Whether the kind writes files (a study's ``plots:``, ``whirl plot --kind``)."""
        return self.figures is not None


@cache
def registry() -> dict[str, PlotKind]:
    """Every kind declared in this package's modules, by name, in rank order."""
    from ...registries import by_rank, declared

    return by_rank(declared(__name__, __path__, PlotKind, "plot kind"))


def get(name: str) -> PlotKind | None:
    """The kind named ``name`` (None: no such kind)."""
    return registry().get(name)


def plot_kinds() -> tuple[str, ...]:
    """The kinds that write files, in rank order."""
    return tuple(name for name, kind in registry().items() if kind.has_files)


def panel_kinds() -> tuple[str, ...]:
    """Every kind (each draws a panel), in rank order."""
    return tuple(registry())


def overlay_kinds() -> tuple[str, ...]:
    """The kinds that overlay several results, in rank order."""
    return tuple(name for name, kind in registry().items() if kind.overlay is not None)
