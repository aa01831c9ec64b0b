"""Safe expressions of a model file: text -> a checked syntax tree -> sympy, never ``eval``.

An expression is parsed by Python's own parser (:mod:`ast`, which only reads) and then
checked against a whitelist: numbers, names, ``+ - * / **``, unary minus and plus,
parentheses, and calls of the functions in :data:`FUNCTIONS` by name. Anything else
(attributes, subscripts, comparisons outside a constraint, lambdas, strings, keyword arguments,
``__import__``) is refused with a reason, and nothing of the text is ever executed.

:func:`parse` checks and returns an :class:`Expression` (its names, no sympy);
:func:`evaluate` computes one with :mod:`math` (datum checks while a file is validated);
:func:`to_sympy` builds the sympy expression code generation starts from.
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable, Mapping
from dataclasses import dataclass

#: Longest expression accepted, in characters.
MAX_LENGTH = 4000
#: Deepest nesting accepted (parentheses, operators, calls).
MAX_DEPTH = 60
#: Largest magnitude of a constant exponent (``x**3``): larger ones overflow or stall sympy.
MAX_EXPONENT = 64

#: Functions an expression may call: name -> (number of arguments, or None for 2 or more).
FUNCTIONS: dict[str, int | None] = {
    **dict.fromkeys(("sqrt", "exp", "log", "sin", "cos", "tan", "asin", "acos", "atan",
                     "sinh", "cosh", "tanh", "asinh", "acosh", "atanh", "abs", "sign"), 1),
    "atan2": 2,
    "min": None,
    "max": None,
}
#: Named constants.
CONSTANTS = {"pi": math.pi}
#: Comparisons a constraint may make.
COMPARISONS: dict[type, tuple[str, Callable[[float, float], bool]]] = {
    ast.Gt: (">", operator.gt), ast.GtE: (">=", operator.ge),
    ast.Lt: ("<", operator.lt), ast.LtE: ("<=", operator.le),
}
_BINARY: dict[type, Callable[[float, float], float]] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
    ast.Div: operator.truediv, ast.Pow: operator.pow,
}
_REFUSED_OPERATORS = {ast.BitXor: "'^' is not a power here: write '**'", ast.Mod: "'%'",
                      ast.FloorDiv: "'//'", ast.MatMult: "'@'", ast.BitAnd: "'&'",
                      ast.BitOr: "'|'", ast.LShift: "'<<'", ast.RShift: "'>>'"}


class ExpressionError(ValueError):
    """An expression that is not allowed; the message is the reason."""


@dataclass(frozen=True)
class Expression:
    """A checked expression: its text, syntax tree and the names it uses (functions and
    ``pi`` excluded)."""

    text: str
    tree: ast.expr
    names: frozenset[str]

    @property
    def canonical(self) -> str:
        """The syntax tree as text: equal for texts that differ only in spacing."""
        return ast.dump(self.tree)


@dataclass(frozen=True)
class Comparison:
    """A checked comparison ``left OP right`` (a constraint)."""

    text: str
    left: Expression
    symbol: str
    right: Expression

    @property
    def names(self) -> frozenset[str]:
        return self.left.names | self.right.names

    def holds(self, values: Mapping[str, float]) -> bool:
        """True if the comparison holds for these values (False where it cannot be computed)."""
        try:
            left, right = evaluate(self.left, values), evaluate(self.right, values)
        except ArithmeticError:
            return False
        compare = next(f for s, f in COMPARISONS.values() if s == self.symbol)
        return math.isfinite(left) and math.isfinite(right) and compare(left, right)


def parse(source: object) -> Expression:
    """Check ``source`` (a string, or a number as YAML gives it) and return it parsed;
    :class:`ExpressionError` with the reason otherwise."""
    tree = _parse_tree(source)
    _check(tree, 0)
    return Expression(_text(source), tree, frozenset(_names(tree)))


def parse_comparison(source: object) -> Comparison:
    """A constraint such as ``I_y - I_d > 0``: one comparison of two expressions."""
    text = _text(source)
    tree = _parse_tree(source)
    if not isinstance(tree, ast.Compare) or len(tree.ops) != 1 \
            or type(tree.ops[0]) not in COMPARISONS:
        raise ExpressionError("expected one comparison with >, >=, < or <=, e.g. 'I_y - I_d > 0'")
    _check(tree.left, 0)
    _check(tree.comparators[0], 0)
    symbol = COMPARISONS[type(tree.ops[0])][0]
    left, right = tree.left, tree.comparators[0]
    return Comparison(text, Expression(text, left, frozenset(_names(left))), symbol,
                      Expression(text, right, frozenset(_names(right))))


def _text(source: object) -> str:
    if isinstance(source, bool) or not isinstance(source, str | int | float):
        raise ExpressionError("expected an expression (text or a number)")
    return source if isinstance(source, str) else repr(source)


def _parse_tree(source: object) -> ast.expr:
    text = _text(source).strip()
    if not text:
        raise ExpressionError("the expression is empty")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"the expression is longer than {MAX_LENGTH} characters")
    if text.count("(") > MAX_DEPTH:
        raise ExpressionError(f"the expression is nested deeper than {MAX_DEPTH} levels")
    try:
        return ast.parse(text, mode="eval").body
    except SyntaxError as error:
        raise ExpressionError(f"cannot read {text!r}: {error.msg}") from None
    except (RecursionError, MemoryError, ValueError):
        raise ExpressionError(f"cannot read {text!r}") from None


def _check(node: ast.AST, depth: int) -> None:
    """Refuse every node outside the whitelist (see the module doc)."""
    if depth > MAX_DEPTH:
        raise ExpressionError(f"the expression is nested deeper than {MAX_DEPTH} levels")
    if isinstance(node, ast.Constant):
        value = node.value
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ExpressionError(f"{value!r} is not a number")
        if not math.isfinite(value) or abs(value) > 1e300:
            raise ExpressionError(f"the number {value!r} is too large")
    elif isinstance(node, ast.Name):
        if node.id.startswith("_"):
            raise ExpressionError(f"names starting with '_' are not allowed ({node.id})")
        if node.id in FUNCTIONS:
            raise ExpressionError(f"{node.id} is a function: call it, e.g. {node.id}(x)")
    elif isinstance(node, ast.UnaryOp):
        if not isinstance(node.op, ast.USub | ast.UAdd):
            raise ExpressionError("only unary '-' and '+' are allowed")
        _check(node.operand, depth + 1)
    elif isinstance(node, ast.BinOp):
        if type(node.op) not in _BINARY:
            shown = _REFUSED_OPERATORS.get(type(node.op), "this operator")
            raise ExpressionError(f"{shown} is not allowed (use + - * / **)")
        _check(node.left, depth + 1)
        _check(node.right, depth + 1)
        if isinstance(node.op, ast.Pow):
            _check_exponent(node.right)
    elif isinstance(node, ast.Call):
        _check_call(node, depth)
    elif isinstance(node, ast.Compare):
        raise ExpressionError("a comparison is not an expression (only constraints compare)")
    else:
        raise ExpressionError(f"{_what(node)} is not allowed in an expression")


def _check_call(node: ast.Call, depth: int) -> None:
    if not isinstance(node.func, ast.Name):
        raise ExpressionError("only the named functions may be called "
                              f"({', '.join(sorted(FUNCTIONS))})")
    name = node.func.id
    if name not in FUNCTIONS:
        raise ExpressionError(f"unknown function {name!r} (allowed: "
                              f"{', '.join(sorted(FUNCTIONS))})")
    if node.keywords or any(isinstance(a, ast.Starred) for a in node.args):
        raise ExpressionError(f"{name}: only plain arguments are allowed")
    wanted = FUNCTIONS[name]
    if (wanted is None and len(node.args) < 2) or (wanted is not None
                                                   and len(node.args) != wanted):
        count = "2 or more" if wanted is None else str(wanted)
        raise ExpressionError(f"{name} takes {count} argument(s), got {len(node.args)}")
    for argument in node.args:
        _check(argument, depth + 1)


def _check_exponent(node: ast.expr) -> None:
    """A constant exponent must be small: ``2**10**10`` would stall sympy."""
    try:
        value = evaluate(Expression("", node, frozenset()), {})
    except (ArithmeticError, KeyError, ExpressionError):
        return  # not a constant (names), or not computable: checked where it is evaluated
    if abs(value) > MAX_EXPONENT:
        raise ExpressionError(f"a constant exponent must be at most {MAX_EXPONENT} in size")


def _what(node: ast.AST) -> str:
    return {ast.Attribute: "an attribute ('.')", ast.Subscript: "a subscript ('[]')",
            ast.Lambda: "a lambda", ast.JoinedStr: "a string", ast.IfExp: "'if'",
            ast.BoolOp: "'and'/'or'", ast.Tuple: "a tuple", ast.List: "a list",
            ast.Dict: "a mapping", ast.Set: "a set", ast.NamedExpr: "':='",
            ast.Starred: "'*'"}.get(type(node), f"'{type(node).__name__}'")


def _names(tree: ast.AST) -> set[str]:
    called = {id(n.func) for n in ast.walk(tree) if isinstance(n, ast.Call)}
    return {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and id(n) not in called
            and n.id not in CONSTANTS}


# ------------------------------------------------------------------------------ numbers
_MATH: dict[str, Callable[..., float]] = {
    "sqrt": math.sqrt, "exp": math.exp, "log": math.log, "sin": math.sin, "cos": math.cos,
    "tan": math.tan, "asin": math.asin, "acos": math.acos, "atan": math.atan,
    "sinh": math.sinh, "cosh": math.cosh, "tanh": math.tanh, "asinh": math.asinh,
    "acosh": math.acosh, "atanh": math.atanh, "abs": abs, "atan2": math.atan2,
    "sign": lambda x: math.copysign(1.0, x) if x else 0.0, "min": min, "max": max,
}


def evaluate(expression: Expression, values: Mapping[str, float]) -> float:
    """The value of a checked expression for ``values`` by name (floats, :mod:`math`):
    ArithmeticError (ValueError from math as well) where it cannot be computed; KeyError for
    a name without a value."""
    try:
        return float(_value(expression.tree, values))
    except ValueError as error:  # math domain errors
        raise ArithmeticError(str(error)) from None


def _value(node: ast.AST, values: Mapping[str, float]) -> float:
    if isinstance(node, ast.Constant):
        return float(node.value)
    if isinstance(node, ast.Name):
        return CONSTANTS[node.id] if node.id in CONSTANTS else values[node.id]
    if isinstance(node, ast.UnaryOp):
        operand = _value(node.operand, values)
        return -operand if isinstance(node.op, ast.USub) else operand
    if isinstance(node, ast.BinOp):
        left, right = _value(node.left, values), _value(node.right, values)
        if isinstance(node.op, ast.Pow) and abs(right) > MAX_EXPONENT * 16 and abs(left) > 1:
            raise OverflowError("power overflows")
        result = _BINARY[type(node.op)](left, right)
        if isinstance(result, complex):
            raise ArithmeticError("a negative number to a fractional power")
        return result
    if isinstance(node, ast.Call):
        assert isinstance(node.func, ast.Name)
        return _MATH[node.func.id](*(_value(a, values) for a in node.args))
    raise ExpressionError(f"{_what(node)} is not allowed in an expression")


# ------------------------------------------------------------------------------ sympy
def to_sympy(expression: Expression, symbols: Mapping[str, object]):
    """The sympy expression of a checked expression, with ``symbols`` by name (sympy symbols
    or expressions). Integers stay exact (``1/2`` is a half); decimals become Floats."""
    return _sympy(expression.tree, symbols)


def _sympy(node: ast.AST, symbols: Mapping[str, object]):
    import sympy as sp

    if isinstance(node, ast.Constant):
        return sp.Integer(node.value) if isinstance(node.value, int) else sp.Float(node.value)
    if isinstance(node, ast.Name):
        return sp.pi if node.id in CONSTANTS else symbols[node.id]
    if isinstance(node, ast.UnaryOp):
        operand = _sympy(node.operand, symbols)
        return -operand if isinstance(node.op, ast.USub) else operand
    if isinstance(node, ast.BinOp):
        return _BINARY[type(node.op)](_sympy(node.left, symbols), _sympy(node.right, symbols))
    if isinstance(node, ast.Call):
        assert isinstance(node.func, ast.Name)
        return _sympy_function(node.func.id)(*(_sympy(a, symbols) for a in node.args))
    raise ExpressionError(f"{_what(node)} is not allowed in an expression")


def _sympy_function(name: str):
    import sympy as sp

    return {"abs": sp.Abs, "sign": sp.sign, "min": sp.Min, "max": sp.Max}.get(name) \
        or getattr(sp, name)
