"""Phase planes at cuts of a one-parameter diagram (thesis figures 3.16, 3.24, 3.26): at each
chosen parameter value every family present there, equilibria as crosses and limit cycles as
closed loops with an arrow for the direction of motion, the second dof horizontal and the
first vertical (the thesis's psi-theta plane); the cuts drawn as lines on the diagram.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import WhirlError
from ..results import Branch, BranchKind, ContinuationResult, PointType
from .key import BLACK, axis_label, display_unit, next_colour, symbol

if TYPE_CHECKING:
    from matplotlib.axes import Axes

_GLOBAL = {PointType.HOMOCLINIC: "homoclinic", PointType.HETEROCLINIC: "heteroclinic"}
_EXACT = 1e-6  # an orbit stored at a cut (orbits_at): within this fraction of the span
_NEAR = 2e-3  # a cut at a global bifurcation: within this fraction of the span
_LETTERS = "abcdefghijklmnopqrstuvwxyz"
_STABLE_POINT = {"marker": "x", "markersize": 8, "markeredgewidth": 1.8, "color": BLACK,
                 "label": "stable fixed point (cross)"}
_UNSTABLE_POINT = {"marker": "x", "markersize": 7, "markeredgewidth": 1.0, "color": "grey",
                   "label": "unstable fixed point (cross)"}
_SADDLE_POINT = {"marker": "X", "markersize": 10, "markeredgewidth": 0.8, "color": "dimgrey",
                 "markeredgecolor": BLACK, "label": "saddle (cross, a real eigenvalue > 0)"}
_REAL = 1e-9  # |Im| of an eigenvalue counted as real, relative to its modulus


@dataclass(frozen=True)
class Solution:
    """One solution at a cut: its family (branch name), kind (a :class:`BranchKind`),
    stability (None: unknown) and states, SI (one row for an equilibrium, the orbit's
    profile for a limit cycle)."""

    family: str
    kind: str
    stable: bool | None
    states: np.ndarray
    parent: str = ""  # " of <branch>" where a periodic family was born on another branch
    saddle: bool = False  # an equilibrium with a real eigenvalue > 0 and one of Re < 0


def is_saddle(eigenvalues: np.ndarray) -> bool:
    """An equilibrium's eigenvalues [1/s] have a real one > 0 and one with Re < 0 (NaN:
    not known, False)."""
    roots = np.asarray(eigenvalues, dtype=complex)
    if not np.all(np.isfinite(roots)):
        return False
    real = np.abs(roots.imag) <= _REAL * np.maximum(np.abs(roots), 1.0)
    return bool(np.any(real & (roots.real > 0)) and np.any(roots.real < 0))


def _span(continuation: ContinuationResult) -> float:
    values = [b.parameters[:, 0] for b in continuation.branches if len(b)]
    return float(np.ptp(np.concatenate(values))) if values else 0.0


def global_point(continuation: ContinuationResult, value: float) -> str | None:
    """"homoclinic" or "heteroclinic" if a global bifurcation of ``continuation`` lies at
    ``value`` (to :data:`_NEAR` of the span), else None."""
    near = _NEAR * _span(continuation)
    for point in continuation.special_points:
        kind = _GLOBAL.get(_type(point.point_type))
        if kind and abs(float(point.parameters[0]) - value) <= near:
            return kind
    return None


def _type(code: int) -> PointType | None:
    try:
        return PointType(int(code))
    except ValueError:
        return None


def solutions_at(continuation: ContinuationResult, value: float) -> list[Solution]:
    """Every solution of ``continuation`` at the parameter value ``value``: each crossing
    of an equilibrium branch (states interpolated between its rows, stability of the nearer
    row), and each limit cycle stored there (``orbits_at``); at a global bifurcation
    (:func:`global_point`) the stored orbit of longest period of each family ending in it
    (the others' stored there)."""
    span = _span(continuation)
    found: list[Solution] = []
    for branch in continuation.branches:
        if branch.kind == BranchKind.EQUILIBRIUM:
            found += _equilibria_at(branch, value)
    at_global = global_point(continuation, value) is not None
    for branch in continuation.branches:
        if not branch.is_periodic:
            continue
        longest = _longest_orbit(continuation, branch, value, _NEAR * span) \
            if at_global else []
        found += longest or [_cycle(branch, o) for o in branch.orbits
                             if abs(float(o.parameters[0]) - value) <= _EXACT * span]
    return found


def _equilibria_at(branch: Branch, value: float) -> list[Solution]:
    """Crossings of ``value`` by the equilibrium ``branch`` (each once: a row exactly at it
    is counted with the segment it starts)."""
    x = branch.parameters[:, 0]
    states = branch.state_max
    out = []
    for k in range(len(x) - 1):
        a, b = x[k] - value, x[k + 1] - value
        if a == 0.0 or (a * b < 0.0):
            w = 0.0 if a == 0.0 else a / (a - b)
            row = k if w < 0.5 else k + 1
            stable = bool(branch.stable[row]) if branch.stability_known[row] else None
            out.append(Solution(branch.name, branch.kind, stable,
                                (states[k] + w * (states[k + 1] - states[k]))[None, :],
                                saddle=is_saddle(branch.eigenvalues[row])))
    if len(x) and x[-1] == value:
        stable = bool(branch.stable[-1]) if branch.stability_known[-1] else None
        out.append(Solution(branch.name, branch.kind, stable, states[-1][None, :],
                            saddle=is_saddle(branch.eigenvalues[-1])))
    return out


def _cycle(branch: Branch, orbit) -> Solution:
    row = orbit.index
    known = 0 <= row < len(branch) and bool(branch.stability_known[row])
    parent = branch.origin.branch
    return Solution(branch.name, branch.kind, bool(branch.stable[row]) if known else None,
                    np.asarray(orbit.states, dtype=float), f" of {parent}" if parent else "")


def _longest_orbit(continuation: ContinuationResult, branch: Branch, value: float,
                   near: float) -> list[Solution]:
    """The stored orbit of longest period of ``branch`` within ``near`` of ``value``, if a
    global bifurcation of the branch lies there."""
    ends_there = any(p.branch == branch.name and _type(p.point_type) in _GLOBAL
                     and abs(float(p.parameters[0]) - value) <= near
                     for p in continuation.special_points)
    orbits = [o for o in branch.orbits if abs(float(o.parameters[0]) - value) <= near]
    if not ends_there or not orbits:
        return []
    return [_cycle(branch, max(orbits, key=lambda o: float(o.period)))]


def cut_title(continuation: ContinuationResult, k: int, value: float) -> str:
    """``"(a)\\nK_1 = -0.2 N m/rad"``, with "at the homoclinic" where one lies there."""
    ref = next((b for b in continuation.branches if len(b)), None)
    name = ref.parameter_names[0] if ref else "p"
    unit = ref.parameter_units[0] if ref else ""
    kind = global_point(continuation, value)
    where = f" at the {kind}" if kind else ""
    return f"({_LETTERS[k % 26]}){where}\n{symbol(name)} = {value:.4g} {unit}".rstrip()


def phase_cut(continuation: ContinuationResult, value: float, ax: Axes, title: str = "",
              degrees: bool = True) -> int:
    """Every solution at ``value`` (:func:`solutions_at`) on ``ax``: the second dof
    horizontal, the first vertical, equal aspect; equilibria as crosses (black stable, grey
    unstable, a filled cross for a saddle: :func:`is_saddle`), each limit cycle closed in a
    colour of its own in the figure (:func:`~whirl_cli.plots.key.next_colour`), solid if
    stable and dotted if not, with an arrow for its direction of motion, labelled by family
    and stability; the larger cycles above the smaller, and a cycle that runs along one
    above it (a secondary cycle beside the main one at a homoclinic) a wide pale band
    around it. Returns the number
    of limit cycles drawn."""
    ref = next((b for b in continuation.branches if len(b)), None)
    if ref is None or len(ref.state_names) < 2:
        raise WhirlError(f"{continuation.name}: a phase plane needs two states")
    iy, ix = 0, 1  # first dof vertical, second horizontal
    fx, unit_x = display_unit(ref.state_units[ix], degrees)
    fy, unit_y = display_unit(ref.state_units[iy], degrees)
    cycles = 0
    points: dict[bool | str | None, list[np.ndarray]] = {}
    letter = title.split(")")[0] + ") " if title.startswith("(") else ""
    loops = []
    for solution in solutions_at(continuation, value):
        xs, ys = solution.states[:, ix] * fx, solution.states[:, iy] * fy
        if solution.kind == BranchKind.EQUILIBRIUM:
            kind = "saddle" if solution.saddle else solution.stable
            points.setdefault(kind, []).append(np.array([xs[0], ys[0]]))
            continue
        loops.append((solution, np.column_stack([np.append(xs, xs[:1]),
                                                 np.append(ys, ys[:1])])))
    loops.sort(key=lambda loop: _box_area(loop[1]))  # the largest (the main cycle) on top
    for rank, (solution, xy) in enumerate(loops):
        cycles += 1
        status = {True: "stable", False: "unstable", None: "stability unknown"}[solution.stable]
        colour = next_colour(ax.figure)
        under = any(_runs_along(xy, above) for _, above in loops[rank + 1:])
        over = any(_runs_along(below, xy) for _, below in loops[:rank])
        ax.plot(xy[:, 0], xy[:, 1], color=colour, zorder=2 + 0.01 * rank,
                linestyle={True: "-", False: ":", None: "--"}[solution.stable],
                label=f"{letter}limit cycle {solution.family}{solution.parent} ({status})",
                **(_UNDER_CYCLE if under else {"linewidth": 2.0 if over else 1.4}))
        _arrow(ax, xy[:, 0], xy[:, 1], colour)
    for stable, style in ((True, _STABLE_POINT), (False, _UNSTABLE_POINT),
                          (None, _UNSTABLE_POINT), ("saddle", _SADDLE_POINT)):
        if stable in points:
            xy = np.array(points[stable])
            ax.plot(xy[:, 0], xy[:, 1], linestyle="none", zorder=4, **style)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="x-small")
    ax.set_xlabel(axis_label(ref.state_names[ix], unit_x))
    ax.set_ylabel(axis_label(ref.state_names[iy], unit_y))
    ax.set_aspect("equal", adjustable="box")
    ax.set_title(title, fontsize="medium")
    return cycles


#: A limit cycle that runs along one drawn above it (the secondary cycles beside the main
#: one at a homoclinic): a wide pale band, the cycle above it drawn inside, a little wider
#: than the others (it reads in greyscale over the band).
_UNDER_CYCLE = {"linewidth": 4.5, "alpha": 0.4, "solid_capstyle": "butt"}
_ALONG = 0.02  # a vertex within this fraction of the loops' extent lies on the other loop
_ALONG_SHARE = 0.25  # a loop with this share of its vertices on another runs along it


def _box_area(xy: np.ndarray) -> float:
    """The area of the box around a loop's vertices."""
    return float(np.ptp(xy[:, 0]) * np.ptp(xy[:, 1]))


def _runs_along(xy: np.ndarray, other: np.ndarray) -> bool:
    """Whether at least :data:`_ALONG_SHARE` of the loop ``xy``'s vertices lie within
    :data:`_ALONG` of both loops' extent of a vertex of ``other``."""
    both = np.vstack([xy, other])
    reach = _ALONG * float(np.max(np.ptp(both, axis=0)))
    gaps = np.linalg.norm(xy[:, None, :] - other[None, :, :], axis=2).min(axis=1)
    return bool(np.mean(gaps <= reach) >= _ALONG_SHARE)


def _arrow(ax: Axes, xs: np.ndarray, ys: np.ndarray, colour: str) -> None:
    """An arrow head on the loop at its point of largest x, pointing along the motion."""
    if len(xs) < 3:
        return
    k = int(np.argmax(xs[:-1]))
    j = (k + max(1, len(xs) // 40)) % (len(xs) - 1)
    ax.annotate("", xy=(xs[j], ys[j]), xytext=(xs[k], ys[k]),
                arrowprops={"arrowstyle": "-|>", "color": colour, "lw": 1.2,
                            "mutation_scale": 12}, annotation_clip=False)


def phase_cuts(continuation: ContinuationResult, values: Sequence[float], region,
               degrees: bool = True) -> list[Axes]:
    """One :func:`phase_cut` per value on a grid in ``region`` (a SubplotSpec; one row, or
    two columns for four or more cuts where the region is not wide enough:
    :func:`grid_columns`), sharing both axes."""
    if not values:
        raise WhirlError("no cuts to draw")
    columns = grid_columns(len(values), region)
    rows = -(-len(values) // columns)
    axes = region.subgridspec(rows, columns).subplots(sharex=True, sharey=True,
                                                      squeeze=False).ravel()
    for k, (ax, value) in enumerate(zip(axes, values, strict=False)):
        phase_cut(continuation, float(value), ax, cut_title(continuation, k, float(value)),
                  degrees)
    for ax in axes[len(values):]:
        ax.remove()
    return list(axes[:len(values)])


#: Least width over height of a panel in a row of panels (the phase cuts are drawn with equal
#: aspect: narrower, they collapse).
ROW_ASPECT = 0.5


def grid_columns(count: int, region) -> int:
    """Columns of a grid of ``count`` small panels in ``region`` (a SubplotSpec): one row if
    fewer than four, or if the region is wide enough for a row of panels at least
    :data:`ROW_ASPECT` as wide as high; else two."""
    if count < 4:
        return count
    figure = region.get_gridspec().figure
    box = region.get_position(figure)
    width, height = figure.get_size_inches()
    wide = box.width * width >= ROW_ASPECT * count * box.height * height
    return count if wide else 2


def mark_cuts(ax: Axes, values: Sequence[float]) -> None:
    """Each cut as a thin dashed vertical line on a diagram, lettered at its foot (the letters
    of cuts next to each other along the axis a line of text apart, in turn on three
    levels)."""
    from matplotlib.font_manager import FontProperties

    line = _CUT_LABEL_LINES * FontProperties(size="small").get_size_in_points()
    order = np.argsort(np.asarray(values, dtype=float), kind="stable")
    level = {int(k): rank % 3 for rank, k in enumerate(order)}
    for k, value in enumerate(values):
        ax.axvline(float(value), color="dimgrey", linestyle=(0, (4, 3)), linewidth=0.8,
                   zorder=1, label="_cut")
        ax.annotate(f"({_LETTERS[k % 26]})", xy=(float(value), 0.0),
                    xycoords=("data", "axes fraction"), xytext=(2, 3 + line * level[k]),
                    textcoords="offset points", fontsize="small", ha="left", va="bottom")


_CUT_LABEL_LINES = 1.2  # the step between the levels of the cuts' letters, lines of text
