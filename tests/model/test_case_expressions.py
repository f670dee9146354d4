"""The case file's expression parser: exact values, the whitelist, hostile inputs refused in
one line with nothing run."""

from __future__ import annotations

import builtins
from pathlib import Path

import hypothesis.strategies as st
import pytest
import sympy as sp
from hypothesis import given, settings

from chargedesign.errors import InputError
from chargedesign.model.case import g1, g2, g3, p, q, r
from chargedesign.scene.expressions import (
    MAX_EXPONENT,
    MAX_LENGTH,
    MAX_LITERAL_DIGITS,
    MAX_NESTING,
    parameter_name_error,
    parameter_symbol,
    parse_expression,
)

G = parameter_symbol("g")


def test_literals_are_exact_from_their_decimal_text() -> None:
    assert parse_expression("0.1*gamma1", "V") == sp.Rational(1, 10) * g1
    assert parse_expression("2.5e-3", "V") == sp.Rational(1, 400)
    assert parse_expression("1_000 - 1e3", "V") == 0
    assert parse_expression("0.3", "V") != sp.Float(0.3)  # not the binary float


def test_the_whitelisted_grammar_builds_the_expected_expression() -> None:
    built = parse_expression(
        "(p**2 - q**2 - g*gamma1)**2 + (2*p*q - g*gamma2)**2 - -r/gamma3**-2 + +1",
        "F",
        {"g": G},
    )
    expected = (p**2 - q**2 - G * g1) ** 2 + (2 * p * q - G * g2) ** 2 + r * g3**2 + 1
    assert sp.expand(built - expected) == 0


def test_an_expression_may_span_lines_and_start_with_spaces() -> None:
    assert parse_expression("  1 +\n  gamma1\n", "V") == 1 + g1


def _one_line(exc: pytest.ExceptionInfo[InputError]) -> str:
    text = str(exc.value)
    assert "\n" not in text
    return text


@pytest.mark.parametrize(
    ("text", "named"),
    [
        ("__import__('os').system('true')", "a call `__import__("),
        ("gamma1.real", "an attribute `gamma1.real` at column 1"),
        ("lambda: 1", "a lambda"),
        ("(lambda: 1)()", "a call"),
        ("g[0]", "a subscript"),
        ("p if q else r", "a conditional"),
        ("p < q", "a comparison"),
        ("'a'", "the constant `'a'`"),
        ("True", "the constant `True`"),
        ("3j", "the constant `3j`"),
        ("0x10", "not a decimal number"),
        ("gamma1^2", "^ (write powers as **)"),
        ("p // q", "//"),
        ("x + 1", "the name `x` at column 1"),
        ("p + __builtins__", "the name `__builtins__` at column 5"),
        ("gamma1**gamma2", "the exponent (only integer literals)"),
        ("gamma1**0.5", "the exponent (only integer literals)"),
        (f"gamma1**{MAX_EXPONENT + 1}", "larger than"),
        ("p**(10**9)", "the exponent"),
        ("((gamma1 + 1)**20)**20", "degree exceeds"),
        ("((1e30)**24)**24", "more than 400 digits"),
        ("9" * (MAX_LITERAL_DIGITS + 1), f"more than {MAX_LITERAL_DIGITS} digits"),
        ("1e999", "outside"),
        ("(" * (MAX_NESTING + 1) + "1" + ")" * (MAX_NESTING + 1), "nested deeper"),
        ("1)+(2", "unmatched `)`"),
        ("1/0", "division by zero"),
        ("p +", "invalid syntax"),
        ("", "empty"),
        ("é", "the character"),
        ("x" * (MAX_LENGTH + 1), "longer than"),
        ("-" * 5000 + "1", "not an expression"),
    ],
)
def test_a_refused_token_is_one_line_naming_it(text: str, named: str) -> None:
    with pytest.raises(InputError) as exc:
        parse_expression(text, "case.V", {"g": G})
    message = _one_line(exc)
    assert message.startswith("case.V: ")
    assert named in message


def test_columns_count_from_one_in_the_text_as_written() -> None:
    with pytest.raises(InputError, match=r"`foo` at column 10"):
        parse_expression("gamma1 + foo", "V")
    with pytest.raises(InputError, match=r"`foo` at line 2, column 3"):
        parse_expression("gamma1 +\n  foo", "V")


def test_a_hostile_expression_runs_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Neither eval, exec nor sympify is reached, and the payload's side effect never happens."""

    def trap(*args: object, **kwargs: object) -> None:
        raise AssertionError("eval/exec/sympify reached")

    monkeypatch.setattr(builtins, "eval", trap)
    monkeypatch.setattr(builtins, "exec", trap)
    monkeypatch.setattr(sp, "sympify", trap)
    monkeypatch.setattr(sp.parsing.sympy_parser, "parse_expr", trap)
    marker = tmp_path / "ran"
    for payload in (
        f"__import__('os').system('touch {marker}')",
        f"open('{marker}', 'w')",
        f"(lambda: open('{marker}', 'w'))()",
        "[c for c in ().__class__.__base__.__subclasses__()]",
    ):
        with pytest.raises(InputError):
            parse_expression(payload, "case.integral")
    assert not marker.exists()
    # and a good expression still parses without any of them
    assert parse_expression("gamma1**2 + 1/gamma3**2", "V") == g1**2 + g3**-2


def test_parameter_names() -> None:
    assert parameter_name_error("kappa") is None
    assert parameter_name_error("lambda") is None  # the theorem's name, read under an alias
    assert "constant" in (parameter_name_error("None") or "")
    assert "state variable" in (parameter_name_error("gamma1") or "")
    assert parameter_name_error("__class__") is not None
    assert parameter_name_error("2x") is not None


# ---------------------------------------------------------- property: text and tree agree

_NAMES = {"p": p, "q": q, "r": r, "gamma1": g1, "gamma2": g2, "gamma3": g3, "g": G}
_LEAVES = st.sampled_from(sorted(_NAMES)).map(lambda n: (n, _NAMES[n])) | st.integers(0, 99).map(
    lambda k: (str(k), sp.Integer(k))
)


def _combine(left: tuple[str, sp.Expr], op: str, right: tuple[str, sp.Expr]):  # type: ignore[no-untyped-def]
    value = {"+": left[1] + right[1], "-": left[1] - right[1], "*": left[1] * right[1]}[op]
    return f"({left[0]} {op} {right[0]})", value


def _extend(children: st.SearchStrategy) -> st.SearchStrategy:  # type: ignore[type-arg]
    binary = st.tuples(children, st.sampled_from(["+", "-", "*"]), children).map(
        lambda t: _combine(*t)
    )
    power = st.tuples(children, st.integers(0, 3)).map(
        lambda t: (f"({t[0][0]})**{t[1]}", t[0][1] ** t[1])
    )
    negative = children.map(lambda c: (f"-({c[0]})", -c[1]))
    return binary | power | negative


@settings(max_examples=60, deadline=None)
@given(st.recursive(_LEAVES, _extend, max_leaves=8))
def test_parsed_text_equals_the_expression_built_beside_it(case: tuple[str, sp.Expr]) -> None:
    """Independent route: each generated text is built alongside by sympy arithmetic."""
    text, expected = case
    assert sp.expand(parse_expression(text, "F", {"g": G}) - expected) == 0


def test_a_parameter_named_like_a_keyword_is_a_parameter_and_never_the_keyword() -> None:
    lam = parameter_symbol("lambda")
    built = parse_expression("lambda/gamma3**2 + lambdas", "V", {"lambda": lam, "lambdas": G})
    assert built == lam / g3**2 + G
    with pytest.raises(InputError, match="invalid syntax"):
        parse_expression("lambda: 1", "V", {"lambda": lam})
    with pytest.raises(InputError, match="invalid syntax"):  # undeclared: the keyword
        parse_expression("lambda + 1", "V")


def test_the_expanded_size_is_bounded_before_anything_is_built() -> None:
    with pytest.raises(InputError, match="may expand to more than"):
        parse_expression("(p + q + r + gamma1 + gamma2 + gamma3 + 1)**20", "F")


_ALPHABET = st.sampled_from(list("pqr gamma123+-*/()**.e0123456789_^%@[]{}'\",:;!<>=~&|lambdx\t"))


@settings(max_examples=300, deadline=None)
@given(st.text(_ALPHABET, max_size=60) | st.text(max_size=30))
def test_any_text_parses_or_is_refused_in_one_line(text: str) -> None:
    """Whatever the text, the parser returns an expression or raises InputError (one line)."""
    try:
        parse_expression(text, "case.V", {"g": G})
    except InputError as exc:
        assert "\n" not in str(exc) and str(exc).startswith("case.V: ")
