"""Models as data: what a model family declares, and nothing derived from it.

A :class:`Family` is a model as its author writes it down: its degrees of freedom (with a
typical amplitude that scales every amplitude threshold whirl uses), its parameters (datum,
unit, description, physical bounds), the structural stiffness term of each degree of freedom
that a stiffness law may replace, its first-order states x if any (an aerodynamic lag, an
actuator, or every state of a plain first-order system), and its equations of motion

    M(p) q'' = G(q, q', x, p) - S(q, p),     S_i = K_i q_i   (or a law's restoring force),
    x' = F(q, q', x, p),

with M the (possibly full) mass matrix, G every other generalised force (aerodynamic,
gyroscopic, damping) and S the structural stiffness. Building the first-order system, its
derivatives, the AUTO Fortran and the numeric functions is whirl's job
(:mod:`whirl_cli.models.symbolic`), done ahead of any run.

This module imports no sympy: a declaration is read (names, units, bounds) by every command,
and only the ``equations`` function, called when code is generated, builds expressions.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field

#: Largest magnitude whirl accepts for any parameter, in its SI unit: far beyond any rotor,
#: and far enough below the double-precision limit that the equations cannot overflow.
MAGNITUDE_LIMIT = 1e9
#: AUTO names (``unames``/``parnames``) are CHARACTER(13) in AUTO-07p 0.9.2.
AUTO_NAME_LENGTH = 13
NAME_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
#: Names a model may not use: the arguments and locals of the generated Fortran routines.
RESERVED_NAMES = frozenset(
    n.lower()
    for n in (
        "NDIM U ICP PAR IJAC F DFDU DFDP T GETP I NBC NINT FB DBC U0 U1 UOLD UDOT UPOLD FI DINT"
        " FS".split()
    )
)


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
        """E.g. "> 0 kg m^2", "an integer >= 3", "in [-1e+09, 1e+09] N m/rad"."""
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
class Dof:
    """A degree of freedom q_i and its rate.

    ``amplitude``: a typical amplitude of its motion, in ``unit``: the scale of every amplitude
    threshold whirl applies to it (a family has grown, shrunk back onto a Hopf point, ...) and
    of AUTO's non-dimensional state (q / amplitude). ``stiffness``: the parameter of its linear
    structural stiffness K_i; the term K_i q_i is what a stiffness law on this dof replaces,
    with K_i as the law's linear coefficient.
    """

    name: str
    rate: str
    unit: str
    description: str
    amplitude: float
    stiffness: str

    @property
    def rate_unit(self) -> str:
        return f"{self.unit}/s"


@dataclass(frozen=True)
class FirstOrderState:
    """A first-order state x_j (its own rate x_j' = F_j is declared, no stiffness law attaches
    to it). ``amplitude``: its typical size in ``unit``, the scale of AUTO's state."""

    name: str
    unit: str
    description: str
    amplitude: float = 1.0


#: A combination of first-order states giving one component of a path: ((state index,
#: factor), ...).
Combination = tuple[tuple[int, float], ...]


@dataclass(frozen=True)
class ModeGroup:
    """Dofs whose modes are told apart from the other groups' by their eigenvector energy
    (e.g. nacelle vs gimbal), and the path in the plane normal to the spin axis (+x) whose
    sense tells forward from backward whirl for this group's modes: components (y, z), each a
    :data:`Combination` of the first-order states (for a nacelle the hub, for a disc its tilt).
    """

    name: str
    dofs: tuple[str, ...]
    path: tuple[Combination, Combination]


@dataclass(frozen=True)
class Constraint:
    """A physical condition on several parameters at once (e.g. I_y - I_d > 0): ``holds``
    takes the values by name (SI units). A study whose values break it is refused, with
    ``reason`` (e.g. "the nacelle-only inertia I_n = I_y - I_d must be > 0") reported at
    the first of ``names`` the study sets."""

    names: tuple[str, ...]
    holds: Callable[[dict], bool] = field(repr=False, compare=False)
    reason: str = ""


#: The equations of a family: given a symbol for every dof (``q[name]``), rate (``v[name]``),
#: parameter (``p[name]``) and first-order state (``x[name]``), return (M, G, F): the mass
#: matrix (n x n, parameters only), the generalised forces other than the structural
#: stiffness (n x 1) in dof order, and the rates of the first-order states (m x 1, in their
#: order; 0 x 1 without any), as sympy matrices.
Equations = Callable[[dict, dict, dict], tuple]


@dataclass(frozen=True)
class Family:
    """A model family as declared (see the module doc).

    ``time_scale``: a reference frequency in rad/s (AUTO's time is tau = time_scale * t).
    ``hub``: the hub displacement normal to the spin axis (+x), components (y, z), each a
    combination ((state index, factor), ...) of the first-order states: it tells forward from
    backward whirl. ``mode_groups``: the dofs by mode group with each group's whirl path
    (default: one group, all dofs, the hub path). ``constraints``: conditions on several
    parameters at once (each parameter's own range is its ``bounds``). ``symmetric``: the
    equations are invariant under y -> -y (equilibria and
    secondary branches come in +/- pairs). ``linear``: apart from the stiffness laws, the
    equations are linear in the states (so a study without nonlinear law coefficients is a
    linear system). ``provisional``: whirl's own derivation, not yet checked against the
    published model. ``first_order``: the first-order states, after the dofs and rates in the
    state vector. ``key``: for a model file, the sha256 of what it declares (its
    generated code is keyed on it); ``source``: the file's text (stored with results).
    """

    name: str
    description: str
    dofs: tuple[Dof, ...]
    parameters: tuple[Parameter, ...]
    equations: Equations = field(repr=False, compare=False)
    time_scale: float = 1.0
    hub: tuple[Combination, Combination] = ((), ())
    mode_groups: tuple[ModeGroup, ...] = ()
    constraints: tuple[Constraint, ...] = ()
    symmetric: bool = True
    linear: bool = True
    provisional: bool = False
    notes: str = ""
    first_order: tuple[FirstOrderState, ...] = ()
    key: str = ""
    source: str = field(default="", repr=False, compare=False)

    def __post_init__(self) -> None:
        names = [d.name for d in self.dofs] + [d.rate for d in self.dofs]
        names += [x.name for x in self.first_order] + [p.name for p in self.parameters]
        aliases = [a for p in self.parameters for a in p.aliases]
        lowered = [n.lower() for n in names + aliases]
        if len(set(lowered)) != len(lowered):
            raise ValueError(f"model {self.name}: names must be unique ignoring case: {names}")
        for n in names + aliases:
            if not NAME_RE.match(n) or n.lower() in RESERVED_NAMES or n.lower().startswith("w_"):
                raise ValueError(f"model {self.name}: {n!r} is not a usable Fortran name")
        for d in self.dofs:
            if len(f"max_{d.rate}") > AUTO_NAME_LENGTH:
                raise ValueError(f"model {self.name}: state name {d.rate!r} too long for AUTO")
            if d.stiffness not in {p.name for p in self.parameters}:
                raise ValueError(f"model {self.name}: dof {d.name}: no parameter {d.stiffness}")
            if not (math.isfinite(d.amplitude) and d.amplitude > 0):
                raise ValueError(f"model {self.name}: dof {d.name}: amplitude must be > 0")
        if not self.dofs and not self.first_order:
            raise ValueError(f"model {self.name}: no dofs and no first-order states")
        for x in self.first_order:
            if len(f"max_{x.name}") > AUTO_NAME_LENGTH:
                raise ValueError(f"model {self.name}: state name {x.name!r} too long for AUTO")
            if not (math.isfinite(x.amplitude) and x.amplitude > 0):
                raise ValueError(f"model {self.name}: state {x.name}: amplitude must be > 0")
        for p in self.parameters:
            if len(p.name) > AUTO_NAME_LENGTH:
                raise ValueError(f"model {self.name}: parameter name {p.name!r} too long")
        grouped = [d for g in self.mode_groups for d in g.dofs]
        if self.mode_groups and sorted(grouped) != sorted(self.dof_names):
            raise ValueError(f"model {self.name}: mode groups must hold every dof once, got "
                             f"{grouped}")
        datum = {p.name: p.default for p in self.parameters}
        for c in self.constraints:
            if not set(c.names) <= set(datum) or not c.holds(datum):
                raise ValueError(f"model {self.name}: constraint on {c.names} fails at datum")

    @property
    def groups(self) -> tuple[ModeGroup, ...]:
        """The declared mode groups, or one group ``all`` of every dof with the hub path."""
        return self.mode_groups or (ModeGroup("all", self.dof_names, self.hub),)

    @property
    def dof_names(self) -> tuple[str, ...]:
        return tuple(d.name for d in self.dofs)

    @property
    def state_names(self) -> tuple[str, ...]:
        """Every state in state order: the dofs, their rates, the first-order states."""
        return (self.dof_names + tuple(d.rate for d in self.dofs)
                + tuple(x.name for x in self.first_order))

    def dof(self, name: str) -> Dof:
        return next(d for d in self.dofs if d.name == name)
