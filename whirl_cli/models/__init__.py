"""Model registry: every model variant whirl can build, generate and run.

A variant is a model family with one stiffness law on one degree of freedom. Variants are built
lazily and cached, because building means sympy work.
"""

from __future__ import annotations

from functools import cache

from . import classical
from .base import Model, Parameter, State
from .nonlinearities import LAWS

__all__ = ["Model", "Parameter", "State", "FAMILIES", "get_model", "all_variants", "LAWS"]

#: family name -> (module with build(law, dof), degrees of freedom a law may act on, default dof)
FAMILIES = {
    "classical": (classical, tuple(classical.DOFS), "theta"),
}


@cache
def get_model(family: str, law: str = "polynomial", dof: str | None = None) -> Model:
    """The variant of ``family`` with stiffness ``law`` on ``dof`` (default: the family's)."""
    module, dofs, default_dof = FAMILIES[family]
    dof = dof or default_dof
    if dof not in dofs:
        raise KeyError(f"model {family!r} has no degree of freedom {dof!r}")
    return module.build(LAWS[law], dof)


def all_variants() -> list[Model]:
    """Every registered variant, in a fixed order (the contents of ``auto_equations/``)."""
    return [
        get_model(family, law, dof)
        for family, (_, dofs, _) in FAMILIES.items()
        for law in LAWS
        for dof in dofs
    ]
