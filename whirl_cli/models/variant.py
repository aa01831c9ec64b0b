"""A model variant: a family with a stiffness law on each degree of freedom, as whirl runs it.

Everything here is data and numbers: names, units, bounds, datum values, scales, and the
numeric right-hand side, Jacobian and derivative tensors, which come from a generated Python
module (:mod:`whirl_cli.models.numeric`, built from the sympy equations once and cached), so
that running a study never imports sympy.

Conventions
-----------
* The state is y = [q, v, x]: the dofs in declaration order, then their rates, then the
  first-order states (if any), in SI units; the physical system is dy/dt = f(y, p) with time
  in seconds.
* AUTO integrates a non-dimensional version: tau = ``time_scale`` * t and y* = y /
  ``state_scale``, with each dof scaled by its typical amplitude and each rate by that times
  ``time_scale``, each first-order state by its typical amplitude. Hence dy*/dtau =
  f(S y*, p) / (S * time_scale). Periods from AUTO divide by ``time_scale`` to give seconds;
  eigenvalues multiply by it to give 1/s; Floquet multipliers are unchanged. Amplitude
  thresholds are set in these units, so they scale with each dof's typical amplitude.
* Parameters: the family's, then each law's coefficients named by dof (``K2_theta``), in dof
  order; all of them travel to AUTO through PAR.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

from .declaration import Dof, Family, Parameter, State
from .laws import LAWS, Law

if TYPE_CHECKING:  # numpy is imported where numbers are computed: validating a study needs none
    import numpy as np


@dataclass(frozen=True)
class Model:
    """One variant: ``family`` with the law named ``laws[i]`` on its i-th dof."""

    family: Family
    laws: tuple[str, ...]

    def __post_init__(self) -> None:
        if len(self.laws) != len(self.family.dofs) or not set(self.laws) <= set(LAWS):
            raise ValueError(f"model {self.family.name}: one law of {sorted(LAWS)} per dof "
                             f"{self.family.dof_names}, got {self.laws}")
        names = [p.name for p in self.parameters]
        if len(set(names)) != len(names):
            raise ValueError(f"model {self.name}: law coefficients collide with parameters")

    # ------------------------------------------------------------------ what it is
    @cached_property
    def name(self) -> str:
        """The variant's name, also the AUTO equation name: ``classical_poly`` (one law on
        every dof) or ``<family>_<law>_<dof>_...``."""
        shorts = [law.short for law in self.law_objects]
        if len(set(shorts)) == 1:
            return f"{self.family.name}_{shorts[0]}"
        return "_".join([self.family.name, *(f"{s}_{d}" for s, d in
                                             zip(shorts, self.family.dof_names, strict=True))])

    @property
    def description(self) -> str:
        laws = ", ".join(f"{law} on {dof}" for law, dof in zip(self.laws, self.family.dof_names,
                                                               strict=True))
        return f"{self.family.description}; {laws}" if laws else self.family.description

    @property
    def notes(self) -> str:
        return self.family.notes

    @property
    def law_objects(self) -> tuple[Law, ...]:
        return tuple(LAWS[name] for name in self.laws)

    @property
    def dofs(self) -> tuple[Dof, ...]:
        return self.family.dofs

    @property
    def time_scale(self) -> float:
        return self.family.time_scale

    @property
    def symmetric(self) -> bool:
        return self.family.symmetric

    @cached_property
    def states(self) -> tuple[State, ...]:
        dofs = self.family.dofs
        return (tuple(State(d.name, d.unit, d.description) for d in dofs)
                + tuple(State(d.rate, d.rate_unit, f"rate of {d.name}") for d in dofs)
                + tuple(State(x.name, x.unit, x.description) for x in self.family.first_order))

    @cached_property
    def state_scale(self) -> tuple[float, ...]:
        """Physical state = state_scale * AUTO state (see the module doc)."""
        amplitudes = tuple(float(d.amplitude) for d in self.family.dofs)
        return (amplitudes + tuple(a * self.time_scale for a in amplitudes)
                + tuple(float(x.amplitude) for x in self.family.first_order))

    @cached_property
    def parameters(self) -> tuple[Parameter, ...]:
        declared = {p.name: p for p in self.family.parameters}
        coefficients = tuple(p for dof, law in zip(self.family.dofs, self.law_objects, strict=True)
                             for p in law.parameters(dof, declared[dof.stiffness]))
        return self.family.parameters + coefficients

    @cached_property
    def typical_amplitudes(self) -> tuple[float, ...]:
        """Each state's typical size, in state order: a dof's amplitude for the dof and for its
        rate (per second), a first-order state's own: states divided by it are in typical
        amplitudes, for tolerances that hold in any unit."""
        amplitudes = tuple(float(d.amplitude) for d in self.family.dofs)
        return amplitudes + amplitudes + tuple(float(x.amplitude)
                                               for x in self.family.first_order)

    @cached_property
    def positions(self) -> tuple[int, ...]:
        """Indices of the states that are not a dof's rate: the dofs, then the first-order
        states (what amplitude bounds, divergence tests and plots of a motion watch)."""
        k = self.n_dof
        return tuple(range(k)) + tuple(range(2 * k, self.n_states))

    @cached_property
    def hub_matrix(self) -> np.ndarray:
        """(2, n): the hub displacement (y, z) normal to the spin axis is hub_matrix @ state."""
        import numpy as np

        matrix = np.zeros((2, self.n_states))
        for row, terms in enumerate(self.family.hub):
            for index, factor in terms:
                matrix[row, index] = factor
        return matrix

    @cached_property
    def mode_groups(self) -> tuple[tuple[str, tuple[int, ...], np.ndarray], ...]:
        """(name, dof indices, path matrix (2, n)) per mode group of the family (one group
        ``all`` unless it declares more): a mode belongs to the group holding most of its
        energy, and its whirl sense is that of the group's path (path_matrix @ state)."""
        import numpy as np

        groups = []
        for group in self.family.groups:
            matrix = np.zeros((2, self.n_states))
            for row, terms in enumerate(group.path):
                for index, factor in terms:
                    matrix[row, index] = factor
            groups.append((group.name, tuple(self.family.dof_names.index(d) for d in group.dofs),
                           matrix))
        return tuple(groups)

    # ------------------------------------------------------------------ names and lookup
    @property
    def n_states(self) -> int:
        return 2 * len(self.family.dofs) + len(self.family.first_order)

    @property
    def n_dof(self) -> int:
        """The number of dofs: the first n_dof states are the dofs, the next n_dof their rates."""
        return len(self.family.dofs)

    @property
    def state_names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.states)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)

    @cached_property
    def _alias_map(self) -> dict[str, str]:
        table = {p.name: p.name for p in self.parameters}
        for p in self.parameters:
            for a in p.aliases:
                table[a] = p.name
        table.update(self.law_stiffness_aliases())
        return table

    def law_stiffness_aliases(self) -> dict[str, str]:
        """Aliases of the stiffnesses a law names itself: ``K_out_theta`` -> ``K_theta`` for
        freeplay on pitch (its ``stiffness_key`` on that dof)."""
        return {law.parameter_name(law.stiffness_key, dof.name): dof.stiffness
                for dof, law in zip(self.family.dofs, self.law_objects, strict=True)
                if law.stiffness_key is not None}

    def canonical(self, name: str) -> str:
        """Parameter name for ``name`` or one of its aliases; KeyError if unknown."""
        return self._alias_map[name]

    def known_parameter_names(self) -> tuple[str, ...]:
        """Every accepted spelling: parameter names and their aliases."""
        return tuple(sorted(self._alias_map))

    def parameter(self, name: str) -> Parameter:
        canonical = self.canonical(name)
        return next(p for p in self.parameters if p.name == canonical)

    def law_on(self, dof: str) -> Law:
        return self.law_objects[self.family.dof_names.index(dof)]

    def coefficient_names(self, dof: str) -> dict[str, str]:
        """The law on ``dof``: its study keys and the parameters they become (K2 -> K2_theta;
        a law's ``stiffness_key`` becomes the dof's stiffness: freeplay's K_out -> K_theta)."""
        law = self.law_on(dof)
        names = {c.key: law.parameter_name(c.key, dof) for c in law.coefficients}
        if law.stiffness_key is not None:
            names[law.stiffness_key] = self.family.dof(dof).stiffness
        return names

    def law_values(self, dof: str, values: dict[str, float]) -> dict[str, float]:
        """The coefficients of the law on ``dof`` by study key, from parameter values by
        canonical name (unset ones at their datum)."""
        full = {**self.defaults(), **values}
        return {key: full[name] for key, name in self.coefficient_names(dof).items()}

    @property
    def piecewise_dofs(self) -> tuple[int, ...]:
        """Indices of the dofs whose law smooths a piecewise one (freeplay): the exact law's
        pieces switch at breakpoints of these dofs (:meth:`breakpoints`)."""
        return tuple(i for i, law in enumerate(self.law_objects) if law.exact is not None)

    def breakpoints(self, dof: int, values: dict[str, float]) -> tuple[float, ...]:
        """Where the pieces of the exact law on the ``dof``-th dof meet, in its unit (for
        these parameter values by canonical name; unset ones at their datum)."""
        law = self.law_objects[dof]
        assert law.breakpoints is not None, f"the {law.name} law has no pieces"
        return tuple(law.breakpoints(self.law_values(self.family.dof_names[dof], values)))

    @property
    def smoothing_parameters(self) -> tuple[str, ...]:
        """The parameters that set how much a law smooths a piecewise one (freeplay's
        ``epsilon_<dof>``; the exact law returns as they go to 0)."""
        return tuple(law.parameter_name(law.smoothing_key, dof)
                     for dof, law in zip(self.family.dof_names, self.law_objects, strict=True)
                     if law.smoothing_key is not None)

    @property
    def piece_names(self) -> tuple[str, ...]:
        """The extra parameters of the exact-law numeric module: ``piece_<dof>`` per
        piecewise dof, the index of the piece it is on (0 below its first breakpoint)."""
        return tuple(f"piece_{self.family.dof_names[i]}" for i in self.piecewise_dofs)

    def law_parameter_names(self) -> frozenset[str]:
        """Every law coefficient parameter (set in a study's law blocks, not ``parameters``)."""
        return frozenset(n for d in self.family.dof_names
                         for n in self.coefficient_names(d).values())

    def defaults(self) -> dict[str, float]:
        return {p.name: float(p.default) for p in self.parameters}

    def parameter_vector(self, overrides: dict[str, float] | None = None) -> np.ndarray:
        """Parameter values in declaration order: defaults with ``overrides`` applied."""
        import numpy as np

        values = self.defaults()
        for key, value in (overrides or {}).items():
            values[self.canonical(key)] = float(value)
        return np.array([values[p.name] for p in self.parameters], dtype=float)

    def is_linear(self, values: dict[str, float]) -> bool:
        """True if the equations are linear in the states for these parameter values (canonical
        names; unset ones at their datum): the family's own terms are, and every law is K x."""
        if not self.family.linear:
            return False
        return all(law.is_linear(self.law_values(dof, values))
                   for dof, law in zip(self.family.dof_names, self.law_objects, strict=True))

    # ------------------------------------------------------------------ numbers
    @cached_property
    def numeric(self):
        """The generated numeric functions (:class:`whirl_cli.models.numeric.Numeric`)."""
        from .numeric import load

        return load(self)

    @cached_property
    def exact_numeric(self):
        """The numeric functions of the exact piecewise laws (:attr:`piecewise_dofs`), one
        piece per dof chosen by the trailing parameters :attr:`piece_names`; the other laws
        as in :attr:`numeric`. For the reference simulation only (not continuable)."""
        from .numeric import load

        return load(self, exact=True)

    def rhs_numpy(self, y: np.ndarray, params: np.ndarray) -> np.ndarray:
        """dy/dt in SI units. ``y``: (n,) or (n, M); ``params``: (P,) or (P, M)."""
        return self.numeric.rhs(y, params)

    def jacobian_numpy(self, y: np.ndarray, params: np.ndarray) -> np.ndarray:
        """df/dy in 1/s; (n, n), or (M, n, n) for inputs with a trailing axis of M points."""
        return self.numeric.jacobian(y, params)

    def derivative_tensors(self, y: np.ndarray, params: np.ndarray
                           ) -> tuple[np.ndarray, np.ndarray]:
        """(d2f/dy2, d3f/dy3) at one point, shapes (n, n, n) and (n, n, n, n), SI units:
        entry [i, j, k(, m)] is the derivative of dy_i/dt by y_j, y_k (and y_m)."""
        return self.numeric.tensors(y, params)

    def mass_numpy(self, params: np.ndarray) -> np.ndarray:
        """The mass matrix M(p), (n_dof, n_dof), or (M, n_dof, n_dof) for params (P, M)."""
        return self.numeric.mass_matrix(params)

    def field_at(self, params: np.ndarray):
        """(f, J): dy/dt (SI) and its Jacobian as fast functions of the state alone, for fixed
        parameter values (for time integration)."""
        return self.numeric.field_at(params)

    def describe(self) -> str:
        """Human-readable summary: states, parameters with defaults, units and bounds."""
        lines = [f"{self.name}: {self.description}"
                 + (" [provisional: whirl's own derivation]" if self.family.provisional else "")]
        lines.append(f"  time scale: tau = {self.time_scale:g} rad/s * t")
        lines.append("  degrees of freedom: " + (", ".join(
            f"{d.name} [{d.unit}] (typical amplitude {d.amplitude:g} {d.unit}, stiffness "
            f"{d.stiffness})" for d in self.family.dofs) or "none"))
        if self.family.first_order:
            lines.append("  first-order states: " + ", ".join(
                f"{x.name} [{x.unit}] (typical amplitude {x.amplitude:g})"
                for x in self.family.first_order))
        lines.append("  states: " + ", ".join(f"{s.name} [{s.unit}]" for s in self.states))
        lines.append("  parameters:")
        for p in self.parameters:
            alias = f" (alias {', '.join(p.aliases)})" if p.aliases else ""
            lines.append(f"    {p.name:<10} {p.default:<12.6g} {p.unit:<14} {p.description}{alias}"
                         f"; {p.bounds.text()}")
        for dof, law in zip(self.family.dof_names, self.law_objects, strict=True):
            if law.stiffness_key is not None:
                names = self.coefficient_names(dof)
                lines.append(f"  {law.name} on {dof}: {law.description}; "
                             f"{law.stiffness_key} is {names[law.stiffness_key]} (alias "
                             f"{law.parameter_name(law.stiffness_key, dof)})")
        if self.family.mode_groups:
            lines.append("  mode groups: " + ", ".join(
                f"{g.name} ({', '.join(g.dofs)})" for g in self.family.mode_groups))
        for constraint in self.family.constraints:
            lines.append(f"  constraint: {constraint.reason}")
        if self.notes:
            lines.append("  notes: " + self.notes)
        return "\n".join(lines)
