"""Value checks of YAML keys (studies, sheets, model files): the Annotated types (``Name``,
``Number``, ``Range``, ...) that attach them to fields, and the strict base of every model. A
value check rejects a value with the reason a message shows (``{got}`` becomes the value as
written in the YAML, see :mod:`whirl_cli.documents.messages`).
"""

from __future__ import annotations

import math
import operator
import re
from collections.abc import Callable
from typing import Annotated, Any, NoReturn

from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict
from pydantic_core import PydanticCustomError

NAME_MAX = 64
#: Largest integer AUTO-07p reads into its (32-bit) INTEGER constants (NMX, NTST, ITNW).
FORTRAN_INT_MAX = 2**31 - 1
#: Most values in ``orbits_at``: AUTO reads at most 2048 characters per constants line (UZR).
ORBITS_MAX = 64
_NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")
_NAME_REASON = (
    "expected letters, digits, '_', '.', '-' (starting with a letter or digit), got {got}"
)


def is_number(value: Any) -> bool:
    """True for an int or float that is not a bool."""
    return isinstance(value, int | float) and not isinstance(value, bool)


def fail(reason: str, at: tuple[str | int, ...] = ()) -> NoReturn:
    """Reject a value; ``{got}`` in ``reason`` becomes the value as written in the YAML.
    ``at``: the key path, below the checked value, of the part at fault (a list item, a
    mapping's key), where the message is reported."""
    raise PydanticCustomError("whirl", "{reason}", {"reason": reason, "at": at})


def _as_string(value: Any) -> str:
    if not isinstance(value, str):
        fail("expected a string, got {got}")
    return value


def as_number(value: Any) -> float:
    """``value`` as a finite float, else the reason."""
    return _number(value, ())


def _number(value: Any, at: tuple[str | int, ...]) -> float:
    """``value`` as a finite float; else the reason, reported at ``at`` below the value."""
    if not is_number(value):
        fail("expected a number, got {got}", at)
    if not math.isfinite(value):
        fail("expected a finite number, got {got}", at)
    return float(value)


def _as_integer(value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        fail("expected an integer, got {got}")
    return value


def _as_boolean(value: Any) -> bool:
    if not isinstance(value, bool):
        fail("expected true or false, got {got}")
    return value


def _as_name(value: Any) -> str:
    if not _NAME_RE.fullmatch(_as_string(value)):
        fail(_NAME_REASON)
    if len(value) > NAME_MAX:
        fail(f"must be at most {NAME_MAX} characters, got {len(value)}")
    return value


def _as_range(value: Any) -> tuple[float, float]:
    if not isinstance(value, list | tuple) or len(value) != 2:
        fail("expected [lower, upper], two numbers, got {value}")
    lower, upper = (_number(v, (k,)) for k, v in enumerate(value))
    if not lower < upper:
        fail("expected [lower, upper] with lower < upper, got {value}")
    if not (math.isfinite(upper - lower) and math.isfinite(lower - (upper - lower))
            and math.isfinite(upper + (upper - lower))):  # AUTO's bounds lie 5 % beyond
        fail("the range is too wide: its width overflows double precision, got {value}")
    return lower, upper


def _state(value: Any, at: tuple[str | int, ...], example: str) -> dict[str, float]:
    """A mapping state name -> finite number (a seed, an initial state), each value checked at
    its key; ``example``: the mapping's shape, for the message."""
    if not isinstance(value, dict) or not all(isinstance(k, str) for k in value):
        fail(f"expected a mapping state -> number, e.g. {example}, got {{got}}", at)
    return {k: _number(v, (*at, k)) for k, v in value.items()}


def as_seeds(value: Any) -> str | tuple[dict[str, float], ...]:
    """``auto``, or a list of mappings state name -> finite number."""
    if value == "auto":
        return value
    if not isinstance(value, list):
        fail("expected `auto` or a list of mappings state -> number, e.g. [{{theta: 4}}], "
              "got {got}")
    return tuple(_state(seed, (k,), "{{theta: 4}}") for k, seed in enumerate(value))


#: The description of ``seeds`` (one- and two-parameter continuations share the key).
SEEDS_TEXT = (
    "Initial states simulated at `start` until they settle; every distinct limit cycle found "
    "is continued both ways (cycles no Hopf point leads to). A list of mappings state name -> "
    "value (angles in deg, rates in deg/s, other states in their unit; unnamed states 0), or "
    "`auto`: each nonlinear dof displaced alone by 2, 4 and 8 times its law's size (freeplay: "
    "delta) or 0.05, 0.2 and 0.5 typical amplitudes. Two-parameter: simulated at `start` on "
    "every slice; the folds of cycles of the families found are loci starts (e.g. freeplay "
    "LCOs, which no Hopf point leads to).")


def as_state(value: Any) -> dict[str, float]:
    """A mapping state name -> finite number (the names are checked against the model)."""
    return _state(value, (), "{{theta: 2}}")


def at_most_orbits(values: tuple) -> tuple:
    """``values`` if there are at most :data:`ORBITS_MAX` of them."""
    if len(values) > ORBITS_MAX:
        fail(f"at most {ORBITS_MAX} values, got {len(values)}")
    return values



def bound(symbol: str, limit: float) -> AfterValidator:
    """A check that the value is ``symbol`` (>=, >, <=) ``limit``."""
    compare: Callable[[Any, Any], bool] = {
        ">=": operator.ge,
        ">": operator.gt,
        "<=": operator.le,
    }[symbol]

    def check(value: Any) -> Any:
        if not compare(value, limit):
            fail(f"must be {symbol} {limit}, got {{got}}")
        return value

    return AfterValidator(check)


Text = Annotated[str, BeforeValidator(_as_string)]
Name = Annotated[str, BeforeValidator(_as_name)]
Number = Annotated[float, BeforeValidator(as_number)]
Integer = Annotated[int, BeforeValidator(_as_integer)]
Boolean = Annotated[bool, BeforeValidator(_as_boolean)]
Range = Annotated[tuple[float, float], BeforeValidator(_as_range)]
Positive = Annotated[Number, bound(">", 0)]
#: An AUTO step, a fraction of the continuation range's width.
Step = Annotated[Positive, bound("<=", 1)]


class Strict(BaseModel):
    """The base of every model read from YAML: unknown keys refused, frozen."""

    model_config = ConfigDict(extra="forbid", frozen=True)
