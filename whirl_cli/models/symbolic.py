"""A model variant's equations as sympy expressions: what code generation starts from.

Built from a family's declaration (:mod:`whirl_cli.models.declaration`) and the stiffness law
on each degree of freedom, never at run time: the AUTO Fortran and the numeric Python module
(:mod:`whirl_cli.models.numeric`) are generated from it once and cached.

With q the dofs, v their rates, x the first-order states and y = [q, v, x] the state, the
first-order system is

    q' = v,     v' = a = M(p)^-1 R(y, p),     R = G(y, p) - S(q, p),     x' = F(y, p),

S_i the structural stiffness term of dof i (K_i q_i, or its law's restoring force). The mass
matrix depends on the parameters only, so every derivative of a with respect to the states is
M^-1 times the same derivative of R. Only R and its derivatives are differentiated
symbolically (never an inverted mass matrix: n^4 derivatives of M^-1 R would blow up for a full
8 x 8 M); the solve with M is numeric, in the generated code.

``exact=True`` builds the reference form instead: every law that smooths a piecewise law
(freeplay) gives its exact restoring force on the piece named by one more parameter per such
dof (``piece_<dof>``, after the model's parameters), so each piece is smooth; the time
simulation of the exact law switches pieces at the breakpoints
(:func:`whirl_cli.analysis.simulate.integrate_exact`). Never given to AUTO.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import sympy as sp

from .variant import Model


@dataclass(frozen=True)
class Symbolic:
    """The symbols and expressions of one variant (physical SI units, time in seconds)."""

    model: Model
    exact: bool = False

    @cached_property
    def q(self) -> tuple[sp.Symbol, ...]:
        return tuple(sp.Symbol(d.name, real=True) for d in self.model.family.dofs)

    @cached_property
    def v(self) -> tuple[sp.Symbol, ...]:
        return tuple(sp.Symbol(d.rate, real=True) for d in self.model.family.dofs)

    @cached_property
    def x(self) -> tuple[sp.Symbol, ...]:
        return tuple(sp.Symbol(s.name, real=True) for s in self.model.family.first_order)

    @property
    def states(self) -> tuple[sp.Symbol, ...]:
        return self.q + self.v + self.x

    @cached_property
    def parameters(self) -> tuple[sp.Symbol, ...]:
        """The model's parameters, and with ``exact`` the piece of each piecewise dof."""
        pieces = self.model.piece_names if self.exact else ()
        return tuple(sp.Symbol(name, real=True)
                     for name in (*self.model.parameter_names, *pieces))

    @cached_property
    def _built(self) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
        family = self.model.family
        q = dict(zip(family.dof_names, self.q, strict=True))
        v = {d.name: s for d, s in zip(family.dofs, self.v, strict=True)}
        x = {str(s): s for s in self.x}
        p = {str(s): s for s in self.parameters}
        mass, forces, rates = family.equations(q, v, p, x)
        mass, forces, rates = sp.Matrix(mass), sp.Matrix(forces), sp.Matrix(rates)
        n, m = len(family.dofs), len(self.x)
        if mass.shape != (n, n) or forces.shape != (n, 1) or rates.shape != (m, 1):
            raise ValueError(f"model {family.name}: equations must give M ({n} x {n}), G "
                             f"({n} x 1) and F ({m} x 1), got {mass.shape}, {forces.shape} "
                             f"and {rates.shape}")
        if mass.free_symbols & set(self.states):
            raise ValueError(f"model {family.name}: the mass matrix may not depend on the states")
        stiffness = []
        for dof, law in zip(family.dofs, self.model.law_objects, strict=True):
            keys = {c.key: p[law.parameter_name(c.key, dof.name)] for c in law.coefficients}
            if self.exact and law.exact is not None:
                piece = p[f"piece_{dof.name}"]
                stiffness.append(law.exact(q[dof.name], p[dof.stiffness], keys, piece))
            else:
                stiffness.append(law.moment(q[dof.name], p[dof.stiffness], keys))
        residual = forces - sp.Matrix(n, 1, stiffness)
        undeclared = (residual.free_symbols | mass.free_symbols | rates.free_symbols) \
            - set(self.states) - set(self.parameters)
        if undeclared:
            names = sorted(map(str, undeclared))
            raise ValueError(f"model {family.name}: undeclared symbols {names}")
        return mass, residual, rates

    @property
    def mass(self) -> sp.Matrix:
        """M(p), n_dof x n_dof."""
        return self._built[0]

    @property
    def residual(self) -> sp.Matrix:
        """R(y, p) = G - S, n_dof x 1."""
        return self._built[1]

    @property
    def rates(self) -> sp.Matrix:
        """F(y, p): the rates of the first-order states, n_first_order x 1."""
        return self._built[2]

    @property
    def rows(self) -> sp.Matrix:
        """[R; F]: every right-hand side row not fixed by q' = v (R is still to be solved
        with M), (n_dof + n_first_order) x 1."""
        return self.residual.col_join(self.rates)

    @cached_property
    def diagonal_mass(self) -> bool:
        return self.mass.is_diagonal()

    @cached_property
    def residual_jacobian(self) -> sp.Matrix:
        """dR/dy, n_dof x n_states."""
        return self.residual.jacobian(self.states)

    @cached_property
    def residual_parameter_jacobian(self) -> sp.Matrix:
        """dR/dp, n_dof x n_parameters."""
        return self.residual.jacobian(self.parameters)

    @cached_property
    def rates_jacobian(self) -> sp.Matrix:
        """dF/dy, n_first_order x n_states."""
        return self.rates.jacobian(self.states)

    @cached_property
    def rates_parameter_jacobian(self) -> sp.Matrix:
        """dF/dp, n_first_order x n_parameters."""
        return self.rates.jacobian(self.parameters)

    @cached_property
    def mass_parameter_derivatives(self) -> list[tuple[int, sp.Matrix]]:
        """(parameter index, dM/dp) for every parameter M depends on."""
        return [(k, self.mass.diff(s)) for k, s in enumerate(self.parameters)
                if s in self.mass.free_symbols]

    @cached_property
    def residual_tensors(self) -> tuple[list[int], list[sp.Expr]]:
        """The non-zero second and third derivatives of [R; F] by the states: (flat indices
        into the concatenated (r, n, n) and (r, n, n, n) arrays, r = n_dof + n_first_order,
        expressions)."""
        y, n = self.states, len(self.states)
        rows = [sp.diff(r, y[j]) for r in self.rows for j in range(n)]
        second = [sp.diff(row, y[k]) for row in rows for k in range(n)]
        third = [sp.diff(entry, y[m]) if entry != 0 else sp.S.Zero
                 for entry in second for m in range(n)]
        entries = second + third
        nonzero = [k for k, e in enumerate(entries) if e != 0]
        return nonzero, [entries[k] for k in nonzero]

    def rhs(self) -> sp.Matrix:
        """The first-order right-hand side [v, M^-1 R, F] (for tests of small models only: it
        inverts M symbolically)."""
        accelerations = self.mass.inv() * self.residual if self.q else []
        return sp.Matrix([*self.v, *accelerations, *self.rates])
