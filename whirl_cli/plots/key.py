"""The plot key (thesis Table 2.1) and what every figure shares: styles, stability segments,
units and axis labels, new figures on an Agg canvas, legend handles.

:data:`PLOT_KEY` has one entry per semantic style, with the matplotlib ``Line2D`` keyword
arguments that draw it and its legend label. Stability maps (thesis figures 3.13, 3.15, 3.28,
3.29) use :data:`BOUNDARY_KEY` in the same way.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Iterator
from dataclasses import replace
from functools import cache
from typing import TYPE_CHECKING

import numpy as np

from ..results import BranchKind, LocateStatus, PointType, Spacing, StudyResult
from ..units import axis_label as _plain_axis_label
from ..units import display_unit  # noqa: F401  (re-exported: plots use them)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

BLACK = "black"
_MARKER_SIZE = 8.0

PLOT_KEY: dict[str, dict[str, object]] = {
    # branches
    "stable_equilibrium": {"color": "green", "linestyle": "-", "label": "stable equilibrium"},
    "unstable_equilibrium": {"color": "magenta", "linestyle": "--",
                             "label": "unstable equilibrium"},
    # a line of equilibria at one parameter value (a linear model at its branch point): each
    # has a zero eigenvalue, so AUTO's stability flag flickers along it
    "neutral_equilibrium": {"color": "grey", "linestyle": "-.",
                            "label": "neutral equilibria (zero eigenvalue)"},
    "stable_periodic": {"color": "blue", "linestyle": "-", "label": "stable periodic"},
    "unstable_periodic": {"color": "red", "linestyle": ":", "label": "unstable periodic"},
    # special points
    "hopf": {"marker": "s", "markerfacecolor": "none", "markeredgecolor": BLACK,
             "label": "Hopf (HB)"},
    "branch_point": {"marker": "*", "markerfacecolor": BLACK, "markeredgecolor": BLACK,
                     "label": "branch point (BP, BPC)"},
    "fold": {"marker": "o", "markerfacecolor": BLACK, "markeredgecolor": BLACK,
             "label": "fold (LP, LPC)"},
    # the folds of a family snaking towards a global bifurcation (plots.markers.draw_cluster)
    "fold_cluster": {"marker": "o", "markerfacecolor": BLACK, "markeredgecolor": BLACK,
                     "label": "folds of a snaking family (LPC): span, \u00d7count"},
    "homoclinic": {"marker": "^", "markerfacecolor": BLACK, "markeredgecolor": BLACK,
                   "label": "homoclinic"},
    "heteroclinic": {"marker": "^", "markerfacecolor": "none", "markeredgecolor": BLACK,
                     "label": "heteroclinic"},
    "torus": {"marker": "o", "markerfacecolor": "none", "markeredgecolor": BLACK,
              "label": "torus (TR)"},
    "period_doubling": {"marker": "D", "markerfacecolor": BLACK, "markeredgecolor": BLACK,
                        "label": "period doubling (PD)"},
}
"""Semantic style -> Line2D keyword arguments (including ``label``). Do not mutate."""

MARKER_STYLE: dict[PointType, str] = {
    PointType.HB: "hopf",
    PointType.BP: "branch_point",
    PointType.BPC: "branch_point",
    PointType.LP: "fold",
    PointType.LPC: "fold",
    PointType.HOMOCLINIC: "homoclinic",
    PointType.HETEROCLINIC: "heteroclinic",
    PointType.TR: "torus",
    PointType.PD: "period_doubling",
}
"""Point type -> key of :data:`PLOT_KEY`; types not listed (REGULAR, RG, UZ, EP, MX, ...) get
no marker."""

UNSAFE_LABEL = "unsafe (overhang)"
BOUNDARY_KEY: dict[str, dict[str, object]] = {
    # linear analysis over a grid
    "linearly_unstable": {"color": "lightgrey", "label": "linearly unstable"},
    "linear_flutter": {"color": BLACK, "linestyle": "-", "linewidth": 0.8,
                       "label": "linear boundary (flutter)"},
    "linear_divergence": {"color": BLACK, "linestyle": "--", "linewidth": 0.8,
                          "label": "linear boundary (divergence)"},
    # loci of the two-parameter continuation, by Boundary.loci kind
    "hopf": {"color": "darkblue", "linestyle": "-", "linewidth": 1.5,
             "label": "Hopf locus (flutter)"},
    "branch_point": {"color": BLACK, "linestyle": "--", "linewidth": 1.5,
                     "label": "branch point locus (divergence)"},
    "fold": {"color": "grey", "linestyle": "-.", "linewidth": 1.5, "label": "fold locus (LP)"},
    "fold_of_cycles": {"color": "orange", "linestyle": "-", "linewidth": 1.5,
                       "label": "fold of cycles locus (LPC)"},
    # the thesis key's torus mark (a hollow circle) strung along a dotted line
    "torus": {"color": "green", "linestyle": ":", "linewidth": 1.5, "marker": "o",
              "markerfacecolor": "none", "markeredgecolor": "green", "markersize": 5,
              "markevery": 0.08, "label": "torus locus (TR)"},
    # the unsafe region
    "unsafe": {"color": "red", "alpha": 0.5, "label": UNSAFE_LABEL},
}
"""Stability-map style -> keyword arguments (``Line2D`` for lines, patch colour/alpha for the
"linearly_unstable" shading and the "unsafe" polygons), including the legend ``label``. The
locus entries are keyed by the kinds of :attr:`Boundary.loci`. Do not mutate."""

PLOTTED_KINDS = (BranchKind.EQUILIBRIUM, BranchKind.PERIODIC)


def branch_style(kind: str, stable: bool) -> str:
    """Key of :data:`PLOT_KEY` for a branch piece of ``kind`` (a :class:`BranchKind`)."""
    family = "periodic" if kind == BranchKind.PERIODIC else "equilibrium"
    return f"{'stable' if stable else 'unstable'}_{family}"


def is_neutral_line(x: np.ndarray, stable: np.ndarray) -> bool:
    """True for a line of equilibria at one parameter value (``x`` constant to 1e-9 of its
    size) whose stability flag takes both values: equilibria with a zero eigenvalue, neutral,
    drawn as one line (not as flickering stable and unstable runs)."""
    x = np.asarray(x, dtype=float)
    stable = np.asarray(stable, dtype=bool)
    return bool(len(x) > 1 and np.ptp(x) <= 1e-9 * max(1.0, float(np.abs(x).max()))
                and stable.any() and not stable.all())


def stability_segments(x: np.ndarray, y: np.ndarray, stable: np.ndarray,
                       known: np.ndarray | None = None
                       ) -> list[tuple[np.ndarray, np.ndarray, bool]]:
    """Split a curve into runs of equal stability, ``[(x_i, y_i, stable_i), ...]`` in order.

    The first point of each new run (the switching point) also ends the previous run, so drawn
    pieces join without gaps. Points whose stability is not ``known`` (e.g. the first point of
    a periodic family, where AUTO printed no multipliers) have none of their own: each joins
    the run before it (leading ones the run after), so they never make a stub of their own;
    with no point known, ``stable`` is drawn as it is. Units are those of ``x`` and ``y``;
    empty input gives ``[]``.
    """
    x = np.asarray(x)
    y = np.asarray(y)
    stable = np.asarray(stable, dtype=bool)
    if not (x.shape == y.shape == stable.shape) or x.ndim != 1:
        raise ValueError(f"x, y and stable must be 1-D of equal length, got shapes "
                         f"{x.shape}, {y.shape}, {stable.shape}")
    if len(x) == 0:
        return []
    if known is not None and np.asarray(known, dtype=bool).any():
        known = np.asarray(known, dtype=bool)
        if known.shape != stable.shape:
            raise ValueError(f"known must have the shape of stable {stable.shape}, got "
                             f"{known.shape}")
        # the stability of the nearest known point before (the first known one for leading
        # unknown points)
        last_known = np.maximum.accumulate(np.where(known, np.arange(len(x)), -1))
        stable = stable[np.where(last_known >= 0, last_known, np.flatnonzero(known)[0])]
    starts = np.concatenate(([0], np.flatnonzero(stable[1:] != stable[:-1]) + 1))
    ends = np.append(starts[1:] + 1, len(x))  # inclusive of the next run's first point
    return [(x[a:b], y[a:b], bool(stable[a])) for a, b in zip(starts, ends, strict=True)]


def stability_curves(x: np.ndarray, y: np.ndarray, stable: np.ndarray,
                     known: np.ndarray | None = None
                     ) -> list[tuple[np.ndarray, np.ndarray, bool]]:
    """The runs of :func:`stability_segments` joined by stability: at most two curves, the
    stable and the unstable one, in the order they first appear, the runs of each separated by
    a NaN (a break in a matplotlib line). Drawn as one line each, a branch whose stability
    flickers from point to point (a neutral family, e.g. the equilibria of a linear model at
    its branch point) costs two artists instead of hundreds (linear_case1's diagram: 415 lines
    and 0.27 s to draw, now 7 and 0.10 s)."""
    runs: dict[bool, list[tuple[np.ndarray, np.ndarray]]] = {}
    for xs, ys, flag in stability_segments(x, y, stable, known):
        runs.setdefault(flag, []).append((xs, ys))
    gap = np.array([np.nan])
    return [(_broken([xs for xs, _ in pieces], gap), _broken([ys for _, ys in pieces], gap),
             flag) for flag, pieces in runs.items()]


def _broken(pieces: list[np.ndarray], gap: np.ndarray) -> np.ndarray:
    """``pieces`` end to end with ``gap`` between each two (float)."""
    if len(pieces) == 1:
        return pieces[0]
    return np.concatenate([part for piece in pieces for part in (piece, gap)][:-1])


def new_figure(**kwargs) -> Figure:
    """A Figure on an Agg canvas, outside pyplot (needs no display, no closing), laid out by
    :func:`_settled_layout_class` (constrained layout, its axes positions rounded) and drawn
    with fresh font objects: matplotlib's cached ones keep state between texts, so an axes edge
    could move by a pixel after other figures were drawn in the process. A figure's pixels
    then depend only on what it shows, not on the figures before it (the order in which
    ``whirl figures`` draws its sheets, or the ``--jobs`` that spread plots over processes)."""
    from matplotlib import font_manager
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fresh = getattr(getattr(font_manager, "_get_font", None), "cache_clear", None)
    if fresh is not None:  # a private cache (matplotlib 3.8-3.11): absent, nothing to reset
        fresh()
    layout = kwargs.pop("layout", "constrained")  # no clipped labels, no bbox pass
    engine = _settled_layout_class()() if layout == "constrained" else layout
    figure = Figure(layout=engine, **kwargs)
    FigureCanvasAgg(figure)
    return figure


#: Decimals of the figure fraction to which :func:`_settled_layout_class` rounds axes
#: positions, and that step (a millionth of a pixel at the widest sheet, 3600 pixels).
_POSITION_DIGITS = 9
POSITION_STEP = 10.0 ** -_POSITION_DIGITS


@cache
def _settled_layout_class():
    """The class of a constrained layout whose axes positions are rounded to
    :data:`POSITION_STEP` (made once, matplotlib imported here).
    kiwisolver, which solves the layout, orders its variables by their memory addresses, so
    its solution varies in the last bits of a double from one drawing of the same figure to
    the next (after a garbage collection, after other figures), enough to move an axes edge
    by a pixel. Rounded, the same figure gives the same pixels."""
    from matplotlib.layout_engine import ConstrainedLayoutEngine

    class SettledLayout(ConstrainedLayoutEngine):
        def execute(self, fig):
            info = super().execute(fig)
            _round_positions(fig)
            return info

    return SettledLayout


def _round_positions(figure) -> None:
    """Round the position of every axes a layout places (``figure``'s and its subfigures')
    to :data:`POSITION_STEP`, leaving it in the layout."""
    for ax in figure.axes:
        if ax.get_in_layout():
            ax.set_position([round(v, _POSITION_DIGITS)
                             for v in ax.get_position(original=True).bounds], which="both")
            ax.set_in_layout(True)  # set_position takes it out
    for sub in getattr(figure, "subfigs", ()):
        _round_positions(sub)


#: Greek letters a quantity's name may spell out, drawn as mathtext symbols.
_GREEK = ("alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta", "lambda", "mu",
          "nu", "xi", "pi", "rho", "sigma", "tau", "phi", "chi", "psi", "omega", "Omega",
          "Delta", "Theta", "Lambda", "Phi", "Psi")
_NAME_RE = re.compile(r"([A-Za-z]+)(?:_([A-Za-z]+|\d+)|(\d+))?")


def symbol(name: str) -> str:
    """A name with a Greek letter as mathtext: ``theta`` -> ``$\\theta$``, ``K_psi`` ->
    ``$K_{\\psi}$``, ``theta_dot`` -> ``$\\dot{\\theta}$``, ``beta_1`` -> ``$\\beta_{1}$``;
    any other name unchanged (``K1``, ``V``, ``hub y``)."""
    stem = name.removesuffix("_dot")
    dot = stem != name
    match = _NAME_RE.fullmatch(stem)
    if match is None:
        return name
    base, sub, digits = match.groups()
    if base not in _GREEK and (len(base) > 1 or sub not in _GREEK):
        return name
    text = f"\\{base}" if base in _GREEK else base
    if dot:
        text = f"\\dot{{{text}}}"
    index = sub if sub is not None else digits
    if index is not None:
        text += f"_{{\\{index}}}" if index in _GREEK else f"_{{{index}}}"
    return f"${text}$"


def axis_label(name: str, unit: str) -> str:
    """``"<symbol> [unit]"``: :func:`symbol` of the name (a trailing ``(max)`` or the like
    kept as text), ``[-]`` for dimensionless quantities."""
    head, sep, tail = name.partition(" ")
    return _plain_axis_label(symbol(head) + sep + tail, unit)


DECADES = 20.0
"""An axis whose values are all positive and whose largest is more than this many times its
smallest is drawn on a log scale (:func:`log_scale_if_decades`)."""


def spans_decades(values, factor: float = DECADES) -> bool:
    """True if the finite ``values`` are all positive and max/min exceeds ``factor``."""
    values = np.asarray(values, dtype=float).ravel()
    values = values[np.isfinite(values)]
    return bool(values.size and values.min() > 0 and values.max() > factor * values.min())


def log_scale_if_decades(ax: Axes, axis: str, values, spacing: Spacing = Spacing.LINEAR
                         ) -> bool:
    """Put ``ax``'s ``axis`` ("x" or "y") on a log scale if ``values`` (what it shows)
    :func:`span decades <spans_decades>`, or were sampled with a log ``spacing`` (all > 0);
    True if it did."""
    if not (spans_decades(values) or spacing == Spacing.LOG and spans_decades(values, 1.0)):
        return False
    getattr(ax, f"set_{axis}scale")("log")
    return True


MARKER_ON_TOP: dict[str, dict[str, object]] = {
    "homoclinic": {"zorder": 5, "markersize": 1.4 * _MARKER_SIZE, "markeredgecolor": "white",
                   "markeredgewidth": 0.8},
    "heteroclinic": {"zorder": 5, "markersize": 1.4 * _MARKER_SIZE, "markeredgewidth": 1.5},
    "torus": {"zorder": 5, "markersize": 1.4 * _MARKER_SIZE, "markeredgewidth": 1.5},
}
"""Markers drawn above the folds and Hopf points (zorder 3) that often sit beside them, and
larger: the global points (the filled one edged in white) and the torus point as a ring, so
that a fold at the same place neither hides them nor is hidden."""


def plot_styled(ax: Axes, x: np.ndarray, y: np.ndarray, style: str, first: dict) -> None:
    """Plot with ``PLOT_KEY[style]``; remember the first artist of each style for the legend."""
    kwargs = dict(PLOT_KEY[style])
    kwargs["label"] = "_" + str(kwargs["label"])  # legend is assembled from ``first``
    if "marker" in kwargs:
        kwargs.update(linestyle="none", markersize=_MARKER_SIZE, zorder=3)
        kwargs.update(MARKER_ON_TOP.get(style, {}))
    (line,) = ax.plot(x, y, **kwargs)
    first.setdefault(style, line)


def colour_cycle() -> Iterator[str]:
    """Endless cycle of the default matplotlib line colours."""
    from matplotlib import rcParams

    return itertools.cycle(rcParams["axes.prop_cycle"].by_key().get("color", ["C0"]))


#: Colours of the lines a figure draws beyond its key (orbits at cuts, simulations): none is
#: a colour of :data:`PLOT_KEY`, and their lightness differs (they survive greyscale better
#: than a hue cycle).
FIGURE_COLOURS = ("#E69F00", "#6A3D9A", "#17BECF", "#8C564B", "#CC79A7", "#393B79",
                  "#B8860B", "#56B4E9", "#D55E00", "#0072B2", "#BCBD22", "#7F7F7F")


def next_colour(figure) -> str:
    """The next of :data:`FIGURE_COLOURS` in ``figure``: no colour is taken twice in one
    figure (they cycle only after all are taken)."""
    taken = getattr(figure, "_whirl_colours_taken", 0)
    figure._whirl_colours_taken = taken + 1
    return FIGURE_COLOURS[taken % len(FIGURE_COLOURS)]


_ENTRY_EMS = 2.0 + 0.8 + 2.0  # a legend entry's handle, its gap to the text, the column gap


def legend_columns(labels: list[str], width: float) -> int:
    """How many columns of ``labels`` (small text, at the current font size) fit in 95 % of
    ``width`` inches, each as wide as the widest entry (measured as its glyphs' outlines)."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextToPath

    font = FontProperties(size="small")
    points = font.get_size_in_points()
    measure = TextToPath().get_text_width_height_descent
    widest = max(measure(label, font, ismath=label.count("$") >= 2)[0] for label in labels)
    entry = (widest + _ENTRY_EMS * points) / 72.0
    return max(1, min(len(labels), int(0.95 * width / entry)))


def patch_proxy(style: dict[str, object]):
    """A legend handle for a filled area of ``style``'s colour (and alpha)."""
    from matplotlib.patches import Patch

    return Patch(facecolor=style["color"], alpha=style.get("alpha"), label=style["label"])


def drawn_points(result: StudyResult, artefacts: bool = False) -> StudyResult:
    """``result`` with only the special points a figure marks: never one whirl's own check
    rejected (AUTO labelled it, but it is not that point), nor, unless ``artefacts``, one
    flagged as an artefact of a smoothed law."""
    def marked(point) -> bool:
        return point.status != LocateStatus.REJECTED and (artefacts or not point.artefact)

    return replace(result, continuations=tuple(
        replace(c, special_points=tuple(p for p in c.special_points if marked(p)))
        for c in result.continuations))
