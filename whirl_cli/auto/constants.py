"""AUTO's PAR array and constants files: where each quantity lives, and the text AUTO reads.

PAR layout (:func:`par_layout`): model parameters fill PAR(1..9), then PAR(37...) because
PAR(10..36) are reserved by AUTO (PAR(11) = period, PAR(12) = torus angle, HomCont PAR(10..36));
the PVLS outputs ``max_<state>`` and ``min_<state>`` follow. All names are AUTO ``parnames``.
:func:`constants_text` writes AUTO's keyword-style constants file and refuses keys and strings
that could break a line.
"""

from __future__ import annotations

import hashlib
import re
from dataclasses import dataclass

from ..errors import CodegenError
from ..models import Model
from ..models.declaration import AUTO_NAME_LENGTH

#: Free PAR slots for user parameters, in order (AUTO reserves 10..36).
_USER_SLOTS = tuple(range(1, 10)) + tuple(range(37, 200))
PERIOD_INDEX = 11
#: PAR(12): the torus angle of a torus (TR) point, in (0, pi) rad; free on a torus locus.
TORUS_ANGLE_INDEX = 12
#: PVLS output: the largest half peak-to-peak value of any (AUTO, non-dimensional) state over
#: the solution; 0 on equilibria. Used to stop periodic families that shrink back onto a Hopf.
AMPLITUDE = "amplitude"
#: A file in an AUTO run's directory whose one line holds the starting state U (AUTO's
#: units) that the generated STPNT reads where the zero state is not an equilibrium.
START_FILE = "whirl_start.txt"


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


def auto_name(name: str) -> str:
    """The name AUTO knows a whirl parameter or state by: the name itself if it fits AUTO's
    13 characters, else its first 8 characters, "_" and 4 hex digits of its SHA-1 (e.g. a
    law's ``epsilon_beta_y``; deterministic, and unique among a model's names in practice:
    :func:`constants_text` refuses a clash)."""
    if len(name) <= AUTO_NAME_LENGTH:
        return name
    return f"{name[:8]}_{hashlib.sha1(name.encode()).hexdigest()[:4]}"


def _auto_names(constants: dict) -> dict:
    """``constants`` with every whirl name AUTO reads as its :func:`auto_name`: the values of
    ``parnames`` and ``unames``, the names in ``ICP`` and the keys of every other mapping
    (``PAR``, ``UZSTOP``, ``UZR``, ...)."""
    renamed = {}
    for key, value in constants.items():
        if key in ("parnames", "unames"):
            value = {i: auto_name(n) for i, n in value.items()}
            if len(set(value.values())) != len(value):
                raise CodegenError(f"AUTO {key} clash once shortened: {sorted(value.values())}")
        elif key == "ICP":
            value = [auto_name(n) if isinstance(n, str) else n for n in value]
        elif isinstance(value, dict):
            value = {auto_name(k) if isinstance(k, str) else k: v for k, v in value.items()}
        renamed[key] = value
    return renamed


def constants_text(constants: dict) -> str:
    """AUTO's keyword-style constants file, one ``KEY = value`` per line, whirl's names as
    AUTO knows them (:func:`auto_name`).

    Enforces AUTO's reader limits: names <= 13 characters, lines <= 2048 characters.
    """
    constants = _auto_names(constants)
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

