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
from typing import Annotated, Literal

from pydantic import AfterValidator, Field, PrivateAttr, ValidationError, model_validator

from ..errors import StudyError
from ..plots.panels import OVERLAY_KINDS, PANEL_KINDS
from ..study.messages import _report, _translate
from ..study.schema import Boolean, Integer, Text, _bound, _fail, _Strict
from ..study.source import _compose, _read_text, _Tree

PanelKind = Literal[PANEL_KINDS]  # the kinds plots.panels.draw draws
_FIGURE_RE = re.compile(r"\d+(\.\d+)*[a-z]?")
_MAX_PANELS = 64


def _as_figure(value: str) -> str:
    if not _FIGURE_RE.fullmatch(value):
        _fail("expected a figure number such as 3.14, got {got}")
    return value


class Member(_Strict):
    """One result of an overlay."""

    study: Text = Field(description="Study file, relative to the sheet's folder.")
    label: Text | None = Field(
        None, description="Legend label; unset: the parameters that differ between the members.")


class PanelSpec(_Strict):
    """One panel: a plot kind of one study's result, or of several overlaid."""

    kind: PanelKind = Field(description="Plot kind drawn in the panel.")
    study: Text | None = Field(None, description="Study file, relative to the sheet's folder.")
    overlay: tuple[Member, ...] = Field(
        (), description="Several studies on one axes (instead of `study`; kinds bifurcation "
        "and damping_multiples).")
    continuation: Text | None = Field(
        None, description="Continuation (or boundary) drawn; unset: the first that fits.")
    branch: Text | None = Field(None, description="Periodic branch of a `phase` panel.")
    state: Text | None = Field(None, description="State drawn; unset: the model's first dof.")
    sweep: Text | None = Field(None, description="Parameter of the linear sweep drawn.")
    slice: Annotated[Integer, _bound(">=", 0)] | None = Field(
        None, description="Boundary slice of an `overhang` panel, from 0.")
    orbits: tuple[Integer, ...] | None = Field(
        None, description="AUTO labels of the orbits a `phase` panel draws.")
    simulation: Text | None = Field(
        None, description="Simulation of a `time_history` or `hub_path` panel; unset: the first.")
    hz: Boolean = Field(False, description="Frequencies in Hz.")
    title: Text | None = Field(None, description="Panel title; unset: the study's.")

    @model_validator(mode="after")
    def _one_source(self) -> PanelSpec:
        if (self.study is None) == (not self.overlay):
            _fail("give exactly one of `study` and `overlay`")
        if self.overlay and self.kind not in OVERLAY_KINDS:
            _fail(f"only {' and '.join(OVERLAY_KINDS)} panels can be overlaid")
        return self


class Sheet(_Strict):
    """One figure of a sheet folder."""

    figure: Annotated[Text, AfterValidator(_as_figure)] = Field(
        description="Figure number (3.14 -> file fig3_14.png).")
    caption: Text = Field(description="What the figure shows, for the index page.")
    note: Text = Field("", description="How whirl's figure differs from the thesis', if it does.")
    layout: tuple[Annotated[Integer, _bound(">=", 1)], Annotated[Integer, _bound(">=", 1)]] | \
        None = Field(None, description="[rows, columns] of panels; unset: one row.")
    size: tuple[Annotated[float, _bound(">", 0)], Annotated[float, _bound(">", 0)]] | None = \
        Field(None, description="[width, height] in inches; unset: 5.2 x 4.2 per panel.")
    legends: Literal["all", "first"] = Field(
        "all", description="Legends on every panel, or on the first panel only (grids).")
    panels: Annotated[tuple[PanelSpec, ...], Field(min_length=1, max_length=_MAX_PANELS)] = \
        Field(description="The panels, row by row.")

    _path: Path = PrivateAttr(Path("."))

    @property
    def shape(self) -> tuple[int, int]:
        """(rows, columns) of the panel grid."""
        return tuple(self.layout) if self.layout else (1, len(self.panels))

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

    def resolve(self, name: str) -> Path:
        """A study path of the sheet, relative to the sheet's folder, normalised."""
        return Path(os.path.normpath(self._path.parent / name))


def load_sheet(path: str | os.PathLike[str]) -> Sheet:
    """Read and check the sheet at ``path``; a StudyError lists every problem."""
    path = Path(path)
    label = str(path)
    tree = _Tree(_compose(_read_text(path, label), label))
    problems = list(tree.problems)
    sheet = None
    try:
        sheet = Sheet.model_validate(tree.data)
    except ValidationError as error:
        problems += [_translate(e, tree, Sheet) for e in error.errors(include_url=False)]
    if sheet is not None:
        sheet._path = path
        problems += _missing_studies(sheet)
        rows, columns = sheet.shape
        if len(sheet.panels) > rows * columns:
            problems.append((("layout",), f"{len(sheet.panels)} panels do not fit a {rows} x "
                                          f"{columns} layout"))
    if problems:
        raise StudyError(_report(problems, tree, label))
    return sheet


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


def find_sheets(paths) -> list[Path]:
    """Sheet files named by ``paths``: files as given, folders searched for ``*.yaml``."""
    from ..sweep.plan import find_studies

    return find_studies(paths, what="sheet files")
