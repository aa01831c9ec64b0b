"""Structural stiffness laws: the restoring force of one degree of freedom.

A law on a dof replaces the dof's structural stiffness term K x (x the dof, K its declared
linear stiffness, e.g. K_theta for pitch) by a restoring force M(x) that takes K as its linear
coefficient and brings coefficients of its own. Inside a study's law block the coefficients
have short names (``K2``, ``K3``); everywhere else (AUTO's PAR, HDF5, ``whirl models``, plots)
they are named by dof (``K2_theta``, ``K3_psi``), so several laws can act at once.

Laws are data plus one sympy function; :data:`LAWS` is the registry by study ``type``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

from ..declaration import Bounds, Dof, Parameter


@dataclass(frozen=True)
class Coefficient:
    """A law coefficient as a study writes it (``key``), with its datum, the power of the dof's
    unit it multiplies (K2 multiplies x^3: ``power`` 3) and its description."""

    key: str
    default: float
    power: int
    description: str
    bounds: Bounds = Bounds()


@dataclass(frozen=True)
class Law:
    """A named stiffness law.

    ``moment(x, k, c)``: the restoring force as a sympy expression of the dof ``x``, its linear
    stiffness symbol ``k`` and the coefficient symbols ``c`` (by key). ``is_linear(values)``:
    whether the law is K x for these coefficient values (by key), so that a model whose laws
    all are is a linear system. ``short``: its tag in model variant names.
    """

    name: str
    short: str
    description: str
    coefficients: tuple[Coefficient, ...]
    moment: Callable[..., object]
    is_linear: Callable[[Mapping[str, float]], bool]

    def parameter_name(self, key: str, dof: str) -> str:
        """The model parameter a study's ``key`` of a law on ``dof`` becomes: K2 -> K2_theta."""
        return f"{key}_{dof}"

    def parameters(self, dof: Dof, stiffness: Parameter) -> tuple[Parameter, ...]:
        """The law's coefficients on ``dof`` as model parameters (units from the dof's
        stiffness: a force per unit of the dof, so K2 is that force per unit^3)."""
        force = stiffness.unit.removesuffix(f"/{dof.unit}")
        return tuple(
            Parameter(self.parameter_name(c.key, dof.name), c.default,
                      f"{force}/{dof.unit}^{c.power}",
                      f"{c.description} of the {dof.name} restoring force ({self.name} law)",
                      bounds=c.bounds)
            for c in self.coefficients)


def _polynomial(x, k, c):
    return k * x + c["K2"] * x**3 + c["K3"] * x**5


POLYNOMIAL = Law(
    "polynomial", "poly",
    "M(x) = K x + K2 x^3 + K3 x^5 (K: the dof's linear stiffness, e.g. K_theta; x in its unit)",
    (Coefficient("K2", 0.0, 3, "cubic coefficient"),
     Coefficient("K3", 0.0, 5, "quintic coefficient")),
    _polynomial,
    lambda values: values.get("K2", 0.0) == 0.0 and values.get("K3", 0.0) == 0.0,
)

#: Laws by study ``type``. ``linear`` is no law of its own: a dof with linear springs is the
#: polynomial law with K2 = K3 = 0, so both share one compiled AUTO program.
LAWS: dict[str, Law] = {law.name: law for law in (POLYNOMIAL,)}
