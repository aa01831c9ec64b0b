"""What a study's figures are called: titles naming the study and its fixed parameters
("combined-case2: K_psi = 0.3 N m/rad"), and the labels of the slices of its two-parameter
continuations ("case 2"), from the provenance stored with a result (no matplotlib).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from ..results import Boundary, Simulation, SimulationLaw, StudyResult


@dataclass(frozen=True)
class Fixed:
    """A parameter the study fixes: canonical name, value and unit (SI)."""

    name: str
    value: float
    unit: str

    def __str__(self) -> str:
        from .key import symbol

        dimensioned = self.unit not in ("", "1")  # "a = 0.3", not "a = 0.3 1"
        return f"{symbol(self.name)} = {self.value:g}{' ' + self.unit if dimensioned else ''}"


@dataclass(frozen=True)
class Captions:
    """The study's name, the parameters it overrides (in the order written), per
    two-parameter continuation one label per slice (empty: none given). ``named``:
    titles start with the study's name (a study's own plot files; a figure of several
    panels names what it shows in its caption instead)."""

    study: str
    fixed: tuple[Fixed, ...] = ()
    slice_labels: dict[str, tuple[str, ...]] = field(default_factory=dict)
    named: bool = True

    def title(self, varied: Iterable[str] = ()) -> str:
        """``"<study>: <name> = <value> <unit>, ..."`` over the fixed parameters that are
        not ``varied`` in the figure (just the study's name if none is left); without the
        study's name (and "" if none is left) unless ``named``."""
        varied = set(varied)
        shown = ", ".join(str(f) for f in self.fixed if f.name not in varied)
        if not self.named:
            return shown
        return f"{self.study}: {shown}" if shown else self.study

    def simulation_title(self, simulation: Simulation) -> str:
        """``"<study>: <fixed>, <the simulation's overrides>\n<simulation name>"``: the
        study's fixed parameters with the simulation's own on top (by canonical name with
        their units), then its name (and ``exact law`` where it simulated the exact law)."""
        own = [str(Fixed(name, float(value), unit)) for name, value, unit in zip(
            simulation.parameter_names, simulation.parameter_values,
            simulation.parameter_units, strict=True)]
        base = self.title(simulation.parameter_names)
        joint = ": " if base == self.study else ", " if base else ""
        shown = base + joint + ", ".join(own) if own else base
        law = " (exact law)" if simulation.law == SimulationLaw.EXACT else ""
        return f"{shown}\n{simulation.name}{law}"

    def slice_label(self, continuation: str, k: int) -> str:
        """The label of slice ``k`` (from 0) of ``continuation``: the study's ``label``, else
        ``"case <k + 1>"``."""
        labels = self.slice_labels.get(continuation, ())
        return labels[k] if k < len(labels) and labels[k] else f"case {k + 1}"

    def case_labels(self, boundary: Boundary) -> tuple[str, ...]:
        """:meth:`slice_label` of every slice of ``boundary``, in order."""
        return tuple(self.slice_label(boundary.name, k) for k in range(len(boundary.slices)))


def captions(result: StudyResult) -> Captions:
    """The captions of ``result`` from its provenance (the study's name alone where that
    records no parameters or slices)."""
    found = result.provenance
    fixed = tuple(Fixed(p.name, p.value, p.unit) for p in found.fixed)
    labels = {name: found.slice_labels(name)
              for name in dict.fromkeys(s.continuation for s in found.slices)}
    return Captions(result.study_name, fixed, labels)
