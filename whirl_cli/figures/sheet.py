"""Sheet files: one YAML file per figure, saying which study results it draws, with which
plot kind, as single panels, overlays or a grid.

A sheet is validated like a study (:mod:`whirl_cli.study`): every problem at once, as
``<file>:<line>: <key.path>: <reason>``; study paths are relative to the sheet's own folder
and must name existing files. Example (thesis figure 3.14)::

    figure: "3.14"
    caption: Bifurcation diagram in K_theta, the roots and damping of the linear model beside
    layout: [1, 2]
    panels:
      - {kind: bifurcation, study: ../../studies/thesis_ch3/linear_case2.yaml}
      - {kind: linear, study: ../../studies/thesis_ch3/linear_ktheta.yaml}
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BeforeValidator,
    Field,
    PrivateAttr,
    model_validator,
)

from ..documents.values import (
    Boolean,
    Integer,
    Number,
    Range,
    Strict,
    Text,
    as_number,
    at_most_orbits,
    bound,
    fail,
)
from ..plots.kinds import overlay_kinds, panel_kinds
from ..study import load_yaml_file
from .numbers import POINTS

PanelKind = Literal[panel_kinds()]  # the kinds plots.panels.draw draws
_FIGURE_RE = re.compile(r"\d+(\.\d+)*[a-z]?")
_MAX_PANELS = 64
PANEL_SIZE = (5.2, 4.2)
"""Default width and height of one panel, inches."""
INCHES = (1.0, 40.0)
"""Smallest and largest width or height of a figure, inches (40 in: 6000 pixels at 150 dpi)."""
COLUMNS = {"single": 3.5, "double": 7.2}
"""Width in inches of a figure set in one column of a journal page, or across both."""
COLUMN_FONT_SIZE = 8.0
"""Text size, points, of a figure set in a journal column (its small text about 6.7 pt)."""


_MAX_CUTS = 8


def _at_most_cuts(value: tuple) -> tuple:
    if not 1 <= len(value) <= _MAX_CUTS:
        fail(f"expected 1 to {_MAX_CUTS} values, got {len(value)}")
    return value


def _as_figure(value: str) -> str:
    if not _FIGURE_RE.fullmatch(value):
        fail("expected a figure number such as 3.14, got {got}")
    return value


def _as_inches(value: Any) -> float:
    """A finite width or height within :data:`INCHES`."""
    number = as_number(value)
    low, high = INCHES
    if not low <= number <= high:
        hint = " (the size is in inches, not pixels)" if number > high else ""
        fail(f"expected inches, {low:g} to {high:g}, got {{got}}{hint}")
    return number


def _panel_count(value: Any) -> Any:
    """A list of 1 to _MAX_PANELS panels (counted before the panels are checked, so that a
    bad panel is reported alone)."""
    if isinstance(value, list) and not 1 <= len(value) <= _MAX_PANELS:
        fail(f"expected 1 to {_MAX_PANELS} panels, got {len(value)}")
    return value


Inches = Annotated[float, BeforeValidator(_as_inches)]
Count = Annotated[Integer, bound(">=", 1), bound("<=", _MAX_PANELS)]


class Member(Strict):
    """One result of an overlay."""

    study: Text = Field(description="Study file, relative to the sheet's folder.")
    label: Text | None = Field(
        None, description="Legend label; unset: the parameters that differ between the members.")


class PanelSpec(Strict):
    """One panel: a plot kind of one study's result, or of several overlaid."""

    kind: PanelKind = Field(description="Plot kind drawn in the panel.")
    study: Text | None = Field(None, description="Study file, relative to the sheet's folder.")
    overlay: tuple[Member, ...] = Field(
        (), description="Several studies on one axes (instead of `study`; kinds bifurcation, "
        "damping_multiples and law).")
    continuation: Text | None = Field(
        None, description="Continuation (or boundary) drawn; unset: the first that fits.")
    branch: Text | None = Field(None, description="Periodic branch of a `phase` panel.")
    state: Text | None = Field(None, description="State drawn; unset: the model's first dof.")
    sweep: Text | None = Field(None, description="Parameter of the linear sweep drawn.")
    slice: Annotated[Integer, bound(">=", 0)] | None = Field(
        None, description="Boundary slice of an `overhang` panel, from 0.")
    orbits: Annotated[tuple[Annotated[Integer, bound(">=", 1)], ...],
                      AfterValidator(at_most_orbits)] | None = Field(
        None, description="AUTO labels (>= 1) of the orbits a `phase` panel draws.")
    simulation: Text | None = Field(
        None, description="Simulation of a `time_history` or `hub_path` panel; unset: the first.")
    hz: Boolean = Field(False, description="Frequencies in Hz.")
    title: Text | None = Field(None, description="Panel title; unset: the study's.")
    cuts: Annotated[tuple[Number, ...], AfterValidator(_at_most_cuts)] | None = Field(
        None, description="Parameter values: a `phase` panel draws every solution at each "
        f"(a grid of phase planes, at most {_MAX_CUTS}), a `bifurcation` panel a line.")

    @model_validator(mode="after")
    def _one_source(self) -> PanelSpec:
        if (self.study is None) == (not self.overlay):
            fail("give exactly one of `study` and `overlay`")
        if self.overlay and self.kind not in overlay_kinds():
            kinds = ", ".join(overlay_kinds()[:-1]) + f" and {overlay_kinds()[-1]}"
            fail(f"only {kinds} panels can be overlaid")
        return self


class ThesisNumber(Strict):
    """A number the thesis gives for the figure, and the special point of a study's result
    that is whirl's (for the index's table)."""

    name: Text = Field(description="What the number is, e.g. 'Hopf point HB1'.")
    value: Number | None = Field(None, description="The thesis's value; unset with `between` "
                                 "unset: not recovered.")
    between: Range | None = Field(None, description="The thesis's value as a range [low, "
                                  "high] (it gives one, e.g. 0.03 to 0.04), instead of `value`.")
    unit: Text = Field(description="Unit of the value, as whirl stores the parameter's.")
    point: Literal[POINTS] = Field(description="Type of whirl's special point.")
    study: Text | None = Field(None, description="Study of whirl's point, one the sheet draws; "
                               "unset: the first it draws.")
    continuation: Text | None = Field(None, description="Its continuation; unset: any "
                                      "one-parameter one.")
    branch: Text | None = Field(None, description="Its branch; unset: any.")
    near: Number | None = Field(None, description="Of several, whirl's point nearest this; "
                                "unset: nearest the thesis's value.")

    @model_validator(mode="after")
    def _one_value(self) -> ThesisNumber:
        if self.value is not None and self.between is not None:
            fail("give at most one of `value` and `between`")
        if self.value is None and self.between is None and self.near is None:
            fail("give `near` (where whirl's point lies) when the thesis's value is unset")
        return self

    @property
    def target(self) -> float:
        """Where whirl's point is looked for: ``near``, else the thesis's value (the middle
        of its range)."""
        if self.near is not None:
            return self.near
        return self.value if self.value is not None else sum(self.between) / 2


class Sheet(Strict):
    """One figure of a sheet folder."""

    figure: Annotated[Text, AfterValidator(_as_figure)] = Field(
        description="Figure number (3.14 -> file fig3_14.png).")
    caption: Text = Field(description="What the figure shows, for the index page.")
    note: Text = Field("", description="How whirl's figure differs from the thesis', if it does.")
    layout: tuple[Count, Count] | None = Field(
        None, description=f"[rows, columns] of panels, each 1 to {_MAX_PANELS}; unset: one row.")
    size: tuple[Inches, Inches] | None = Field(
        None, description=f"[width, height] in inches, each {INCHES[0]:g} to {INCHES[1]:g}; "
        f"unset: {PANEL_SIZE[0]:g} x {PANEL_SIZE[1]:g} per panel.")
    column: Literal[tuple(COLUMNS)] | None = Field(
        None, description=f"Journal column the figure is set in: {COLUMNS['single']:g} in "
        f"wide (single) or {COLUMNS['double']:g} in (double), as high as `size` (else the "
        f"panels) in proportion, text at {COLUMN_FONT_SIZE:g} pt; unset: `size`.")
    legends: Literal["all", "first", "figure"] = Field(
        "figure", description="One legend for the figure with every style drawn on it "
        "(below the panels), legends on every panel, or on the first panel only.")
    share: Literal["none", "x", "y", "both"] = Field(
        "none", description="Panels whose axes show the same quantities get the same "
        "limits on this axis (a comparison grid).")
    panels: Annotated[tuple[PanelSpec, ...], BeforeValidator(_panel_count)] = Field(
        description="The panels, row by row.")
    thesis: tuple[ThesisNumber, ...] = Field(
        (), description="The thesis's numbers the figure shows, each beside whirl's in the "
        "index's table.")

    _path: Path = PrivateAttr(Path("."))

    @property
    def shape(self) -> tuple[int, int]:
        """(rows, columns) of the panel grid."""
        return tuple(self.layout) if self.layout else (1, len(self.panels))

    @property
    def figure_size(self) -> tuple[float, float]:
        """(width, height) in inches: ``size``, else :data:`PANEL_SIZE` per panel; scaled to
        the width of ``column`` if set."""
        rows, columns = self.shape
        width, height = self.size if self.size else (PANEL_SIZE[0] * columns,
                                                     PANEL_SIZE[1] * rows)
        if self.column is None:
            return width, height
        return COLUMNS[self.column], COLUMNS[self.column] * height / width

    @property
    def style(self) -> dict[str, float]:
        """matplotlib settings the figure is drawn and written with: the text size of a
        journal column if ``column`` is set."""
        return {"font.size": COLUMN_FONT_SIZE} if self.column else {}

    @property
    def stem(self) -> str:
        """The figure's file name without suffix: ``fig3_14``."""
        return "fig" + self.figure.replace(".", "_")

    @property
    def path(self) -> Path:
        """The sheet file."""
        return self._path

    def studies(self) -> list[Path]:
        """Every study file the sheet draws, in panel order, each once."""
        found: list[Path] = []
        for panel in self.panels:
            for name in ([panel.study] if panel.study else [m.study for m in panel.overlay]):
                path = self.resolve(name)
                if path not in found:
                    found.append(path)
        return found

    def thesis_study(self, number: ThesisNumber) -> Path:
        """The study file of whirl's value of ``number``."""
        return self.resolve(number.study) if number.study else self.studies()[0]

    def resolve(self, name: str) -> Path:
        """A study path of the sheet, relative to the sheet's folder, normalised."""
        return Path(os.path.normpath(self._path.parent / name))


def load_sheet(path: str | os.PathLike[str]) -> Sheet:
    """Read and check the sheet at ``path``; a StudyError lists every problem."""
    path = Path(path)

    def checks(sheet: Sheet) -> list:
        sheet._path = path
        problems = _missing_studies(sheet)
        problems += _foreign_thesis_studies(sheet)
        rows, columns = sheet.shape
        if len(sheet.panels) > rows * columns:
            problems.append((("layout",), f"{len(sheet.panels)} panels do not fit a {rows} x "
                                          f"{columns} layout"))
        return problems + _default_size_problems(sheet)

    return load_yaml_file(path, Sheet, "sheet", checks)


def _default_size_problems(sheet: Sheet) -> list:
    """A sheet without ``size`` whose panels at their default size make too large a figure,
    or one set in a column so flat or tall that its height leaves :data:`INCHES`."""
    width, height = sheet.figure_size
    if sheet.column and not INCHES[0] <= height <= INCHES[1]:
        return [(("column",), f"{width:g} in wide, the figure would be {height:.3g} in high, "
                              f"outside {INCHES[0]:g} to {INCHES[1]:g}; change `size`")]
    if sheet.size or max(width, height) <= INCHES[1]:
        return []
    rows, columns = sheet.shape
    return [(("layout",) if sheet.layout else ("panels",),
             f"{rows} x {columns} panels of {PANEL_SIZE[0]:g} x {PANEL_SIZE[1]:g} inches make "
             f"{width:g} x {height:g} inches, over {INCHES[1]:g}; give `size`")]


def _missing_studies(sheet: Sheet) -> list:
    """(key path, reason) of every study path that names no file."""
    problems = []
    for k, panel in enumerate(sheet.panels):
        named = [(("panels", k, "study"), panel.study)] if panel.study else [
            (("panels", k, "overlay", j, "study"), m.study) for j, m in enumerate(panel.overlay)]
        for loc, name in named:
            if not sheet.resolve(name).is_file():
                problems.append((loc, f"no study file {sheet.resolve(name)}"))
    return problems


def _foreign_thesis_studies(sheet: Sheet) -> list:
    """(key path, reason) of every ``thesis:`` study that no panel of the sheet draws."""
    drawn = sheet.studies()
    return [(("thesis", k, "study"), "expected a study a panel of the sheet draws, got "
             f"{number.study}") for k, number in enumerate(sheet.thesis)
            if number.study and sheet.resolve(number.study) not in drawn]


def find_sheets(paths) -> list[Path]:
    """Sheet files named by ``paths``: files as given, folders searched for ``*.yaml``."""
    from ..sweep.plan import find_studies

    return find_studies(paths, what="sheet files")
