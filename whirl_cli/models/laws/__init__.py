"""Structural stiffness laws: the restoring force of one degree of freedom.

A law on a dof replaces the dof's structural stiffness term K x (x the dof, K its declared
linear stiffness, e.g. K_theta for pitch) by a restoring force M(x) that takes K as its linear
coefficient and brings coefficients of its own. Inside a study's law block the coefficients
have short names (``K2``, ``K3``, ``delta``); everywhere else (AUTO's PAR, HDF5, ``whirl
models``, plots) they are named by dof (``K2_theta``, ``delta_psi``), so several laws can act
at once. A law may name the dof's stiffness itself under a key of its own (freeplay's
``K_out``: the stiffness outside the gap is K_theta on pitch).

Laws are data plus sympy functions (:class:`~whirl_cli.models.laws.base.Law`); :data:`LAWS`
is the registry by study ``type``, of the laws declared here and in the modules of this package
(a new smooth law is a new module; its coefficients make its block of the study schema):

* ``polynomial`` (here): K x + K2 x^3 + K3 x^5;
* ``freeplay`` (:mod:`~whirl_cli.models.laws.freeplay`): whirl's smoothed deadband
  (docs/models.md, "Freeplay: whirl's law"), with its exact piecewise-linear form.
"""

from __future__ import annotations

from .base import Coefficient, Law, LawProblem
from .freeplay import FREEPLAY

__all__ = ["Coefficient", "Law", "LawProblem", "LAWS", "POLYNOMIAL", "FREEPLAY"]


def _polynomial(x, k, c):
    return k * x + c["K2"] * x**3 + c["K3"] * x**5


POLYNOMIAL = Law(
    "polynomial", "poly",
    "M(x) = K x + K2 x^3 + K3 x^5 (K: the dof's linear stiffness, e.g. K_theta; x in its unit)",
    (Coefficient("K2", 0.0, 3, "cubic coefficient",
                 doc="Cubic coefficient, force per unit^3 (classical: N m/rad^3)"),
     Coefficient("K3", 0.0, 5, "quintic coefficient",
                 doc="Quintic coefficient, force per unit^5 (classical: N m/rad^5)")),
    _polynomial,
    lambda values: values.get("K2", 0.0) == 0.0 and values.get("K3", 0.0) == 0.0,
    study_doc="restoring force K x + K2 x^3 + K3 x^5 on `dof`, K the dof's linear stiffness, "
    "e.g. K_theta; x in the dof's unit, rad for angles",
)

#: Laws by study ``type``. ``linear`` is no law of its own: a dof with linear springs is the
#: polynomial law with K2 = K3 = 0, so both share one compiled AUTO program.
def _declared() -> dict[str, Law]:
    """The laws declared here and in this package's modules, by name: this module's first,
    then module by module in name order."""
    from ...registries import declared

    return declared(__name__, __path__, Law, "stiffness law", {POLYNOMIAL.name: POLYNOMIAL})


LAWS: dict[str, Law] = _declared()
