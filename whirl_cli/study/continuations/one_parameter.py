"""The ``one-parameter`` continuation type: equilibria in one parameter, the periodic families
from their Hopf points, seeds, explored values (its recipe:
:func:`whirl_cli.continuation.recipes.continue_one_parameter`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Any, Literal

from pydantic import AfterValidator, BeforeValidator, Field

from ...documents.values import (
    ORBITS_MAX,
    SEEDS_TEXT,
    Boolean,
    Number,
    Positive,
    Range,
    Text,
    as_seeds,
    as_state,
    at_most_orbits,
)
from ...kinds import ContinuationKind
from ..resolve import Names, resolved_parameter
from . import ContinuationSpec, ContinuationType

if TYPE_CHECKING:
    from ..schema import Study

#: The default initial state of ``explore``: the first dof displaced by this (deg for angles).
EXPLORE_OFFSET = 2.0
#: Whirl periods an ``explore`` simulation discards before it classifies (a weakly attracting
#: cycle needs many to settle).
EXPLORE_TRANSIENT = 60.0


class OneParameterContinuation(ContinuationSpec):
    """Equilibria in one parameter, with the branches that hang off them.

    After validation ``parameter`` is the canonical name and ``start`` is filled.
    """

    type: Literal["one-parameter"] = Field(
        description="`one-parameter`: equilibria in one parameter (AUTO-07p continuation)."
    )
    parameter: Text = Field(
        description="Continuation parameter, by name or alias, in its SI unit (stored as the "
        "canonical name: `K1` -> `K_theta`)."
    )
    start: Number | None = Field(
        None,
        description="Starting value, in the parameter's unit; must lie within `range`. Unset: "
        "the study value (`parameters`, else the model's datum).",
    )
    range: Range = Field(
        description="[lower, upper] bounds of the parameter, in its unit; AUTO stops at either."
    )
    periodic: Boolean = Field(
        False, description="Continue periodic orbits from every Hopf point (main and secondary)."
    )
    branch_points: Boolean = Field(
        True, description="Switch at branch points (pitchforks) to follow secondary equilibria."
    )
    period_doubling: Boolean = Field(
        False, description="Follow the period-doubled family from every period-doubling (PD) "
        "point of a periodic family (AUTO's branch switching at PD, the period doubled), and "
        "from theirs, up to 3 doublings; stored as branches `<family>_pd<k>`."
    )
    spread_equilibria: Boolean = Field(
        False, description="Also seek equilibria at `start` by Newton's method from a spread of "
        "starts (each dof alone and all together at 13 amplitudes from 0.01 to 1 typical "
        "amplitude, both signs); each one on no computed branch starts a branch both ways "
        "(equilibria no branch point reaches, e.g. freeplay's offset ones)."
    )
    start_state: Annotated[dict[str, float] | None, BeforeValidator(as_state)] = Field(
        None,
        description="Where Newton's method seeks the starting equilibrium at `start` when the "
        "zero state is not one: state name -> value (angles in deg, rates in deg/s, other "
        "states in their unit; unnamed states 0). Unset: from the zero state.",
    )
    orbits_at: Annotated[tuple[Number, ...], AfterValidator(at_most_orbits)] = Field(
        (),
        description="Parameter values (in its unit) at which every branch stores a labelled "
        "solution: orbit profiles for phase-plane plots (AUTO UZR).",
    )
    seeds: Annotated[Any, BeforeValidator(as_seeds)] = Field((), description=SEEDS_TEXT)

    explore: Annotated[tuple[Number, ...], AfterValidator(at_most_orbits)] = Field(
        (),
        description="Parameter values (in its unit), each within `range`, at which the "
        "settled motion is classified by time simulation after the AUTO runs: equilibrium, "
        "periodic, quasi-periodic, chaotic or diverged, with the largest Lyapunov exponent, "
        "frequencies and Poincaré section (for the `poincare`, `spectrum` and "
        f"`orbit_diagram` plots); at most {ORBITS_MAX} values.",
    )
    explore_initial: Annotated[dict[str, float] | None, BeforeValidator(as_state)] = Field(
        None,
        description="Initial state of the `explore` simulations, state name -> value (angles "
        "in deg, rates in deg/s, other states in their unit; unnamed states 0), as the "
        f"`seeds`. Unset: the model's first dof at {EXPLORE_OFFSET:g} (deg for an angle).",
    )
    explore_transient: Positive = Field(
        EXPLORE_TRANSIENT,
        description="Periods of the least damped whirl mode (of the linearisation at the "
        "origin) simulated and discarded before the `explore` classification's window of 20 "
        "periods (40 where its Poincaré section and spectrum disagree), > 0 (a weakly "
        "attracting cycle needs many to settle; a trajectory at rest at a stable equilibrium "
        "ends it early).",
    )
    explore_section: Text | None = Field(
        None,
        description="State whose mean level, crossed upwards, is the Poincaré section of the "
        "`explore` classification (`whirl models` lists the states). Unset: the rate of the "
        "model's first dof (classical: `dtheta`): the section is at that dof's minima, the "
        "points of the brute-force orbit diagram.",
    )

    def start_value(self, study: Study) -> float:
        """``start``, or the study value of the parameter when unset (models built by hand)."""
        if self.start is not None:
            return self.start
        names = study.names()
        name = names.canonical(self.parameter)
        return study.parameter_values().get(name, names.defaults()[name])

    def explore_start(self, first: str) -> dict[str, float]:
        """The initial state of the ``explore`` simulations as the seeds give states:
        ``explore_initial``, or the state ``first`` (the model's first dof) at
        :data:`EXPLORE_OFFSET`."""
        return self.explore_initial if self.explore_initial is not None else {
            first: EXPLORE_OFFSET}


def _recipe(stage, spec: OneParameterContinuation):
    from ...continuation.recipes import continue_one_parameter

    return continue_one_parameter(stage, spec)


def _cost(spec: OneParameterContinuation, study: Study) -> int:
    """One run; periodic families (and their cross-checks) dominate."""
    return 1 + 2 * spec.periodic + 2 * spec.periodic * bool(study.cross_check)


def _problems(loc, item: dict, names: Names, family: str, values: dict[str, float]) -> list:
    from ..checks import single_problems

    return single_problems(loc, item, names, family, values)


ONE_PARAMETER = ContinuationType(ContinuationKind.ONE_PARAMETER, 10, OneParameterContinuation,
                                 _recipe, _cost, resolved_parameter, _problems, repeated=True)
