"""Models: each defined once, as data, from which everything downstream is generated.

Modules, lowest first:

* :mod:`~whirl_cli.models.declaration` -- what a model family declares: degrees of freedom,
  parameters with bounds, its equations (M q'' = G - S); no sympy;
* :mod:`~whirl_cli.models.laws` -- structural stiffness laws on a dof (polynomial);
* :mod:`~whirl_cli.models.classical`, :mod:`~whirl_cli.models.gimballed` (provisional),
  :mod:`~whirl_cli.models.oscillators` -- the families;
* :mod:`~whirl_cli.models.variant` -- a family with a law on each dof, as whirl runs it
  (names, scales, numeric functions);
* :mod:`~whirl_cli.models.symbolic` -- a variant's sympy equations (code generation only);
* :mod:`~whirl_cli.models.numeric` -- the numeric module generated from them, cached.

:func:`get_model` builds variants (cheap: no sympy); :data:`SHIPPED` lists the variants the
shipped studies use, whose AUTO files are committed under ``auto_equations/``.
"""

from __future__ import annotations

from functools import cache

from . import classical, gimballed, oscillators
from .declaration import Bounds, Constraint, Dof, Family, ModeGroup, Parameter, State
from .laws import LAWS
from .variant import Model

__all__ = ["Bounds", "Constraint", "Dof", "Family", "ModeGroup", "Model", "Parameter", "State",
           "FAMILIES", "LAWS", "SHIPPED", "get_model", "all_variants"]

#: Model families by the name a study gives as ``model``.
FAMILIES: dict[str, Family] = {f.name: f for f in (classical.FAMILY, gimballed.FAMILY,
                                                    oscillators.FAMILY)}

#: The variants the shipped studies use: (family, law per dof).
SHIPPED: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("classical", ("polynomial", "polynomial")),
    ("classical", ("freeplay", "polynomial")),  # studies/freeplay
    ("classical", ("polynomial", "freeplay")),
    ("gimballed", ("polynomial",) * 4),
)


@cache
def get_model(family: str, laws: tuple[str, ...] | None = None) -> Model:
    """The variant of ``family`` with ``laws[i]`` on its i-th dof (default: the polynomial law
    on every dof, which with zero coefficients is the linear model)."""
    declared = FAMILIES[family]
    return Model(declared, tuple(laws) if laws else ("polynomial",) * len(declared.dofs))


def all_variants() -> list[Model]:
    """The shipped variants, in a fixed order (the contents of ``auto_equations/``)."""
    return [get_model(family, laws) for family, laws in SHIPPED]
