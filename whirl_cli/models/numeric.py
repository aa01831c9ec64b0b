"""The numeric right-hand side, Jacobian and derivative tensors of a variant, generated ahead.

:func:`numeric_source` prints a variant's sympy expressions (:mod:`whirl_cli.models.symbolic`)
as a plain Python module of numpy code; :func:`load` generates it once per variant and code
version into the cache (:mod:`whirl_cli.cache`) and afterwards only reads it, so a run never
imports sympy. The generated module holds, for R = G - S (the forces of the mass equation
M(p) v' = R):

* ``prepare(p)``: the parameter values and every subexpression that depends on parameters
  only (aerodynamic coefficients, ...), computed once per parameter set;
* ``residual(y, c)``, ``residual_jacobian(y, c)``: [R; F] and its derivative by y from the
  state and ``c = prepare(p)`` (F the rates of the first-order states, if any);
  ``residual_tensors(y, p)``: the non-zero second and third derivatives;
* ``mass(p)``: the entries of M, and ``DIAGONAL_MASS``.

The states and parameters are local names there, so every name the module makes up
(arguments, written ``p``, ``y`` ... above, and temporaries) starts with ``w_``, which no
model's name may.

:class:`Numeric` adds the generic part: q' = v, and the solve with M (a division where M is
diagonal), vectorised over points.
"""

from __future__ import annotations

import hashlib
from functools import cache
from pathlib import Path

import numpy as np

from ..cache import cache_dir, write_atomically

PACKAGE = Path(__file__).resolve().parent


#: Modules of the models package that read or register models and generate nothing: a
#: change to them regenerates nothing (a model file's own content is in its key).
READERS = frozenset({"__init__.py", "file.py"})


@cache
def code_key() -> str:
    """sha256 over the generator: the source of the models package that generated code
    depends on (declarations, laws, the expression reader, the symbolic and numeric
    generators). A change to it regenerates every variant's code; the models themselves are
    files, whose content is in each family's key (:func:`variant_key`)."""
    digest = hashlib.sha256()
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.relative_to(PACKAGE).as_posix() in READERS:
            continue
        digest.update(path.relative_to(PACKAGE).as_posix().encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()


def variant_key(model) -> str:
    """Identifies everything generated for ``model`` without generating it: the generator,
    what its model file declares (a comment in one file changes no other's key) and laws."""
    declared = f"{model.family.key}:" if model.family.key else ""
    return hashlib.sha256(f"{code_key()}:{declared}{model.name}:{model.laws}".encode()
                          ).hexdigest()


# ------------------------------------------------------------------------------ generation
def numeric_source(model, exact: bool = False) -> str:
    """The generated module for ``model`` (deterministic text); ``exact``: of its exact
    piecewise laws, one piece per piecewise dof chosen by trailing parameters (see
    :class:`whirl_cli.models.symbolic.Symbolic`)."""
    import sympy as sp
    from sympy.printing.numpy import NumPyPrinter

    from .symbolic import Symbolic

    symbolic = Symbolic(model, exact=exact)
    printer = NumPyPrinter({"fully_qualified_modules": True, "allow_unknown_functions": False})
    states = [str(s) for s in symbolic.states]
    params = [str(s) for s in symbolic.parameters]
    n_dof, n = len(symbolic.q), len(symbolic.states)
    n_rows = n_dof + len(symbolic.x)

    residual = [_by_state(e, symbolic.states) for e in symbolic.rows]
    jacobian = [_by_state(e, symbolic.states)
                for e in symbolic.residual_jacobian.col_join(symbolic.rates_jacobian)]
    temporaries, reduced = sp.cse(residual + jacobian, symbols=sp.numbered_symbols("w_"),
                                  order="canonical")
    parameter_only: list[tuple[sp.Symbol, sp.Expr]] = []
    known = set(symbolic.parameters)
    state_dependent = []
    for symbol, expression in temporaries:
        if expression.free_symbols <= known:
            parameter_only.append((symbol, expression))
            known.add(symbol)
        else:
            state_dependent.append((symbol, expression))
    prepared = params + [str(s) for s, _ in parameter_only]
    forces, slopes = reduced[:n_rows], reduced[n_rows:]

    # M^-1 as prepared numbers (field_at: fixed parameters): 1/M_ii, or a numeric inverse
    inverse = [[sp.Symbol(f"w_m{i}_{j}") for j in range(n_dof)] for i in range(n_dof)]
    structure = [[i == j or not symbolic.diagonal_mass for j in range(n_dof)]
                 for i in range(n_dof)]
    if symbolic.diagonal_mass:
        inverse_lines = [f"    w_m{i}_{i} = 1.0 / ({printer.doprint(symbolic.mass[i, i])})"
                         for i in range(n_dof)]
    else:
        inverse_lines = [f"    ({', '.join(str(s) for row in inverse for s in row)},) = "
                         f"numpy.linalg.inv(numpy.array(mass(w_p), dtype=float).reshape("
                         f"{n_dof}, {n_dof})).ravel()"]
    field_constants = prepared + [str(inverse[i][j]) for i in range(n_dof)
                                  for j in range(n_dof) if structure[i][j]]
    # each force and slope once, as a temporary: with a full M^-1 every row of the
    # accelerations sums all of them (printed inline, each would be evaluated n_dof times)
    force_symbols = [sp.Symbol(f"w_r{j}") for j in range(n_dof)]
    slope_symbols = [sp.S.Zero if slopes[j * n + k] == 0 else sp.Symbol(f"w_s{j}_{k}")
                     for j in range(n_dof) for k in range(n)]
    force_lines = list(zip(force_symbols, forces[:n_dof], strict=True))
    slope_lines = [(symbol, slope) for symbol, slope in zip(slope_symbols, slopes[:n_dof * n],
                                                             strict=True) if symbol != 0]
    accelerations = [sp.Add(*[inverse[i][j] * force_symbols[j] for j in range(n_dof)
                              if structure[i][j]]) for i in range(n_dof)]
    lower = [sp.Add(*[inverse[i][j] * slope_symbols[j * n + k] for j in range(n_dof)
                      if structure[i][j]]) for i in range(n_dof) for k in range(n)]
    upper = [sp.S.One if k == n_dof + i else sp.S.Zero for i in range(n_dof) for k in range(n)]

    def body(assignments, results, unpack) -> list[str]:
        lines = [f"    {line}" for line in unpack]
        lines += [f"    {s} = {printer.doprint(e)}" for s, e in assignments]
        lines.append("    return [" + ", ".join(printer.doprint(e) for e in results) + "]")
        return lines

    def unpack(names: list[str], source: str) -> str:
        return f"({', '.join(names)},) = {source}"

    def used(results):
        return [a for a in state_dependent if a[0] in _needed(results, state_dependent)]

    nonzero, tensors = symbolic.residual_tensors
    tensor_temps, tensor_reduced = sp.cse(tensors, symbols=sp.numbered_symbols("w_t"),
                                          order="canonical") if tensors else ([], [])
    laws = ", ".join(f"{law} on {dof}" for law, dof in zip(model.laws, model.family.dof_names,
                                                          strict=True))
    lines = [
        f'"""Generated by whirl from the symbolic model {model.name}; do not edit.',
        "",
        f"Laws: {laws}{' (exact piecewise forms)' if exact else ''}.",
        f"States: {', '.join(states)}.",
        f"Parameters: {', '.join(params)}.",
        '"""',
        "",
        "import numpy",
        "",
        f"N_DOF = {n_dof}",
        f"N_STATES = {n}",
        *([f"N_FIRST_ORDER = {n_rows - n_dof}"] if n_rows > n_dof else []),
        f"DIAGONAL_MASS = {symbolic.diagonal_mass}",
        f"TENSOR_INDEX = {list(nonzero)}",
        "",
        "",
        "def prepare(w_p):",
        *body(parameter_only, [sp.Symbol(name) for name in prepared], [unpack(params, "w_p")]),
        "",
        "",
        "def residual(w_y, w_c):",
        *body(used(forces), forces, [unpack(states, "w_y"), unpack(prepared, "w_c")]),
        "",
        "",
        "def residual_jacobian(w_y, w_c):",
        *body(used(slopes), slopes, [unpack(states, "w_y"), unpack(prepared, "w_c")]),
        "",
        "",
        "def residual_tensors(w_y, w_p):",
        *body(tensor_temps, tensor_reduced, [unpack(states, "w_y"), unpack(params, "w_p")]),
        "",
        "",
        "def mass(w_p):",
        *body([], list(symbolic.mass), [unpack(params, "w_p")]),
        "",
        "",
        "def prepare_field(w_p):",
        f"    ({', '.join(params)},) = w_p",
        *inverse_lines,
        "    return prepare(w_p) + [" + ", ".join(field_constants[len(prepared):]) + "]",
        "",
        "",
        "def field(w_y, w_f):",
        *body(used(forces) + force_lines, list(symbolic.v) + accelerations + forces[n_dof:],
              [unpack(states, "w_y"), unpack(field_constants, "w_f")]),
        "",
        "",
        "def field_jacobian(w_y, w_f):",
        *body(used(slopes) + slope_lines, upper + lower + slopes[n_dof * n:],
              [unpack(states, "w_y"), unpack(field_constants, "w_f")]),
        "",
    ]
    return "\n".join(lines)


def _by_state(expression, states):
    """``expression`` as a sum of (parameter-only coefficient) x (state factor), the terms
    with equal state factors summed: common subexpression elimination then finds the
    coefficients, which ``prepare`` computes once per parameter set."""
    import sympy as sp

    grouped: dict = {}
    for term in sp.Add.make_args(expression):
        coefficient, factor = term.as_independent(*states, as_Add=False)
        grouped[factor] = grouped.get(factor, 0) + coefficient
    return sp.Add(*[coefficient * factor for factor, coefficient in grouped.items()])


def _needed(results, assignments) -> set:
    """The temporaries of ``assignments`` that ``results`` use, directly or through others."""
    definitions = dict(assignments)
    needed: set = set()
    todo = [s for e in results for s in getattr(e, "free_symbols", ()) if s in definitions]
    while todo:
        symbol = todo.pop()
        if symbol not in needed:
            needed.add(symbol)
            todo += [s for s in definitions[symbol].free_symbols if s in definitions]
    return needed


# ------------------------------------------------------------------------------ loading
def load(model, exact: bool = False) -> Numeric:
    """The numeric functions of ``model`` (``exact``: of its exact piecewise laws): the cached
    module, generated first if needed."""
    form = "-exact" if exact else ""
    path = cache_dir() / "models" / f"{model.name}{form}-{variant_key(model)[:24]}.py"
    try:
        text = path.read_text()
    except FileNotFoundError:
        text = numeric_source(model, exact)
        write_atomically(path, text)
    namespace: dict = {}
    exec(compile(text, str(path), "exec"), namespace)  # noqa: S102 - whirl's own generated code
    return Numeric(namespace)


def _stack(values, axis: int) -> np.ndarray:
    return np.stack(np.broadcast_arrays(*values), axis=axis)


class Numeric:
    """dy/dt = [v, M^-1 R, F], its Jacobian and derivative tensors from a generated module."""

    def __init__(self, module: dict) -> None:
        self.n = int(module["N_STATES"])
        self.n_dof = int(module["N_DOF"])
        self.n_rows = self.n - self.n_dof  # rows of [R; F]
        self.prepare = module["prepare"]
        self.residual = module["residual"]
        self.residual_jacobian = module["residual_jacobian"]
        self.residual_tensors = module["residual_tensors"]
        self.mass = module["mass"]
        self.prepare_field, self.field = module["prepare_field"], module["field"]
        self.field_jacobian = module["field_jacobian"]
        self.diagonal = bool(module["DIAGONAL_MASS"])
        self.tensor_index = np.asarray(module["TENSOR_INDEX"], dtype=int)

    def mass_matrix(self, params) -> np.ndarray:
        """M with the points first: (..., n_dof, n_dof)."""
        return self._mass(params)

    def _mass(self, params) -> np.ndarray:
        """M with the points first: (..., n_dof, n_dof)."""
        entries = self.mass(tuple(params))
        if not entries:  # no dofs
            points = np.shape(params)[1:]
            return np.zeros(points + (0, 0))
        entries = _stack(entries, axis=-1)
        return entries.reshape(entries.shape[:-1] + (self.n_dof, self.n_dof))

    def _solved(self, mass: np.ndarray, right: np.ndarray) -> np.ndarray:
        """M^-1 right, points first: ``right`` (..., n_dof, k) -> (..., n_dof, k)."""
        if self.diagonal:
            return right / np.diagonal(mass, axis1=-2, axis2=-1)[..., None]
        batch = np.broadcast_shapes(mass.shape[:-2], right.shape[:-2])
        return np.linalg.solve(np.broadcast_to(mass, batch + mass.shape[-2:]),
                               np.broadcast_to(right, batch + right.shape[-2:]))

    def rhs(self, y, params) -> np.ndarray:
        """dy/dt: (n,) or (n, M), like ``y``/``params`` (P,) or (P, M)."""
        y = tuple(y)
        rows = _stack(self.residual(y, self.prepare(tuple(params))), axis=-1)
        k = self.n_dof
        acceleration = self._solved(self._mass(params), rows[..., :k, None])[..., 0] if k \
            else rows[..., :0]
        values = list(y[k:2 * k]) + [acceleration[..., i] for i in range(k)] \
            + [rows[..., i] for i in range(k, self.n_rows)]
        return _stack(values, axis=0)

    def jacobian(self, y, params) -> np.ndarray:
        """df/dy: (n, n), or (M, n, n) with M points."""
        y = tuple(y)
        entries = _stack(self.residual_jacobian(y, self.prepare(tuple(params))), axis=-1)
        rows = entries.reshape(entries.shape[:-1] + (self.n_rows, self.n))
        k = self.n_dof
        lower = self._solved(self._mass(params), rows[..., :k, :]) if k else rows[..., :0, :]
        upper = np.zeros(rows.shape[:-2] + (k, self.n))
        upper[..., np.arange(k), k + np.arange(k)] = 1.0
        return np.concatenate([upper, lower, rows[..., k:, :]], axis=-2)

    def tensors(self, y, params) -> tuple[np.ndarray, np.ndarray]:
        """(d2f/dy2 (n, n, n), d3f/dy3 (n, n, n, n)) at one point."""
        n, k, r = self.n, self.n_dof, self.n_rows
        flat = np.zeros(r * n**2 + r * n**3)
        if len(self.tensor_index):
            flat[self.tensor_index] = np.array(
                self.residual_tensors(tuple(y), tuple(params)), dtype=float)
        second_rows = flat[:r * n**2].reshape(r, n, n)
        third_rows = flat[r * n**2:].reshape(r, n, n, n)
        second = np.zeros((n, n, n))
        third = np.zeros((n, n, n, n))
        if k:
            inverse = np.linalg.inv(self._mass(params))
            second[k:2 * k] = np.einsum("ij,j...->i...", inverse, second_rows[:k])
            third[k:2 * k] = np.einsum("ij,j...->i...", inverse, third_rows[:k])
        second[2 * k:] = second_rows[k:]
        third[2 * k:] = third_rows[k:]
        return second, third

    def field_at(self, params):
        """(f(y), J(y)) for fixed ``params`` (for time integration): the parameter-only work
        and M^-1 are done once here."""
        # Python floats: the generated scalar code runs 2-4 times faster on them than on
        # numpy scalars (the constants, and the state: a solver's array is made a list)
        constants = [float(c) for c in self.prepare_field(tuple(float(v) for v in params))]
        field, field_jacobian, n = self.field, self.field_jacobian, self.n

        def f(y) -> np.ndarray:
            state = y.tolist() if isinstance(y, np.ndarray) else y
            return np.array(field(state, constants), dtype=float)

        def jacobian(y) -> np.ndarray:
            state = y.tolist() if isinstance(y, np.ndarray) else y
            return np.array(field_jacobian(state, constants), dtype=float).reshape(n, n)

        return f, jacobian
