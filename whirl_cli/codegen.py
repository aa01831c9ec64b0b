"""Code generation: symbolic model -> AUTO-07p Fortran equations file and constants file.

The generated ``.f90`` holds FUNC (right-hand side with the analytic Jacobians DFDU and DFDP),
STPNT (datum parameters, start at the trivial equilibrium y = 0), PVLS (max and min of every
state over the solution into spare PAR slots) and the required stubs BCND, ICND, FOPT. Output is
deterministic: no dates, host names or library versions, only the model hash.

PAR layout (:func:`par_layout`): model parameters fill PAR(1..9), then PAR(37...) because
PAR(10..36) are reserved by AUTO (PAR(11) = period, PAR(12) = torus angle, HomCont PAR(10..36));
the PVLS outputs ``max_<state>`` and ``min_<state>`` follow. All names are AUTO ``parnames``.
"""

from __future__ import annotations

import hashlib
import math
import re
from dataclasses import dataclass
from pathlib import Path

import sympy as sp

from .errors import CodegenError
from .models import Model, all_variants

#: Free PAR slots for user parameters, in order (AUTO reserves 10..36).
_USER_SLOTS = tuple(range(1, 10)) + tuple(range(37, 200))
PERIOD_INDEX = 11
#: PVLS output: the largest half peak-to-peak value of any (AUTO, non-dimensional) state over
#: the solution; 0 on equilibria. Used to stop periodic families that shrink back onto a Hopf.
AMPLITUDE = "amplitude"
_FCODE = dict(standard=2008, source_format="free", strict=True,
              user_functions={"asinh": "asinh"})


@dataclass(frozen=True)
class ParLayout:
    """Where each named quantity lives in AUTO's PAR array (1-based indices)."""

    parameters: dict[str, int]
    state_max: dict[str, int]
    state_min: dict[str, int]
    amplitude: int

    @property
    def npar(self) -> int:
        return self.amplitude

    def parnames(self) -> dict[int, str]:
        names = {i: n for n, i in self.parameters.items()}
        names.update({i: f"max_{n}" for n, i in self.state_max.items()})
        names.update({i: f"min_{n}" for n, i in self.state_min.items()})
        names[self.amplitude] = AMPLITUDE
        return dict(sorted(names.items()))

    def measures(self) -> list[str]:
        """The PVLS output names, in PAR order (listed at the end of every ICP)."""
        return ([f"max_{n}" for n in self.state_max] + [f"min_{n}" for n in self.state_min]
                + [AMPLITUDE])


def par_layout(model: Model) -> ParLayout:
    """The PAR indices of ``model``'s parameters and PVLS outputs."""
    n_states = model.n_states
    slots = iter(_USER_SLOTS)
    parameters = {p.name: next(slots) for p in model.parameters}
    maxima = [next(slots) for _ in range(n_states)]
    minima = [next(slots) for _ in range(n_states)]
    return ParLayout(parameters, dict(zip(model.state_names, maxima, strict=True)),
                     dict(zip(model.state_names, minima, strict=True)), next(slots))


def model_hash(model: Model) -> str:
    """sha256 of everything that determines the generated files."""
    text = "\n".join([model.name, sp.srepr(model.auto_rhs), repr(par_layout(model)),
                      repr([(p.name, p.default) for p in model.parameters])])
    return hashlib.sha256(text.encode()).hexdigest()


def source_key(model: Model) -> str:
    """Identifies :func:`fortran_source` output without generating it (the compile cache key):
    the model hash plus the text of this generator."""
    generator = hashlib.sha256(Path(__file__).read_bytes()).hexdigest()
    return hashlib.sha256(f"{model_hash(model)}:{generator}".encode()).hexdigest()


def fortran_number(value: float) -> str:
    """A double-precision Fortran literal that round-trips ``value``."""
    if not math.isfinite(value):
        raise CodegenError(f"cannot write {value!r} as a Fortran number")
    text = repr(float(value)).replace("e", "d")
    return text if "d" in text else text + "d0"


def _assignments(targets: list[str], exprs: list[sp.Expr], temp_prefix: str
                 ) -> tuple[list[str], list[str]]:
    """Fortran lines computing ``targets = exprs`` through common subexpressions."""
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


def fortran_source(model: Model) -> str:
    """The complete AUTO-07p equations file for ``model`` (free-form Fortran 90)."""
    layout = par_layout(model)
    n = model.n_states
    f = model.auto_rhs
    states = model.state_symbols
    params = model.parameter_symbols
    jac_u = f.jacobian(states)
    jac_p = f.jacobian(params)

    f_temps, f_lines = _assignments([f"F({i + 1})" for i in range(n)], list(f), "w_f")
    ju = [(i, j) for i in range(n) for j in range(n) if jac_u[i, j] != 0]
    ju_temps, ju_lines = _assignments([f"DFDU({i + 1},{j + 1})" for i, j in ju],
                                      [jac_u[i, j] for i, j in ju], "w_u")
    jp = [(i, k) for k in range(len(params)) for i in range(n) if jac_p[i, k] != 0]
    index = [layout.parameters[p.name] for p in model.parameters]
    jp_temps, jp_lines = _assignments([f"DFDP({i + 1},{index[k]})" for i, k in jp],
                                      [jac_p[i, k] for i, k in jp], "w_p")

    header = [
        "!" + "-" * 78,
        f"! whirl AUTO-07p equations: {model.name}",
        f"! {model.description}",
        "! Generated by `whirl generate` from the symbolic model; do not edit by hand.",
        f"! model sha256: {model_hash(model)}",
        f"! Time is non-dimensional: tau = {model.time_scale:g} rad/s * t.",
        "! States (AUTO value -> SI value):",
    ]
    for i, (s, scale) in enumerate(zip(model.states, model.state_scale, strict=True)):
        header.append(f"!   U({i + 1}) = {s.name}: {s.description} [{s.unit}] = "
                      f"{scale:g} * U({i + 1})")
    header.append("! Parameters:")
    for p in model.parameters:
        header.append(f"!   PAR({layout.parameters[p.name]}) = {p.name} [{p.unit}]: "
                      f"{p.description}")
    header.append(f"!   PAR({PERIOD_INDEX}) = period in tau")
    header.append(f"!   PAR({min(layout.state_max.values())}..{layout.npar - 1}) = max and min "
                  "of each state over the solution (PVLS)")
    header.append(f"!   PAR({layout.amplitude}) = {AMPLITUDE}: largest half peak-to-peak value "
                  "of a state (PVLS)")
    header.append("!" + "-" * 78)
    broken = [line for line in header if "\n" in line or "\r" in line]
    if broken:  # a line break would end the comment and start a Fortran statement
        raise CodegenError(f"model {model.name}: a line break in a description: {broken[0]!r}")

    unpack = [f"  {s.name} = U({i + 1})" for i, s in enumerate(model.states)]
    unpack += [f"  {p.name} = PAR({layout.parameters[p.name]})" for p in model.parameters]
    max_param_index = max(layout.parameters.values())

    body = [
        "",
        "SUBROUTINE FUNC(NDIM,U,ICP,PAR,IJAC,F,DFDU,DFDP)",
        "  ! Evaluates the right-hand side F(U,PAR) and, for IJAC >= 1, DFDU and DFDP.",
        "  IMPLICIT NONE",
        "  INTEGER, INTENT(IN) :: NDIM, ICP(*), IJAC",
        "  DOUBLE PRECISION, INTENT(IN) :: U(NDIM), PAR(*)",
        "  DOUBLE PRECISION, INTENT(OUT) :: F(NDIM)",
        "  DOUBLE PRECISION, INTENT(INOUT) :: DFDU(NDIM,NDIM), DFDP(NDIM,*)",
        *_declare([s.name for s in model.states] + [p.name for p in model.parameters]),
        *_declare(f_temps + ju_temps + jp_temps),
        "",
        *unpack,
        "",
        *["  " + line for line in "\n".join(f_lines).splitlines()],
        "  IF (IJAC == 0) RETURN",
        "",
        "  DFDU(1:NDIM,1:NDIM) = 0d0",
        *["  " + line for line in "\n".join(ju_lines).splitlines()],
        "  IF (IJAC == 1) RETURN",
        "",
        f"  DFDP(1:NDIM,1:{max_param_index}) = 0d0",
        *["  " + line for line in "\n".join(jp_lines).splitlines()],
        "END SUBROUTINE FUNC",
        "",
        "SUBROUTINE STPNT(NDIM,U,PAR,T)",
        "  ! Datum parameters; the start point is the trivial equilibrium U = 0.",
        "  IMPLICIT NONE",
        "  INTEGER, INTENT(IN) :: NDIM",
        "  DOUBLE PRECISION, INTENT(INOUT) :: U(NDIM), PAR(*)",
        "  DOUBLE PRECISION, INTENT(IN) :: T",
        "",
        *[f"  PAR({layout.parameters[p.name]}) = {fortran_number(p.default)}  ! {p.name}"
          for p in model.parameters],
        "  U(1:NDIM) = 0d0",
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
        "",
    ]
    return "\n".join(header + body)


# ---------------------------------------------------------------------------- constants
def base_constants(model: Model) -> dict:
    """Constants every run of ``model`` shares: names, dimensions and Jacobian mode."""
    layout = par_layout(model)
    return {
        "e": model.name,
        "unames": {i + 1: s for i, s in enumerate(model.state_names)},
        "parnames": layout.parnames(),
        "NDIM": model.n_states,
        "NPAR": layout.npar,
        "JAC": 1,
    }


def _constant_value(value) -> str:
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, str):
        if any(c in value for c in "'\"\n\r\0"):
            raise CodegenError(f"AUTO constants cannot hold the string {value!r}")
        return f"'{value}'"
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_constant_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_constant_value(k)}: {_constant_value(v)}"
                               for k, v in value.items()) + "}"
    raise CodegenError(f"cannot write {value!r} ({type(value).__name__}) as an AUTO constant")


#: AUTO names (parnames, unames: CHARACTER(13)) and constant keys: ASCII identifiers only.
_AUTO_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,12}")
_CONSTANT_KEY = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


def constants_text(constants: dict) -> str:
    """AUTO's keyword-style constants file, one ``KEY = value`` per line.

    Enforces AUTO's reader limits: names <= 13 characters, lines <= 2048 characters.
    """
    for key in ("parnames", "unames"):
        for name in constants.get(key, {}).values():
            if not _AUTO_NAME.fullmatch(name):
                raise CodegenError(f"AUTO name {name!r} must be <= 13 characters, [A-Za-z0-9_]")
    for key in constants:
        if not isinstance(key, str) or not _CONSTANT_KEY.fullmatch(key):
            raise CodegenError(f"not an AUTO constant name: {key!r}")
    lines = [f"{key} = {_constant_value(value)}" for key, value in constants.items()]
    too_long = [line[:40] for line in lines if len(line) > 2000]
    if too_long:
        raise CodegenError(f"AUTO reads at most 2048 characters per line: {too_long[0]}...")
    return "\n".join(lines) + "\n"


def example_constants(model: Model) -> dict:
    """The committed ``c.<variant>`` file: equilibria in K1 from the datum, for hand use."""
    first = model.parameters[0].name
    return base_constants(model) | {
        "IPS": 1, "IRS": 0, "ILP": 1, "ISP": 2, "ISW": 1, "MXBF": 0,
        "ICP": [first, *par_layout(model).measures()],
        "NMX": 500, "NPR": 0, "DS": -0.002, "DSMIN": 1e-6, "DSMAX": 0.02,
        "EPSL": 1e-8, "EPSU": 1e-8, "EPSS": 1e-6, "UZSTOP": {first: [-0.3, 0.5]},
    }


# ---------------------------------------------------------------------------- files
def generated_files(model: Model) -> dict[str, str]:
    """Relative path -> text of every file ``whirl generate`` writes for ``model``."""
    return {
        f"{model.name}/{model.name}.f90": fortran_source(model),
        f"{model.name}/c.{model.name}": constants_text(example_constants(model)),
    }


def all_generated_files() -> dict[str, str]:
    files: dict[str, str] = {}
    for model in all_variants():
        files.update(generated_files(model))
    return files


def write_generated(root: Path) -> list[Path]:
    """(Re)write ``auto_equations/`` under ``root``; returns the files that changed."""
    changed = []
    for rel, text in all_generated_files().items():
        path = root / rel
        if not path.exists() or path.read_text() != text:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
            changed.append(path)
    return changed


def drifted(root: Path) -> list[str]:
    """Generated files under ``root`` that differ from what the models generate now."""
    return [rel for rel, text in all_generated_files().items()
            if not (root / rel).exists() or (root / rel).read_text() != text]
