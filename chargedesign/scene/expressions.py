"""A whitelisted parser for the expressions of a case file (V, l, mu, the claimed integral).

The text is parsed by Python's :func:`ast.parse` (which builds a tree and runs nothing) and
the tree is walked, without recursion, against a whitelist:

- numbers, read exactly from their decimal text (``0.1`` is ``1/10``, ``2.5e-3`` is
  ``1/400``), their size checked on the text before the number is built
  (:func:`chargedesign.validation.exact_decimal`: at most 40 digits, a written exponent of
  at most 99, magnitudes within :data:`chargedesign.validation.MAX_MAGNITUDE`);
- the state's names ``p q r gamma1 gamma2 gamma3`` and the case's declared parameters;
- ``+ - * /``, unary ``+``/``-``, ``**`` with an integer literal exponent of at most
  :data:`MAX_EXPONENT` in size, parentheses.

Everything else (calls, attributes, subscripts, lambdas, comparisons, strings, ``^``, ...) is
refused with one line naming the token and its column. Sympy objects are built from the
tree (``sympy.Rational``, ``sympy.Symbol``, ``+``, ``*``, ``**``): nothing from the file
reaches ``eval``, ``exec``, ``sympify`` or ``parse_expr``. Bounds on the text's length, its
nesting, the tree's size and the expression's degree keep hostile inputs cheap to refuse.
"""

from __future__ import annotations

import ast
import keyword
import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import sympy as sp

from chargedesign.errors import InputError
from chargedesign.validation import DECIMAL_PATTERN, MAX_LITERAL_DIGITS, exact_decimal

# The state's symbols, made here, at the boundary, which imports no model:
# :mod:`chargedesign.model.case` takes them from here (sympy symbols of the same name and
# assumptions are the same symbol anyway).
p, q, r = sp.symbols("p q r", real=True)
g1, g2, g3 = sp.symbols("gamma1 gamma2 gamma3", real=True)

#: the state's names as written in a case file
STATE_NAMES: dict[str, sp.Symbol] = {
    "p": p,
    "q": q,
    "r": r,
    "gamma1": g1,
    "gamma2": g2,
    "gamma3": g3,
}
#: longest expression text, characters
MAX_LENGTH = 20_000
#: deepest nesting of parentheses
MAX_NESTING = 40
#: most tree nodes in one expression
MAX_NODES = 5_000
#: largest |exponent| of ``**``
MAX_EXPONENT = 24
#: largest degree bound of an expression (numerator plus denominator, over all names)
MAX_DEGREE = 64
#: most digits (numerator plus denominator) of a number made by a power of a number
MAX_NUMBER_DIGITS = 400
#: largest bound on the decades of an expanded coefficient's size (the parameters at their
#: values): the case's numbers become floats (1e308 at most) and are squared on the way
MAX_SCALE = 100
#: largest bound on the number of terms of an expanded product or power (the certificate's
#: work grows with it; the theorem's integral I4 reaches 105)
MAX_TERMS = 5_000

ACCEPTED = (
    "accepted: numbers, p q r gamma1 gamma2 gamma3, the declared parameters, + - * /, "
    "** with an integer exponent, parentheses"
)
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
_DIGITS = re.compile(r"\d(?:_?\d){" + str(MAX_LITERAL_DIGITS) + ",}")
_WHAT = {
    ast.Call: "a call",
    ast.Attribute: "an attribute",
    ast.Subscript: "a subscript",
    ast.Lambda: "a lambda",
    ast.Compare: "a comparison",
    ast.BoolOp: "a boolean operator",
    ast.IfExp: "a conditional",
    ast.NamedExpr: "an assignment",
    ast.Starred: "a starred expression",
    ast.Tuple: "a tuple",
    ast.List: "a list",
    ast.Dict: "a dict",
    ast.Set: "a set",
    ast.JoinedStr: "a string",
    ast.ListComp: "a comprehension",
    ast.GeneratorExp: "a comprehension",
    ast.Await: "an await",
}
_BINARY_NAMES = {
    ast.BitXor: "^ (write powers as **)",
    ast.FloorDiv: "//",
    ast.Mod: "%",
    ast.MatMult: "@",
    ast.BitAnd: "&",
    ast.BitOr: "|",
    ast.LShift: "<<",
    ast.RShift: ">>",
}


def parameter_name_error(name: object) -> str | None:
    """Why ``name`` cannot name a parameter, or None when it can.

    A Python keyword may name a parameter (the theorem's ``lambda``): the parser reads it
    under an alias, it never becomes the keyword.
    """
    if not isinstance(name, str) or not _NAME.match(name):
        return "a parameter name is a letter followed by letters, digits or _"
    if name in ("True", "False", "None"):
        return f"{name!r} is a Python constant"
    if name in STATE_NAMES:
        return f"{name!r} is a state variable"
    return None


def parameter_symbol(name: str) -> sp.Symbol:
    """The sympy symbol of a declared parameter (real; distinct from the state's)."""
    return sp.Symbol(name, real=True)


def _at(node: ast.AST) -> str:
    """The node's place in the text as written (the parser reads it inside one pair of
    parentheses, hence the shift on the first line)."""
    line = getattr(node, "lineno", 1)
    column = getattr(node, "col_offset", 1) + (0 if line > 1 else -1) + 1
    return f"column {column}" if line == 1 else f"line {line}, column {column}"


def _refuse(where: str, text: str, node: ast.AST, what: str) -> InputError:
    segment = ast.get_source_segment(text, node) or type(node).__name__
    segment = " ".join(segment.split())
    if len(segment) > 30:
        segment = segment[:27] + "..."
    return InputError(f"{where}: {what} `{segment}` at {_at(node)} is not allowed ({ACCEPTED})")


def _literal(where: str, text: str, node: ast.Constant) -> sp.Rational:
    value = node.value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _refuse(where, text, node, "the constant")
    source = ast.get_source_segment(text, node) or ""
    if DECIMAL_PATTERN.match(source) is None:
        raise _refuse(where, text, node, "the literal (not a decimal number)")
    # read from the text, its size checked before it is built (1e99999999 is never made)
    exact = exact_decimal(source, where, at=f" at {_at(node)}")
    return sp.Rational(exact.numerator, exact.denominator)


def _exponent(where: str, text: str, node: ast.AST) -> int:
    """An integer literal exponent, possibly signed, of at most MAX_EXPONENT in size."""
    sign = 1
    inner = node
    while isinstance(inner, ast.UnaryOp) and isinstance(inner.op, (ast.USub, ast.UAdd)):
        sign = -sign if isinstance(inner.op, ast.USub) else sign
        inner = inner.operand
    if not (
        isinstance(inner, ast.Constant)
        and isinstance(inner.value, int)
        and not isinstance(inner.value, bool)
    ):
        raise _refuse(where, text, node, "the exponent (only integer literals)")
    if abs(inner.value) > MAX_EXPONENT:
        raise InputError(
            f"{where}: the exponent `{(ast.get_source_segment(text, node) or '')[:30]}` at "
            f"{_at(node)} is larger than {MAX_EXPONENT} in size"
        )
    return sign * inner.value


def _check_text(where: str, text: object) -> str:
    if not isinstance(text, str):
        raise InputError(f"{where}: expected an expression in a string, got {type(text).__name__}")
    if len(text) > MAX_LENGTH:
        raise InputError(f"{where}: the expression is longer than {MAX_LENGTH} characters")
    for column, char in enumerate(text, start=1):
        if not (char.isascii() and (char.isprintable() or char in "\t\n")):
            raise InputError(
                f"{where}: the character {char!r} at column {column} is not allowed ({ACCEPTED})"
            )
    digits = _DIGITS.search(text)
    if digits:
        raise InputError(
            f"{where}: a number of more than {MAX_LITERAL_DIGITS} digits at column "
            f"{digits.start() + 1}"
        )
    depth = deepest = 0
    for column, char in enumerate(text, start=1):
        depth += (char == "(") - (char == ")")
        deepest = max(deepest, depth)
        if depth < 0:
            raise InputError(f"{where}: an unmatched `)` at column {column}")
    if deepest > MAX_NESTING:
        raise InputError(f"{where}: parentheses nested deeper than {MAX_NESTING} levels")
    return text


@dataclass(frozen=True)
class Parsed:
    """An expression with bounds on what its expansion makes, known before it is expanded.

    Attributes
    ----------
    expression : sympy.Expr
    degree : int
        Bound on the degree (numerator plus denominator, over all names).
    terms : int
        Bound on the number of terms of its expansion.
    scale : float
        Bound on ``|log10|`` of the size of its expanded coefficients (the sum of their
        magnitudes, the parameters at their values).
    digits : int
        Bound on the digits (numerator plus denominator) of one expanded coefficient.
    """

    expression: sp.Expr
    degree: int
    terms: int
    scale: float
    digits: int


def parse_expression(
    text: object, where: str, parameters: Mapping[str, sp.Symbol] | None = None
) -> sp.Expr:
    """The sympy expression of ``text`` (see the module's whitelist).

    Parameters
    ----------
    text : str
        The expression as written in the file.
    where : str
        The input's name in error messages (e.g. ``"case.V"``).
    parameters : mapping of str to sympy.Symbol, optional
        The declared parameters' names and symbols (:func:`parameter_symbol`).

    Raises
    ------
    InputError
        One line naming the refused token and its column, or the bound exceeded.
    """
    return parse_bounded(text, where, parameters).expression


def parse_bounded(
    text: object,
    where: str,
    parameters: Mapping[str, sp.Symbol] | None = None,
    values: Mapping[str, sp.Rational] | None = None,
) -> Parsed:
    """:func:`parse_expression` with the bounds of its expansion (:class:`Parsed`), the
    declared parameters at their ``values`` (when given) for the coefficients' scale.

    Every number the expansion would make is bounded before it is built: at most
    :data:`MAX_NUMBER_DIGITS` digits (products of numbers as powers) and a scale of at most
    :data:`MAX_SCALE` decades, so every coefficient becomes a float.
    """
    source = _check_text(where, text)
    names: dict[str, sp.Expr] = dict(STATE_NAMES)
    names.update(parameters or {})
    scales = {name: _scale_of(value) for name, value in (values or {}).items()}
    if not source.strip():
        raise InputError(f"{where}: expected an expression, got an empty string")
    # read inside one pair of parentheses: expressions may span lines and start with spaces
    source = f"({source})"
    parsed = source
    for name in list(names):
        if keyword.iskeyword(name):
            # a parameter named like a Python keyword (the theorem's lambda) is read under an
            # alias of the same length (columns unchanged) that no declared name can take
            alias = "_" + name[1:]
            parsed = re.sub(rf"(?<![A-Za-z0-9_]){name}(?![A-Za-z0-9_])", alias, parsed)
            names[alias] = names.pop(name)
            if name in scales:
                scales[alias] = scales.pop(name)
    try:
        tree = ast.parse(parsed, mode="eval")
    except SyntaxError as exc:
        place = ""
        if exc.offset:
            line = exc.lineno or 1
            column = exc.offset - (1 if line == 1 else 0)
            place = f" at column {column}" if line == 1 else f" at line {line}, column {column}"
        raise InputError(f"{where}: not an expression (invalid syntax{place})") from None
    except (RecursionError, MemoryError, ValueError):
        raise InputError(f"{where}: not an expression (too complex to parse)") from None
    # iterative post-order walk: children before parents, no recursion
    order: list[ast.AST] = []
    stack: list[ast.AST] = [tree.body]
    while stack:
        node = stack.pop()
        order.append(node)
        if len(order) > MAX_NODES:
            raise InputError(f"{where}: the expression has more than {MAX_NODES} parts")
        if isinstance(node, ast.BinOp):
            stack.append(node.left)
            if not isinstance(node.op, ast.Pow):
                stack.append(node.right)
        elif isinstance(node, ast.UnaryOp):
            stack.append(node.operand)
    built: dict[int, Parsed] = {}
    for node in reversed(order):
        built[id(node)] = _build(where, source, node, names, scales, built)
    result = built[id(tree.body)]
    # the numbers sympy combined on the way (1/3 + 1/7 + ...), measured as built
    for number in result.expression.atoms(sp.Rational):
        if _digits(number) > MAX_NUMBER_DIGITS:
            raise InputError(
                f"{where}: the expression makes a number of more than {MAX_NUMBER_DIGITS} digits"
            )
    return result


def _scale_of(value: sp.Rational) -> float:
    """``|log10 |value||`` of an exact rational (0 for zero), without converting to float."""
    if value == 0:
        return 0.0
    return abs(math.log10(abs(int(value.p))) - math.log10(int(value.q)))


def _build(
    where: str,
    text: str,
    node: ast.AST,
    names: Mapping[str, sp.Expr],
    scales: Mapping[str, float],
    built: Mapping[int, Parsed],
) -> Parsed:
    if isinstance(node, ast.Constant):
        value = _literal(where, text, node)
        return Parsed(value, 0, 1, _scale_of(value), _digits(value))
    if isinstance(node, ast.Name):
        if node.id not in names:
            raise InputError(
                f"{where}: the name `{ast.get_source_segment(text, node)}` at {_at(node)} is "
                "not a state variable (p q r gamma1 gamma2 gamma3) nor a declared parameter"
            )
        return Parsed(names[node.id], 1, 1, scales.get(node.id, 0.0), 0)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        inner = built[id(node.operand)]
        value = -inner.expression if isinstance(node.op, ast.USub) else inner.expression
        return Parsed(value, inner.degree, inner.terms, inner.scale, inner.digits)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
        base = built[id(node.left)]
        exponent = _exponent(where, text, node.right)
        if exponent < 0 and base.expression == 0:
            raise InputError(f"{where}: zero to a negative power at {_at(node)}")
        size = math.comb(base.terms + abs(exponent) - 1, abs(exponent)) if exponent else 1
        return _bounded(
            where,
            node,
            Parsed(
                sp.Integer(0),
                base.degree * abs(exponent),
                size,
                base.scale * abs(exponent),
                base.digits * abs(exponent),
            ),
            lambda: base.expression**exponent,
        )
    if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub, ast.Mult, ast.Div)):
        left, right = built[id(node.left)], built[id(node.right)]
        if isinstance(node.op, (ast.Add, ast.Sub)):
            add = isinstance(node.op, ast.Add)
            value = (
                left.expression + right.expression if add else left.expression - right.expression
            )
            # a sum's coefficients: their sizes add; digits: the larger (decimals share
            # their denominators; what sympy combines is measured at the end)
            return _bounded(
                where,
                node,
                Parsed(
                    sp.Integer(0),
                    max(left.degree, right.degree),
                    left.terms + right.terms,
                    _sum_scale(left.scale, right.scale),
                    max(left.digits, right.digits),
                ),
                lambda: value,
            )
        if isinstance(node.op, ast.Div) and right.expression == 0:
            raise InputError(f"{where}: division by zero at {_at(node)}")
        return _bounded(
            where,
            node,
            Parsed(
                sp.Integer(0),
                left.degree + right.degree,
                left.terms * right.terms,
                left.scale + right.scale,
                left.digits + right.digits,
            ),
            lambda: (
                left.expression * right.expression
                if isinstance(node.op, ast.Mult)
                else left.expression / right.expression
            ),
        )
    if isinstance(node, ast.BinOp):
        operator = _BINARY_NAMES.get(type(node.op), type(node.op).__name__)
        raise _refuse(where, text, node, f"the operator {operator} in")
    if isinstance(node, ast.UnaryOp):
        raise _refuse(where, text, node, "the unary operator in")
    raise _refuse(where, text, node, _WHAT.get(type(node), "the construct"))


def _sum_scale(left: float, right: float) -> float:
    """``log10(10^left + 10^right)`` without overflow."""
    high, low = max(left, right), min(left, right)
    return high + math.log10(1.0 + 10.0 ** (low - high))


def _digits(value: sp.Rational) -> int:
    """Decimal digits of the numerator, plus the denominator's unless it is 1 (from their
    logarithms: no conversion to text, which Python refuses past 4300 digits)."""
    parts = (value.p,) if value.q == 1 else (value.p, value.q)
    return sum(math.floor(math.log10(abs(int(x)))) + 1 if x else 1 for x in parts)


def _bounded(where: str, node: ast.AST, bounds: Parsed, make: Callable[[], sp.Expr]) -> Parsed:
    """Build ``make()`` only when the degree, the expanded size and the numbers it makes
    stay within bounds."""
    if bounds.degree > MAX_DEGREE:
        raise InputError(f"{where}: the expression's degree exceeds {MAX_DEGREE} at {_at(node)}")
    if bounds.terms > MAX_TERMS:
        raise InputError(
            f"{where}: the expression at {_at(node)} may expand to more than {MAX_TERMS} terms"
        )
    if bounds.digits > MAX_NUMBER_DIGITS:
        raise InputError(
            f"{where}: the expression at {_at(node)} makes a number of more than "
            f"{MAX_NUMBER_DIGITS} digits"
        )
    value = make()
    # a number is measured as built (its digits are bounded): 333/331 is near 1 in size
    scale = _scale_of(value) if isinstance(value, sp.Rational) else bounds.scale
    if scale > MAX_SCALE:
        raise InputError(
            f"{where}: the expression at {_at(node)} makes coefficients outside "
            f"1e-{MAX_SCALE}..1e{MAX_SCALE} in size (with the parameters' values); rescale "
            "the units"
        )
    return Parsed(value, bounds.degree, bounds.terms, scale, bounds.digits)


__all__ = [
    "ACCEPTED",
    "MAX_DEGREE",
    "MAX_EXPONENT",
    "MAX_LENGTH",
    "MAX_LITERAL_DIGITS",
    "MAX_NESTING",
    "MAX_NODES",
    "MAX_NUMBER_DIGITS",
    "MAX_SCALE",
    "MAX_TERMS",
    "STATE_NAMES",
    "Parsed",
    "parameter_name_error",
    "parameter_symbol",
    "parse_bounded",
    "parse_expression",
]
