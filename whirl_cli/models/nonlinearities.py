"""Structural stiffness laws: the restoring moment of one degree of freedom.

A law replaces the linear spring term ``K x`` of the chosen degree of freedom by a restoring moment
M(x) and brings its own parameters. Laws are composable with any model that declares the degree of
freedom and its linear stiffness parameter.

* ``polynomial``: M(x) = K1 x + K2 x^3 + K3 x^5 (x in rad). K1 takes the role of the linear
  stiffness, whose name stays accepted as an alias (in the classical model, ``K_theta`` = ``K1``).
  The ``linear`` nonlinearity of a study is this law with K2 = K3 = 0, so both share one compiled
  AUTO executable.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import sympy as sp

from .base import Parameter


@dataclass(frozen=True)
class StiffnessLaw:
    """A named law: ``build(x, stiffness)`` returns the moment expression and its parameters."""

    name: str
    description: str
    build: Callable[[sp.Symbol, Parameter], tuple[sp.Expr, tuple[Parameter, ...]]]


def _polynomial(x: sp.Symbol, stiffness: Parameter) -> tuple[sp.Expr, tuple[Parameter, ...]]:
    unit = stiffness.unit.removesuffix("/rad")
    k1 = Parameter(
        "K1",
        stiffness.default,
        stiffness.unit,
        f"linear coefficient of the {x} restoring moment ({stiffness.name})",
        aliases=(stiffness.name, *stiffness.aliases),
        bounds=stiffness.bounds,
    )
    k2 = Parameter("K2", 0.0, f"{unit}/rad^3", f"cubic coefficient of the {x} restoring moment")
    k3 = Parameter("K3", 0.0, f"{unit}/rad^5", f"quintic coefficient of the {x} restoring moment")
    s1, s2, s3 = (sp.Symbol(p.name, real=True) for p in (k1, k2, k3))
    return s1 * x + s2 * x**3 + s3 * x**5, (k1, k2, k3)


POLYNOMIAL = StiffnessLaw(
    "polynomial", "M(x) = K1 x + K2 x^3 + K3 x^5 (K1 replaces the linear stiffness)", _polynomial
)

LAWS: dict[str, StiffnessLaw] = {law.name: law for law in (POLYNOMIAL,)}
