"""Freeplay: whirl's smoothed deadband law (docs/models.md, "Freeplay: whirl's law").

The exact law: stiffness K_in inside a gap of half-width delta around zero, K_out outside, no
preload (x the dof, in its unit: rad for the classical model's angles)::

    M_fp(x) = K_in x + (K_out - K_in) [x - delta sat(x / delta)],   sat(z) = max(-1, min(1, z))

The law AUTO continues is its C-infinity, odd smoothing of width epsilon::

    M_eps(x)  = K_in x + (K_out - K_in) [x - (epsilon/2) (lc((x + delta)/epsilon)
                                                         - lc((x - delta)/epsilon))]
    M_eps'(x) = K_in + (K_out - K_in) [1 - (tanh((x + delta)/epsilon)
                                            - tanh((x - delta)/epsilon)) / 2]
    lc(z) = ln cosh z = |z| + ln(1 + exp(-2 |z|)) - ln 2

printed in that form (:class:`LnCosh`), which never overflows for any epsilon > 0: exp only
sees arguments <= 0, and every derivative is a polynomial in tanh. Its largest error,
(K_out - K_in) epsilon ln2 / 2, is at the corners x = +-delta; the exact law returns as
epsilon -> 0. This smoothing is whirl's own: the papers' form is not recovered.

Coefficients (study keys; model parameters ``<key>_<dof>``): ``delta`` (half-gap, > 0, the
dof's unit), ``K_in`` (stiffness inside the gap, >= 0), ``epsilon`` (smoothing width, > 0
and < delta, the dof's unit; a study's default is delta/100), and ``K_out``, the stiffness
outside the gap, which *is* the dof's linear stiffness parameter (K_theta on pitch; default
its datum): the linear model with K_theta = K_out is the one the law tends to at large
amplitude, and continuing K_theta continues K_out.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

from ..declaration import NON_NEGATIVE, POSITIVE
from .base import Coefficient, Law, LawProblem

if TYPE_CHECKING:  # numpy is imported where the describing function is computed
    import numpy as np

#: The smoothing width a study gets when it gives none, as a fraction of delta.
EPSILON_FRACTION = 0.01


def _sympy_function():
    """The sympy class ln cosh, made on first use (the law's data needs no sympy)."""
    import sympy as sp

    class LnCosh(sp.Function):
        """ln cosh z, printed as |z| + ln(1 + exp(-2|z|)) - ln 2 (no overflow); d/dz = tanh z."""

        nargs = 1

        def fdiff(self, argindex=1):
            return sp.tanh(self.args[0])

        def _numpycode(self, printer):
            z = printer._print(self.args[0])
            return (f"(numpy.abs({z}) + numpy.log1p(numpy.exp(-2.0*numpy.abs({z})))"
                    f" - numpy.log(2.0))")

        def _fcode(self, printer):
            z = printer._print(self.args[0])
            return f"(ABS({z}) + LOG(1.0d0 + EXP(-2.0d0*ABS({z}))) - LOG(2.0d0))"

    return LnCosh


_LNCOSH = None


def lncosh(z):
    """sympy ln cosh z in the overflow-free form (see the module doc)."""
    global _LNCOSH
    if _LNCOSH is None:
        _LNCOSH = _sympy_function()
    return _LNCOSH(z)


def _moment(x, k, c):
    """M_eps(x) with K_out = k (the dof's stiffness symbol)."""
    delta, k_in, epsilon = c["delta"], c["K_in"], c["epsilon"]
    gap = epsilon / 2 * (lncosh((x + delta) / epsilon) - lncosh((x - delta) / epsilon))
    return k_in * x + (k - k_in) * (x - gap)


def _moment_numeric(x, k, c):
    """M_eps(x) on numpy arrays, in the same overflow-free ln cosh form."""
    import numpy as np

    def lc(z):
        z = np.abs(z)
        return z + np.log1p(np.exp(-2.0 * z)) - math.log(2.0)

    delta, k_in, epsilon = c["delta"], c["K_in"], c["epsilon"]
    x = np.asarray(x, dtype=float)
    gap = epsilon / 2 * (lc((x + delta) / epsilon) - lc((x - delta) / epsilon))
    return k_in * x + (k - k_in) * (x - gap)


def _exact(x, k, c, piece):
    """M_fp(x) on piece 0 (x <= -delta), 1 (inside the gap) or 2 (x >= delta)."""
    side = piece - 1
    return c["K_in"] * x + side**2 * (k - c["K_in"]) * (x - side * c["delta"])


def _breakpoints(values: Mapping[str, float]) -> tuple[float, ...]:
    return (-float(values["delta"]), float(values["delta"]))


def _problems(values: Mapping[str, float]) -> list[LawProblem]:
    """epsilon < delta (a smoothing wider than the gap is no deadband), K_out > K_in."""
    found: list[LawProblem] = []
    delta, epsilon = values.get("delta"), values.get("epsilon")
    if delta is not None and epsilon is not None and delta > 0 and epsilon >= delta:
        found.append((("epsilon", "delta"), f"epsilon must be < delta = {delta!r} (the "
                      f"smoothing width below the half-gap), got {epsilon!r}"))
    k_in, k_out = values.get("K_in"), values.get("K_out")
    if k_in is not None and k_out is not None and k_in >= 0 and k_out <= k_in:
        found.append((("K_out", "K_in"), f"K_out must be > K_in = {k_in!r} (stiffer outside "
                      f"the gap than inside), got K_out = {k_out!r}"))
    return found


def _derived_defaults(given: Mapping[str, float]) -> dict[str, float]:
    """epsilon = delta/100 when a study gives delta but no epsilon."""
    if "epsilon" in given or "delta" not in given:
        return {}
    return {"epsilon": EPSILON_FRACTION * given["delta"]}


def equivalent_stiffness(amplitude, delta: float, k_in: float, k_out: float) -> np.ndarray:
    """The describing function of the deadband (models.md section 7): the stiffness K_eq(A)
    that one harmonic x = A sin(w t) sees, in the stiffness's unit,

        K_eq(A) = K_in + (K_out - K_in) {1 - (2/pi) [asin(delta/A) + (delta/A) sqrt(1 -
                  delta^2/A^2)]}      (A > delta; K_in for A <= delta),

    rising from K_in at A = delta towards K_out. ``amplitude``: A (array), in the dof's unit."""
    import numpy as np

    ratio = np.clip(delta / np.maximum(np.asarray(amplitude, dtype=float), 1e-300), 0.0, 1.0)
    share = 1.0 - (2.0 / math.pi) * (np.arcsin(ratio) + ratio * np.sqrt(1.0 - ratio**2))
    return k_in + (k_out - k_in) * share


FREEPLAY = Law(
    "freeplay", "fp",
    "whirl's law (models.md 7): deadband of half-gap delta, stiffness K_in inside and K_out "
    "(the dof's linear stiffness, e.g. K_theta) outside, smoothed over epsilon by ln cosh",
    (Coefficient("delta", 0.01, 0, "half-gap", bounds=POSITIVE, in_dof_unit=True,
                 doc="Half-gap of the deadband, in the dof's unit (rad for angles), > 0",
                 required=True),
     Coefficient("K_in", 0.0, 1, "stiffness inside the gap", bounds=NON_NEGATIVE,
                 doc="Stiffness inside the gap, force per unit, >= 0"),
     Coefficient("epsilon", 0.01 * EPSILON_FRACTION, 0, "smoothing width", bounds=POSITIVE,
                 in_dof_unit=True,
                 doc="Smoothing width, in the dof's unit, > 0 and < `delta` (the smoothed "
                 "law's largest error, (K_out - K_in) epsilon ln2 / 2, is at x = +-delta)",
                 unset=f"delta/{round(1 / EPSILON_FRACTION)}")),
    _moment,
    lambda values: values.get("K_in", 0.0) == values.get("K_out"),
    stiffness_key="K_out",
    problems=_problems,
    derived_defaults=_derived_defaults,
    exact=_exact,
    breakpoints=_breakpoints,
    smoothing_key="epsilon",
    numeric=_moment_numeric,
    study_doc="whirl's law: a deadband of half-gap `delta`, stiffness `K_in` inside and "
    "`K_out` outside, smoothed over `epsilon` by ln cosh",
    stiffness_doc="Stiffness outside the gap, force per unit (classical: N m/rad), > `K_in`: "
    "it is the dof's linear stiffness parameter (`K_theta` on pitch; also `K_out_<dof>`), so "
    "results, continuations and the linear model name it so; `parameters` may not set it "
    "beside the law. Unset: that parameter's datum.",
)
