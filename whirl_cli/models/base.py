"""The symbolic model type every whirl model is built into.

A :class:`Model` is one *variant*: a model family (e.g. the classical Reed/Bielawa rotor-nacelle)
with one structural stiffness law applied to one degree of freedom. Everything downstream (the
AUTO Fortran file, the numpy right-hand side for eigenvalues and time simulation, the Jacobians,
AUTO's ``parnames``/``unames``) is derived from the sympy expressions held here, so each model is
defined exactly once.

Conventions
-----------
* ``rhs`` is the physical first-order system dy/dt = f(y, p) in SI units (time in seconds).
* AUTO integrates a non-dimensional version: tau = ``time_scale`` * t, and the AUTO state is
  y* = y / ``state_scale`` (angles stay in rad, angular rates become d(angle)/d tau). Hence
  dy*/dtau = f(S y*, p) / (S * time_scale). Periods from AUTO divide by ``time_scale`` to give
  seconds; eigenvalues multiply by it to give 1/s; Floquet multipliers are unchanged.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import sympy as sp

#: AUTO names (``unames``/``parnames``) are CHARACTER(13) in AUTO-07p 0.9.2.
AUTO_NAME_LENGTH = 13
_NAME_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
#: Names a model may not use: the arguments and locals of the generated Fortran routines.
RESERVED_NAMES = frozenset(
    n.lower()
    for n in (
        "NDIM U ICP PAR IJAC F DFDU DFDP T GETP I NBC NINT FB DBC U0 U1 UOLD UDOT UPOLD FI DINT"
        " FS".split()
    )
)


#: Largest magnitude whirl accepts for any parameter, in its SI unit: far beyond any rotor,
#: and far enough below the double-precision limit that the equations cannot overflow.
MAGNITUDE_LIMIT = 1e9


@dataclass(frozen=True)
class Bounds:
    """The physical range of a parameter's value: ``lower`` <= value <= ``upper`` (strict where
    ``*_open``), a whole number if ``integer``. Both ends are finite (at most
    :data:`MAGNITUDE_LIMIT` in size)."""

    lower: float = -MAGNITUDE_LIMIT
    upper: float = MAGNITUDE_LIMIT
    lower_open: bool = False
    upper_open: bool = False
    integer: bool = False

    def contains(self, value: float) -> bool:
        low = value > self.lower if self.lower_open else value >= self.lower
        high = value < self.upper if self.upper_open else value <= self.upper
        return low and high and (not self.integer or float(value).is_integer())

    def text(self, unit: str = "") -> str:
        """E.g. "> 0 kg m^2", "an integer in [3, 1e+09]", "in [-1e+09, 1e+09] N m/rad"."""
        unit = f" {unit}" if unit and unit != "1" else ""
        if self.upper == MAGNITUDE_LIMIT and not self.upper_open and \
                self.lower > -MAGNITUDE_LIMIT:
            text = f"{'>' if self.lower_open else '>='} {self.lower:g}{unit}"
        else:
            text = (f"in {'(' if self.lower_open else '['}{self.lower:g}, {self.upper:g}"
                    f"{')' if self.upper_open else ']'}{unit}")
        return f"an integer {text}" if self.integer else text


POSITIVE = Bounds(lower=0.0, lower_open=True)
NON_NEGATIVE = Bounds(lower=0.0)


@dataclass(frozen=True)
class Parameter:
    """A model parameter: travels to AUTO through PAR, never compiled in. ``bounds``: its
    physical range (a study value outside it is refused)."""

    name: str
    default: float
    unit: str
    description: str
    aliases: tuple[str, ...] = ()
    bounds: Bounds = Bounds()

    def __post_init__(self) -> None:
        if not self.bounds.contains(self.default):
            raise ValueError(f"parameter {self.name}: datum {self.default!r} outside its bounds "
                             f"{self.bounds.text()}")


@dataclass(frozen=True)
class State:
    """One state of the first-order system, with the unit of its physical (SI) value."""

    name: str
    unit: str
    description: str


@dataclass(frozen=True)
class Model:
    """One model variant, defined symbolically.

    Attributes
    ----------
    name : variant name, also the AUTO equation name (``auto_equations/<name>/<name>.f90``).
    family, law, dof : model family, stiffness law and the degree of freedom it acts on.
    states, parameters : declared states (in order) and parameters (in PAR order).
    rhs : sympy Matrix, shape (n_states, 1): dy/dt in SI units.
    time_scale : reference frequency in rad/s; AUTO's time is tau = time_scale * t.
    state_scale : physical state = state_scale * AUTO state, per state.
    notes : provenance, sign conventions and caveats, shown by ``whirl models``.
    """

    name: str
    family: str
    law: str
    dof: str
    description: str
    states: tuple[State, ...]
    parameters: tuple[Parameter, ...]
    rhs: sp.Matrix = field(repr=False, compare=False)
    time_scale: float = 1.0
    state_scale: tuple[float, ...] = ()
    notes: str = ""
    symmetric: bool = True  # invariant under y -> -y
    #: hub displacement in the plane normal to the spin axis (+x) as ((state index, factor), ...)
    #: for its (y, z) components: used to tell forward from backward whirl.
    hub_plane: tuple[tuple[int, float], tuple[int, float]] = ((1, 1.0), (0, 1.0))

    def __post_init__(self) -> None:
        names = [s.name for s in self.states] + [p.name for p in self.parameters]
        aliases = [a for p in self.parameters for a in p.aliases]
        lowered = [n.lower() for n in names + aliases]
        if len(set(lowered)) != len(lowered):
            raise ValueError(f"model {self.name}: names must be unique ignoring case: {names}")
        for n in names + aliases:
            if not _NAME_RE.match(n) or n.lower() in RESERVED_NAMES or n.lower().startswith("w_"):
                raise ValueError(f"model {self.name}: {n!r} is not a usable Fortran name")
        for s in self.states:
            if len(f"max_{s.name}") > AUTO_NAME_LENGTH:
                raise ValueError(f"model {self.name}: state name {s.name!r} too long for AUTO")
        for p in self.parameters:
            if len(p.name) > AUTO_NAME_LENGTH:
                raise ValueError(f"model {self.name}: parameter name {p.name!r} too long")
        if len(self.state_scale) != len(self.states) or self.rhs.shape != (len(self.states), 1):
            raise ValueError(f"model {self.name}: rhs/state_scale do not match the states")
        free = {s.name for s in self.rhs.free_symbols}
        undeclared = free - set(names)
        if undeclared:
            raise ValueError(f"model {self.name}: undeclared symbols {sorted(undeclared)}")

    # ------------------------------------------------------------------ names and lookup
    @property
    def n_states(self) -> int:
        return len(self.states)

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
        return table

    def canonical(self, name: str) -> str:
        """Parameter name for ``name`` or one of its aliases; KeyError if unknown."""
        return self._alias_map[name]

    def known_parameter_names(self) -> tuple[str, ...]:
        """Every accepted spelling: parameter names and their aliases."""
        return tuple(sorted(self._alias_map))

    def parameter(self, name: str) -> Parameter:
        canonical = self.canonical(name)
        return next(p for p in self.parameters if p.name == canonical)

    def defaults(self) -> dict[str, float]:
        return {p.name: float(p.default) for p in self.parameters}

    def parameter_vector(self, overrides: dict[str, float] | None = None) -> np.ndarray:
        """Parameter values in declaration order: defaults with ``overrides`` applied."""
        values = self.defaults()
        for key, value in (overrides or {}).items():
            values[self.canonical(key)] = float(value)
        return np.array([values[p.name] for p in self.parameters], dtype=float)

    # ------------------------------------------------------------------ symbols
    @cached_property
    def state_symbols(self) -> tuple[sp.Symbol, ...]:
        return tuple(sp.Symbol(s.name, real=True) for s in self.states)

    @cached_property
    def parameter_symbols(self) -> tuple[sp.Symbol, ...]:
        return tuple(sp.Symbol(p.name, real=True) for p in self.parameters)

    @cached_property
    def auto_rhs(self) -> sp.Matrix:
        """dy*/dtau: the non-dimensional right-hand side AUTO integrates (see module doc)."""
        scale = [sp.Rational(repr(float(s))) for s in self.state_scale]  # exact decimals
        time_scale = sp.Rational(repr(float(self.time_scale)))
        subs = {y: sc * y for y, sc in zip(self.state_symbols, scale, strict=True)}
        f = self.rhs.xreplace(subs)
        return sp.Matrix([f[i] / (scale[i] * time_scale) for i in range(self.n_states)])

    # ------------------------------------------------------------------ numpy functions
    @cached_property
    def _numpy_rhs(self):
        return sp.lambdify(
            (self.state_symbols, self.parameter_symbols), list(self.rhs), modules="numpy", cse=True
        )

    @cached_property
    def _numpy_jacobian(self):
        jac = self.rhs.jacobian(self.state_symbols)
        return sp.lambdify(
            (self.state_symbols, self.parameter_symbols), list(jac), modules="numpy", cse=True
        )

    @cached_property
    def _numpy_derivative_tensors(self):
        """(flat indices, function of (y, params)) of the non-zero second and third derivatives
        of the rhs with respect to the states (flattened one after the other)."""
        y, n = self.state_symbols, self.n_states
        rows = [sp.diff(self.rhs[i], y[j]) for i in range(n) for j in range(n)]
        second = [sp.diff(row, y[k]) for row in rows for k in range(n)]
        third = [sp.diff(entry, y[m]) for entry in second for m in range(n)]
        nonzero = [k for k, entry in enumerate(second + third) if entry != 0]
        entries = [(second + third)[k] for k in nonzero]
        return np.array(nonzero, dtype=int), sp.lambdify(
            (self.state_symbols, self.parameter_symbols), entries, modules="numpy", cse=True)

    def derivative_tensors(self, y: np.ndarray, params: np.ndarray
                           ) -> tuple[np.ndarray, np.ndarray]:
        """(d2f/dy2, d3f/dy3) at one point, shapes (n, n, n) and (n, n, n, n), SI units:
        entry [i, j, k(, m)] is the derivative of dy_i/dt by y_j, y_k (and y_m)."""
        n = self.n_states
        nonzero, function = self._numpy_derivative_tensors
        values = np.zeros(n ** 3 + n ** 4)
        values[nonzero] = np.array(function(tuple(y), tuple(params)), dtype=float)
        return values[:n ** 3].reshape(n, n, n), values[n ** 3:].reshape(n, n, n, n)

    def field_at(self, params: np.ndarray):
        """(f, J): dy/dt (SI) and its Jacobian as fast functions of the state alone, for fixed
        parameter values (substituted symbolically once; for time integration)."""
        values = {sym: sp.Float(float(v)) for sym, v in zip(self.parameter_symbols, params,
                                                            strict=True)}
        rhs = self.rhs.xreplace(values)
        function = sp.lambdify((self.state_symbols,), list(rhs), modules="numpy", cse=True)
        jacobian = sp.lambdify((self.state_symbols,), rhs.jacobian(self.state_symbols),
                               modules="numpy", cse=True)
        return (lambda y: np.array(function(y), dtype=float),
                lambda y: np.array(jacobian(y), dtype=float))

    def rhs_numpy(self, y: np.ndarray, params: np.ndarray) -> np.ndarray:
        """dy/dt in SI units. ``y``: (n,) or (n, M); ``params``: (P,) or (P, M)."""
        values = self._numpy_rhs(tuple(y), tuple(params))
        return np.stack(np.broadcast_arrays(*values), axis=0)

    def jacobian_numpy(self, y: np.ndarray, params: np.ndarray) -> np.ndarray:
        """df/dy in 1/s units; shape (..., n, n) broadcast over the trailing axes of inputs.

        ``y``: (n,) or (n, M); ``params``: (P,) or (P, M). Returns (n, n) or (M, n, n).
        """
        n = self.n_states
        values = self._numpy_jacobian(tuple(y), tuple(params))
        stacked = np.stack(np.broadcast_arrays(*values), axis=-1)  # (..., n*n)
        return stacked.reshape(stacked.shape[:-1] + (n, n))

    def describe(self) -> str:
        """Human-readable summary: states, parameters with defaults and units."""
        lines = [f"{self.name}: {self.description}"]
        lines.append(f"  time scale: tau = {self.time_scale:g} rad/s * t")
        lines.append("  states: " + ", ".join(f"{s.name} [{s.unit}]" for s in self.states))
        lines.append("  parameters:")
        for p in self.parameters:
            alias = f" (alias {', '.join(p.aliases)})" if p.aliases else ""
            lines.append(f"    {p.name:<10} {p.default:<12.6g} {p.unit:<14} {p.description}{alias}"
                         f"; {p.bounds.text()}")
        if self.notes:
            lines.append("  notes: " + self.notes)
        return "\n".join(lines)
