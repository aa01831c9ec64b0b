"""What a stiffness law is: data plus sympy functions (see :mod:`whirl_cli.models.laws`)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

from ..declaration import Bounds, Dof, Parameter

#: A problem with a law's coefficient values: (the study keys it concerns, most to blame
#: first; the reason).
LawProblem = tuple[tuple[str, ...], str]


def _no_problems(values: Mapping[str, float]) -> list[LawProblem]:
    return []


def _no_defaults(values: Mapping[str, float]) -> dict[str, float]:
    return {}


@dataclass(frozen=True)
class Coefficient:
    """A law coefficient as a study writes it (``key``), with its datum, its unit and its
    description. The unit is a force per ``power`` of the dof's unit (K2 multiplies x^3:
    ``power`` 3; ``power`` 1 is a stiffness), or the dof's own unit if ``in_dof_unit`` (a
    length or angle of the law, e.g. freeplay's half-gap).

    Its key in a study's law block (the schema is made from these): ``doc`` describes it,
    ``required``: a study must give it; ``unset``: a study may leave it out, and it then
    becomes what this says (the law's ``derived_defaults``); else it defaults to ``default``."""

    key: str
    default: float
    power: int
    description: str
    bounds: Bounds = Bounds()
    in_dof_unit: bool = False
    doc: str = ""
    required: bool = False
    unset: str = ""


@dataclass(frozen=True)
class Law:
    """A named stiffness law.

    ``moment(x, k, c)``: the restoring force as a sympy expression of the dof ``x``, its linear
    stiffness symbol ``k`` and the coefficient symbols ``c`` (by key); C-infinity, so AUTO can
    continue it. ``is_linear(values)``: whether the law is K x for these coefficient values (by
    key, with ``stiffness_key``, if the law has one, giving the dof's stiffness), so that a
    model whose laws all are is a linear system. ``short``: its tag in model variant names.

    ``stiffness_key``: the study key under which the law sets the dof's own linear stiffness
    parameter (freeplay's ``K_out`` is K_theta on pitch); None if the law takes it as it is.
    ``problems(values)``: what is wrong with a combination of coefficient values (by key,
    the stiffness under ``stiffness_key``) that each value's bounds cannot say.
    ``derived_defaults(given)``: defaults that depend on other values, from the finite
    values a study gives (by key); freeplay's epsilon = delta/100. Filled when a study is
    read (:mod:`whirl_cli.study.resolve`).

    A law that smooths a piecewise law gives the exact one too: ``breakpoints(values)``, the
    increasing dof values where its pieces meet, and ``exact(x, k, c, piece)``, the restoring
    force on piece ``piece`` (a symbol taking 0 .. len(breakpoints), piece j lying between
    breakpoints j - 1 and j), smooth on each piece. ``exact`` None: the law is exact as it is.
    ``smoothing_key``: the coefficient that sets the smoothing (the exact law returns as it
    goes to 0; freeplay's epsilon), for the persistence check of special points.

    ``numeric(x, k, c)``: the same restoring force on numpy arrays and floats (to draw the
    law), where ``moment`` needs sympy-only functions; None: ``moment`` itself takes arrays.

    ``study_doc``: the law in a study's ``type`` description; ``stiffness_doc``: the study key
    ``stiffness_key`` described (the rest of the law's study keys are its coefficients).
    :meth:`force` and :meth:`exact_force` evaluate the law and its exact form numerically.
    """

    name: str
    short: str
    description: str
    coefficients: tuple[Coefficient, ...]
    moment: Callable[..., object]
    is_linear: Callable[[Mapping[str, float]], bool]
    stiffness_key: str | None = None
    problems: Callable[[Mapping[str, float]], list[LawProblem]] = _no_problems
    derived_defaults: Callable[[Mapping[str, float]], dict[str, float]] = _no_defaults
    exact: Callable[..., object] | None = None
    breakpoints: Callable[[Mapping[str, float]], tuple[float, ...]] | None = None
    smoothing_key: str | None = None
    numeric: Callable[..., object] | None = None
    study_doc: str = ""
    stiffness_doc: str = ""

    def force(self, x, k: float, c: Mapping[str, float]):
        """The restoring force at ``x`` (array, the dof's unit) for stiffness ``k`` and
        coefficients ``c`` (by key), in the stiffness's unit times the dof's."""
        return (self.numeric or self.moment)(x, k, c)

    def exact_force(self, x, k: float, c: Mapping[str, float]):
        """The exact (unsmoothed) restoring force at ``x``, piece by piece; :meth:`force` if
        the law is exact as it is."""
        if self.exact is None or self.breakpoints is None:
            return self.force(x, k, c)
        import numpy as np

        x = np.asarray(x, dtype=float)
        piece = np.searchsorted(np.asarray(self.breakpoints(c), dtype=float), x)
        return self.exact(x, k, c, piece)

    def parameter_name(self, key: str, dof: str) -> str:
        """The model parameter a study's ``key`` of a law on ``dof`` becomes: K2 -> K2_theta."""
        return f"{key}_{dof}"

    def parameters(self, dof: Dof, stiffness: Parameter) -> tuple[Parameter, ...]:
        """The law's coefficients on ``dof`` as model parameters (units from the dof's
        stiffness: a force per unit of the dof, so K2 is that force per unit^3)."""
        force = stiffness.unit.removesuffix(f"/{dof.unit}")
        return tuple(
            Parameter(self.parameter_name(c.key, dof.name), c.default,
                      dof.unit if c.in_dof_unit else f"{force}/{dof.unit}"
                      + (f"^{c.power}" if c.power != 1 else ""),
                      f"{c.description} of the {dof.name} restoring force ({self.name} law)",
                      bounds=c.bounds)
            for c in self.coefficients)
