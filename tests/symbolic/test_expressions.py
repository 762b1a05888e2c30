"""The trace-expression language: parsing, printing, and refusing what it must refuse."""

from __future__ import annotations

import contextlib

import pytest
import sympy
from hypothesis import given
from hypothesis import strategies as st

from phdesign.core.errors import ExpressionError
from phdesign.symbolic.expressions import Z, exact_number, parameter_symbol, parse_scalar
from phdesign.symbolic.printing import format_expression
from phdesign.symbolic.traces import (
    Trace,
    linear_coefficients,
    parse_trace_expression,
    trace_of,
    trace_symbol,
)

INTERVAL = (0, 1)


def traces(text: str, order: int = 2, size: int = 2, parameters=("EI", "d")) -> sympy.Expr:
    return parse_trace_expression(text, INTERVAL, order, size, parameters)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        # each expected value is the definition of the syntax in DESIGN.md
        ("e2''(1)", trace_symbol(2, 2, "b")),
        ("-e2(0)", -trace_symbol(2, 0, "a")),
        (
            "(e1(0) - e2(0))/sqrt(2)",
            (trace_symbol(1, 0, "a") - trace_symbol(2, 0, "a")) / sympy.sqrt(2),
        ),
        ("EI*e2'(b)", parameter_symbol("EI") * trace_symbol(2, 1, "b")),
        ("e1(a) + 2*e1( 1 )", trace_symbol(1, 0, "a") + 2 * trace_symbol(1, 0, "b")),
        ("0.5*e1(0)", sympy.Rational(1, 2) * trace_symbol(1, 0, "a")),
        ("e1(0)/2^2", trace_symbol(1, 0, "a") / 4),
        ("-(-e1(1))", trace_symbol(1, 0, "b")),
    ],
)
def test_parse_trace_expression(text, expected):
    result = traces(text, order=3)
    assert sympy.simplify(result - expected) == 0


def test_trace_symbol_round_trip():
    symbol = trace_symbol(3, 2, "a")
    assert trace_of(symbol) == Trace(3, 2, "a")
    assert trace_of(sympy.Symbol("e3''(a)")) is None  # not real: not a phdesign trace
    assert trace_of(parameter_symbol("d")) is None


def test_linear_coefficients():
    expr = traces("(e1(0) - 3*e2'(1))/d")
    d = parameter_symbol("d")
    assert linear_coefficients(expr) == {Trace(1, 0, "a"): 1 / d, Trace(2, 1, "b"): -3 / d}


def test_scalar_is_exact():
    assert parse_scalar("0.1 + 1e-3", ()) == sympy.Rational(101, 1000)
    assert parse_scalar("EI*(1 + z/10)", ["EI"]) == parameter_symbol("EI") * (1 + Z / 10)
    assert parse_scalar("2**-1") == sympy.Rational(1, 2)
    assert parse_scalar("-2**2") == -4  # power binds tighter than unary minus, as in Python
    assert exact_number(0.2, "d") == sympy.Rational(1, 5)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("e1(0)*e2(0)", "not linear"),
        ("e1(0)**2", "not linear"),
        ("sin(e1(0))", "not linear"),
        ("e1(0) + 1", "constant term"),
        ("e1(0.5)", "interior"),
        ("e1(2)", "interior or outside"),
        ("e3(0)", "component index"),
        ("e0(0)", "component index"),
        ("e1''(0)", "derivative order 2"),
        ("x*e1(0)", "unknown symbol 'x'"),
        ("z*e1(0)", "spatial variable"),
        ("2", "no trace"),
        ("", "empty"),
        ("e1(0) +", "ends too early"),
        ("(e1(0)", r"expected '\)'"),
        ("e1(0))", r"unexpected '\)'"),
        ("e1(0) ; 1", "unexpected character ';'"),
        ("__import__('os').system('true')", "unexpected character"),
        ("e1(0).real", "unexpected character"),
        ("lambda: e1(0)", "unexpected character ':'"),
        ("e1(0)/0", "division by zero"),
        ("2**1000*e1(0)", "exponent"),
        ("e1(x)", "point"),
        ("1e999*e1(0)", "out of range"),
        ("((10**64)**64)**64*e1(0)", "out of range"),
        ("1" * 311 + "*e1(0)", "out of range"),  # digits beyond MAX_NUMBER_DIGITS
        ("2" * 303 + "*e1(0)", "out of range"),  # 303 digits but more than 1000 bits
        ("(" * 300 + "e1(0)" + ")" * 300, "nested"),
    ],
)
def test_bad_trace_expressions(text, message):
    with pytest.raises(ExpressionError, match=message):
        traces(text)


def test_overlong_text_is_refused():
    with pytest.raises(ExpressionError, match="characters long"):
        traces("e1(0)+" * 5000 + "e1(0)")


def test_non_text_is_refused():
    with pytest.raises(ExpressionError, match="must be text"):
        traces(3)  # type: ignore[arg-type]


_atoms = st.sampled_from(["e1(0)", "e2(1)", "e1'(0)", "e2'(b)", "d", "EI", "2", "sqrt(3)", "0.25"])


@st.composite
def linear_texts(draw) -> str:
    """Random linear trace expressions: sum of nonzero coefficient * distinct traces."""
    terms = draw(
        st.lists(
            st.tuples(
                st.sampled_from(["1", "-2", "d", "sqrt(2)/EI", "0.75"]),
                st.sampled_from(["e1(0)", "e2(1)", "e1'(0)", "e2'(b)"]),
            ),
            min_size=1,
            max_size=4,
            unique_by=lambda term: term[1],
        )
    )
    return " + ".join(f"({c})*{t}" for c, t in terms)


@given(linear_texts())
def test_print_then_parse_is_exact(text):
    expr = traces(text)
    assert traces(format_expression(expr, INTERVAL)) == expr


@given(st.text(max_size=60))
def test_random_text_raises_only_expression_error(text):
    with contextlib.suppress(ExpressionError):
        traces(text)
