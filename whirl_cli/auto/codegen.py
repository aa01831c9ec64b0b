"""Code generation: symbolic model -> AUTO-07p Fortran equations file.

The generated ``.f90`` holds FUNC (right-hand side with the analytic Jacobians DFDU and DFDP),
STPNT (datum parameters, start at the trivial equilibrium y = 0), PVLS (max and min of every
state over the solution into spare PAR slots) and the required stubs BCND, ICND, FOPT. Output is
deterministic: no dates, host names or library versions, only the variant key. The PAR slots
are those of :func:`whirl_cli.auto.constants.par_layout`. sympy is imported only to generate a
file (never to find a cached program: :func:`source_key` needs no symbolic work).
"""

from __future__ import annotations

import hashlib
import math
import re
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import CodegenError
from ..models import Model
from ..models.numeric import variant_key
from .constants import AMPLITUDE, PERIOD_INDEX, START_FILE, par_layout

if TYPE_CHECKING:
    import sympy as sp

_FCODE = dict(standard=2008, source_format="free", strict=True,
              user_functions={"asinh": "asinh"})


def fortran_number(value: float) -> str:
    """A double-precision Fortran literal that round-trips ``value``."""
    if not math.isfinite(value):
        raise CodegenError(f"cannot write {value!r} as a Fortran number")
    text = repr(float(value)).replace("e", "d")
    return text if "d" in text else text + "d0"


def _assignments(targets: list[str], exprs: list[sp.Expr], temp_prefix: str
                 ) -> tuple[list[str], list[str]]:
    """Fortran lines computing ``targets = exprs`` through common subexpressions."""
    import sympy as sp

    symbols = sp.numbered_symbols(temp_prefix)
    replacements, reduced = sp.cse(exprs, symbols=symbols, order="canonical")
    lines = [sp.fcode(e, assign_to=str(s), **_FCODE) for s, e in replacements]
    lines += [sp.fcode(e, assign_to=t, **_FCODE) for t, e in zip(targets, reduced, strict=True)]
    return [str(s) for s, _ in replacements], lines


def _declare(names: list[str]) -> list[str]:
    out = []
    for start in range(0, len(names), 8):
        out.append("  DOUBLE PRECISION :: " + ", ".join(names[start:start + 8]))
    return out


def source_key(model: Model) -> str:
    """Identifies :func:`fortran_source` output without generating it (the compile cache key):
    the variant's key (its declaration and the models package's code) plus this generator's
    text. No sympy work: a run never builds the symbolic model."""
    generator = hashlib.sha256(Path(__file__).read_bytes()).hexdigest()
    return hashlib.sha256(f"{variant_key(model)}:{generator}".encode()).hexdigest()


def _solve_lines(k: int, diagonal: bool, target: str, columns: str) -> list[str]:
    """Fortran lines replacing ``target(1:k, 1:columns)`` by WM^-1 ``target`` in place: a
    division by the diagonal where M is diagonal, else Gaussian elimination with partial
    pivoting on a copy of WM (WL)."""
    if diagonal:
        return [f"  DO I = 1, {k}",
                f"    {target}(I,1:{columns}) = {target}(I,1:{columns}) / WM(I,I)",
                "  END DO"]
    return [f"  CALL WHIRL_SOLVE({k}, WM, {target}, {columns})"]


_SOLVER = """
SUBROUTINE WHIRL_SOLVE(K, WM, B, NB)
  ! B(1:K,1:NB) := WM^-1 B by Gaussian elimination with partial pivoting (WM is kept).
  IMPLICIT NONE
  INTEGER, INTENT(IN) :: K, NB
  DOUBLE PRECISION, INTENT(IN) :: WM(K,K)
  DOUBLE PRECISION, INTENT(INOUT) :: B(K,NB)
  DOUBLE PRECISION :: A(K,K), ROW(K), BROW(NB), FACTOR
  INTEGER :: I, J, P
  A = WM
  DO J = 1, K
    P = J - 1 + MAXLOC(ABS(A(J:K,J)), 1)
    IF (P /= J) THEN
      ROW = A(J,:)
      A(J,:) = A(P,:)
      A(P,:) = ROW
      BROW = B(J,:)
      B(J,:) = B(P,:)
      B(P,:) = BROW
    END IF
    DO I = J + 1, K
      FACTOR = A(I,J) / A(J,J)
      A(I,J:K) = A(I,J:K) - FACTOR * A(J,J:K)
      B(I,:) = B(I,:) - FACTOR * B(J,:)
    END DO
  END DO
  DO J = K, 1, -1
    B(J,:) = (B(J,:) - MATMUL(A(J,J+1:K), B(J+1:K,:))) / A(J,J)
  END DO
END SUBROUTINE WHIRL_SOLVE
"""


def model_hash(model: Model) -> str:
    """The variant's key (:func:`whirl_cli.models.numeric.variant_key`), printed in the file."""
    return variant_key(model)


def _first_order_lines(symbolic, model: Model, layout, scale: list[float]
                       ) -> tuple[list[str], dict[str, list[str]], dict[str, list[str]]]:
    """For the first-order states x' = F(y, p) (rows 2 n_dof + 1.. of F): the temporaries,
    the lines assigning F, DFDU (by AUTO's U: times each state's scale) and DFDP in physical
    units, and the lines scaling those rows to AUTO's (by 1 / (scale time_scale))."""
    import sympy as sp

    first = 2 * len(symbolic.q)
    rows = range(len(symbolic.x))
    if not symbolic.x:
        return [], {"F": [], "DFDU": [], "DFDP": []}, {"F": [], "DFDU": [], "DFDP": []}
    factor = [fortran_number(1.0 / (scale[first + i] * model.time_scale)) for i in rows]
    n = len(symbolic.states)
    slopes = symbolic.rates_jacobian
    by_state = [(i, j) for i in rows for j in range(n) if slopes[i, j] != 0]
    by_parameter = [(i, c) for c, _ in enumerate(symbolic.parameters) for i in rows
                    if symbolic.rates_parameter_jacobian[i, c] != 0]
    columns = [layout.parameters[model.parameters[c].name] for _, c in by_parameter]
    temps, lines = [], {}
    for key, targets, expressions, prefix in (
            ("F", [f"F({first + i + 1})" for i in rows], list(symbolic.rates), "w_x"),
            ("DFDU", [f"DFDU({first + i + 1},{j + 1})" for i, j in by_state],
             [slopes[i, j] * sp.Rational(repr(scale[j])) for i, j in by_state], "w_y"),
            ("DFDP", [f"DFDP({first + i + 1},{col})" for (i, _), col in
                      zip(by_parameter, columns, strict=True)],
             [symbolic.rates_parameter_jacobian[i, c] for i, c in by_parameter], "w_z")):
        names, lines[key] = _assignments(targets, expressions, prefix)
        temps += names
    last = max(layout.parameters.values())
    scaling = {"F": [f"  F({first + i + 1}) = F({first + i + 1}) * {factor[i]}" for i in rows],
               "DFDU": [f"  DFDU({first + i + 1},1:{n}) = DFDU({first + i + 1},1:{n}) * "
                        f"{factor[i]}" for i in rows],
               "DFDP": [f"  DFDP({first + i + 1},1:{last}) = DFDP({first + i + 1},1:{last}) * "
                        f"{factor[i]}" for i in rows]}
    return temps, lines, scaling


def fortran_source(model: Model) -> str:
    """The complete AUTO-07p equations file for ``model`` (free-form Fortran 90).

    FUNC computes the physical state y = S U from AUTO's U, the forces R(y, p) of the mass
    equation M v' = R and M itself, solves for the accelerations (a division where M is
    diagonal, Gaussian elimination with partial pivoting otherwise: no mass matrix is inverted
    symbolically) and returns F = f(y) / (S time_scale); DFDU and DFDP follow from dR/dy, dR/dp
    and dM/dp the same way (M depends on the parameters only).
    """
    import sympy as sp

    from ..models.symbolic import Symbolic

    symbolic = Symbolic(model)
    layout = par_layout(model)
    k, n = len(symbolic.q), len(symbolic.states)
    scale = [float(s) for s in model.state_scale]
    rate = [fortran_number(1.0 / (scale[k + i] * model.time_scale)) for i in range(k)]
    diagonal = symbolic.diagonal_mass

    mass = [(i, j) for i in range(k) for j in range(k) if symbolic.mass[i, j] != 0]
    m_temps, m_lines = _assignments([f"WM({i + 1},{j + 1})" for i, j in mass],
                                    [symbolic.mass[i, j] for i, j in mass], "w_m")
    f_temps, f_lines = _assignments([f"WA({i + 1},1)" for i in range(k)],
                                    list(symbolic.residual), "w_f")
    jac = symbolic.residual_jacobian
    ju = [(i, j) for i in range(k) for j in range(n) if jac[i, j] != 0]
    ju_temps, ju_lines = _assignments(
        [f"WJ({i + 1},{j + 1})" for i, j in ju],
        [jac[i, j] * sp.Rational(repr(scale[j])) for i, j in ju], "w_u")
    slopes = dict(symbolic.mass_parameter_derivatives)
    accelerations = [sp.Symbol(f"WA_{j + 1}") for j in range(k)]
    jp: list[tuple[int, int]] = []
    jp_exprs = []
    for column, _ in enumerate(symbolic.parameters):
        for i in range(k):
            expr = symbolic.residual_parameter_jacobian[i, column]
            if column in slopes:
                expr -= sum(slopes[column][i, j] * accelerations[j] for j in range(k))
            if expr != 0:
                jp.append((i, column))
                jp_exprs.append(expr)
    used = sorted({column for _, column in jp})
    position = {column: c + 1 for c, column in enumerate(used)}
    jp_temps, jp_lines = _assignments([f"WP({i + 1},{position[c]})" for i, c in jp], jp_exprs,
                                      "w_p")
    jp_lines = [re.sub(r"\bWA_(\d+)\b", r"WA(\1,1)", line) for line in jp_lines]
    n_p = max(len(used), 1)
    x_temps, x_lines, x_scaling = _first_order_lines(symbolic, model, layout, scale)

    header = [
        "!" + "-" * 78,
        f"! whirl AUTO-07p equations: {model.name}",
        f"! {model.description}",
        "! Generated by `whirl generate` from the symbolic model; do not edit by hand.",
        f"! variant key: {model_hash(model)}",
        f"! Time is non-dimensional: tau = {model.time_scale:g} rad/s * t.",
        "! States (AUTO value -> SI value):",
    ]
    for i, (s, factor) in enumerate(zip(model.states, scale, strict=True)):
        header.append(f"!   U({i + 1}) = {s.name}: {s.description} [{s.unit}] = "
                      f"{factor:g} * U({i + 1})")
    header.append("! Parameters:")
    for p in model.parameters:
        header.append(f"!   PAR({layout.parameters[p.name]}) = {p.name} [{p.unit}]: "
                      f"{p.description}")
    header.append(f"!   PAR({PERIOD_INDEX}) = period in tau")
    header.append(f"!   PAR({min(layout.state_max.values())}..{layout.npar - 1}) = max and min "
                  "of each state over the solution (PVLS)")
    header.append(f"!   PAR({layout.amplitude}) = {AMPLITUDE}: largest half peak-to-peak value "
                  "of a state (PVLS)")
    header.append(f"! M dv/dt = R(y, p): the accelerations M^-1 R are solved numerically "
                  f"({'M diagonal' if diagonal else 'M full'}).")
    if symbolic.x:
        header.append(f"! dx/dt = F(y, p) for the first-order states U({2 * k + 1}..{n}).")
    header.append("!" + "-" * 78)
    broken = [line for line in header if "\n" in line or "\r" in line]
    if broken:  # a line break would end the comment and start a Fortran statement
        raise CodegenError(f"model {model.name}: a line break in a description: {broken[0]!r}")

    unpack = [f"  {s.name} = {fortran_number(factor)} * U({i + 1})"
              for i, (s, factor) in enumerate(zip(model.states, scale, strict=True))]
    unpack += [f"  {p.name} = PAR({layout.parameters[p.name]})" for p in model.parameters]
    max_param_index = max(layout.parameters.values())

    def indented(lines: list[str]) -> list[str]:
        return ["  " + line for line in "\n".join(lines).splitlines()]

    body = [
        "",
        "SUBROUTINE FUNC(NDIM,U,ICP,PAR,IJAC,F,DFDU,DFDP)",
        "  ! Evaluates the right-hand side F(U,PAR) and, for IJAC >= 1, DFDU and DFDP.",
        "  IMPLICIT NONE",
        "  INTEGER, INTENT(IN) :: NDIM, ICP(*), IJAC",
        "  DOUBLE PRECISION, INTENT(IN) :: U(NDIM), PAR(*)",
        "  DOUBLE PRECISION, INTENT(OUT) :: F(NDIM)",
        "  DOUBLE PRECISION, INTENT(INOUT) :: DFDU(NDIM,NDIM), DFDP(NDIM,*)",
        f"  DOUBLE PRECISION :: WM({k},{k}), WA({k},1), WJ({k},{n}), WP({k},{n_p})",
        "  INTEGER :: I",
        *_declare([s.name for s in model.states] + [p.name for p in model.parameters]),
        *_declare(m_temps + f_temps + ju_temps + jp_temps + x_temps),
        "",
        *unpack,
        "",
        "  WM = 0d0",
        *indented(m_lines),
        *indented(f_lines),
        *_solve_lines(k, diagonal, "WA", "1"),
        *[f"  F({i + 1}) = U({k + i + 1})" for i in range(k)],
        *[f"  F({k + i + 1}) = WA({i + 1},1) * {rate[i]}" for i in range(k)],
        *indented(x_lines["F"]),
        *x_scaling["F"],
        "  IF (IJAC == 0) RETURN",
        "",
        "  DFDU(1:NDIM,1:NDIM) = 0d0",
        *[f"  DFDU({i + 1},{k + i + 1}) = 1d0" for i in range(k)],
        "  WJ = 0d0",
        *indented(ju_lines),
        *_solve_lines(k, diagonal, "WJ", str(n)),
        *[f"  DFDU({k + i + 1},1:{n}) = WJ({i + 1},1:{n}) * {rate[i]}" for i in range(k)],
        *indented(x_lines["DFDU"]),
        *x_scaling["DFDU"],
        "  IF (IJAC == 1) RETURN",
        "",
        f"  DFDP(1:NDIM,1:{max_param_index}) = 0d0",
        "  WP = 0d0",
        *indented(jp_lines),
        *(_solve_lines(k, diagonal, "WP", str(len(used))) if used else []),
        *[f"  DFDP({k + i + 1},{layout.parameters[model.parameters[c].name]}) = "
          f"WP({i + 1},{position[c]}) * {rate[i]}" for c in used for i in range(k)],
        *indented(x_lines["DFDP"]),
        *x_scaling["DFDP"],
        "END SUBROUTINE FUNC",
        "",
        "SUBROUTINE STPNT(NDIM,U,PAR,T)",
        "  ! Datum parameters; the start point is the trivial equilibrium U = 0, or the state",
        f"  ! in {START_FILE} where whirl wrote one (an equilibrium found by Newton's method).",
        "  IMPLICIT NONE",
        "  INTEGER, INTENT(IN) :: NDIM",
        "  DOUBLE PRECISION, INTENT(INOUT) :: U(NDIM), PAR(*)",
        "  DOUBLE PRECISION, INTENT(IN) :: T",
        "  LOGICAL :: GIVEN",
        "  INTEGER :: UNITNO",
        "",
        *[f"  PAR({layout.parameters[p.name]}) = {fortran_number(p.default)}  ! {p.name}"
          for p in model.parameters],
        "  U(1:NDIM) = 0d0",
        f"  INQUIRE(FILE='{START_FILE}', EXIST=GIVEN)",
        "  IF (GIVEN) THEN",
        f"    OPEN(NEWUNIT=UNITNO, FILE='{START_FILE}', STATUS='OLD', ACTION='READ')",
        "    READ(UNITNO, *) U(1:NDIM)",
        "    CLOSE(UNITNO)",
        "  END IF",
        "END SUBROUTINE STPNT",
        "",
        "SUBROUTINE PVLS(NDIM,U,PAR)",
        "  ! Max and min of each state over the solution (for equilibria: the state itself).",
        "  IMPLICIT NONE",
        "  INTEGER, INTENT(IN) :: NDIM",
        "  DOUBLE PRECISION, INTENT(IN) :: U(NDIM)",
        "  DOUBLE PRECISION, INTENT(INOUT) :: PAR(*)",
        "  DOUBLE PRECISION, EXTERNAL :: GETP",
        "",
    ]
    body.append(f"  PAR({layout.amplitude}) = 0d0  ! {AMPLITUDE}")
    for i, s in enumerate(model.states):
        high, low = layout.state_max[s.name], layout.state_min[s.name]
        body.append(f"  PAR({high}) = GETP('MAX', {i + 1}, U)  ! max_{s.name}")
        body.append(f"  PAR({low}) = GETP('MIN', {i + 1}, U)  ! min_{s.name}")
        body.append(f"  PAR({layout.amplitude}) = MAX(PAR({layout.amplitude}), "
                    f"0.5d0*(PAR({high}) - PAR({low})))")
    body += [
        "END SUBROUTINE PVLS",
        "",
        "! The following subroutines are not used here, but AUTO requires them.",
        "SUBROUTINE BCND",
        "END SUBROUTINE BCND",
        "",
        "SUBROUTINE ICND",
        "END SUBROUTINE ICND",
        "",
        "SUBROUTINE FOPT",
        "END SUBROUTINE FOPT",
    ]
    if not diagonal:
        body += _SOLVER.splitlines()
    body.append("")
    return "\n".join(header + body)
