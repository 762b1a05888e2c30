r"""Boundary traces and the trace expressions that define a model's ports.

A trace ``e<i><primes>(<point>)`` is the value at an endpoint of the ``k``-th
:math:`z`-derivative (``k`` = number of primes) of the ``i``-th effort component
:math:`e = \mathcal{H} x`.  Users write the boundary ports as linear combinations of
traces (``"-e2(0)"``, ``"(e1(0) - e2(0))/sqrt(2)"``, ``"EI*e2'(b)"``), read by the safe
parser (:mod:`phdesign.symbolic.parser`) with coefficients in the parameters
(:mod:`phdesign.symbolic.expressions`).  Each trace is a real sympy symbol named in the
user syntax at the symbolic points ``a`` and ``b`` (:func:`trace_symbol`); printing
(:mod:`phdesign.symbolic.printing`) writes it at the model's endpoints, so
``parse(format(expr)) == expr`` holds exactly.

Examples
--------
>>> from phdesign.symbolic.printing import format_expression
>>> expr = parse_trace_expression("(e1(0) - e2'(1))/sqrt(2)", interval=(0, 1), order=2, size=2)
>>> format_expression(expr, interval=(0, 1))
"sqrt(2)*(e1(0) - e2'(1))/2"
>>> linear_coefficients(expr)[Trace(2, 1, "b")]
-sqrt(2)/2
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Literal

import sympy

from phdesign.core.errors import ExpressionError
from phdesign.symbolic.expressions import Z, exact_number, name_resolver
from phdesign.symbolic.parser import Token, brief, check_text, parse, unparse

__all__ = [
    "Side",
    "Trace",
    "linear_coefficients",
    "parse_trace_expression",
    "trace_of",
    "trace_reader",
    "trace_symbol",
]

Side = Literal["a", "b"]


@dataclass(frozen=True)
class Trace:
    r"""The boundary trace :math:`\partial_z^k e_i` at one endpoint.

    Parameters
    ----------
    component : int
        1-based index ``i`` of the effort component.
    derivative : int
        Order ``k`` of the :math:`z`-derivative, ``0 <= k < N``.
    side : {"a", "b"}
        The endpoint.
    """

    component: int
    derivative: int
    side: Side

    @property
    def symbol(self) -> sympy.Symbol:
        """The sympy symbol standing for this trace."""
        return trace_symbol(self.component, self.derivative, self.side)

    def label(self, interval: Sequence[object] | None = None, tilde: bool = False) -> str:
        """Return the trace in user syntax, e.g. ``e2'(0)``, or ``ẽ2'(0)`` with ``tilde``.

        ``interval`` gives the endpoints to print (numbers, or text read by the safe
        parser); without it the point is written ``a`` or ``b``.
        """
        point = self.side if interval is None else _point_text(interval, self.side)
        head = "ẽ" if tilde else "e"
        return f"{head}{self.component}{chr(39) * self.derivative}({point})"


@lru_cache(maxsize=4096)
def trace_symbol(component: int, derivative: int, side: Side) -> sympy.Symbol:
    r"""Return the symbol of trace :math:`\partial_z^k e_i(\text{side})`.

    Examples
    --------
    >>> trace_symbol(2, 1, "b")
    e2'(b)
    """
    return sympy.Symbol(f"e{component}{chr(39) * derivative}({side})", real=True)


_SYMBOL_NAME = re.compile(r"e(\d+)('*)\((a|b)\)\Z")


def trace_of(symbol: sympy.Basic) -> Trace | None:
    """Return the :class:`Trace` a symbol stands for, or ``None`` for other symbols."""
    if not isinstance(symbol, sympy.Symbol):
        return None
    match = _SYMBOL_NAME.match(symbol.name)
    if match is None or symbol != trace_symbol(
        int(match[1]),
        len(match[2]),
        match[3],
    ):
        return None
    return Trace(int(match[1]), len(match[2]), match[3])  # type: ignore[arg-type]


def _endpoints(interval: object) -> tuple[sympy.Expr, sympy.Expr]:
    """Return the exact endpoints of a caller's interval (numbers, or text for the parser)."""
    if isinstance(interval, str) or not isinstance(interval, Sequence) or len(interval) != 2:
        raise ExpressionError(f"interval must be a pair (a, b); found {brief(interval, 60)}")
    a, b = (exact_number(p, "interval endpoint") for p in interval)
    return a, b


def _point_text(interval: Sequence[object], side: Side) -> str:
    try:  # a model prints every trace at its interval: read the endpoints once
        return _cached_point_text(tuple(interval), side)
    except TypeError:  # an unhashable endpoint
        return unparse(_endpoints(interval)[0 if side == "a" else 1])


#: Longest endpoint text a trace's point may hold (:func:`_side_of` reads no longer one).
_POINT_TEXT_LIMIT = 40


@lru_cache(maxsize=256)
def _cached_point_text(interval: tuple[object, ...], side: Side) -> str:
    text = unparse(_endpoints(interval)[0 if side == "a" else 1])
    # an endpoint too long to read back as a point (b = 1e300 has 301 digits) is its name
    return text if len(text) <= _POINT_TEXT_LIMIT and _POINT_NUMBER.match(text) else side


def parse_trace_expression(
    text: str,
    interval: Sequence[object],
    order: int,
    size: int,
    parameters: Iterable[str] = (),
    what: str = "trace expression",
) -> sympy.Expr:
    """Parse a linear combination of boundary traces.

    Parameters
    ----------
    text : str
        E.g. ``"-e2(0)"``, ``"(e1(0) - e2(0))/sqrt(2)"``, ``"EI*e2'(b)"``.
    interval : (a, b)
        The spatial interval; a point is written ``a``, ``b`` or as the endpoint's value.
    order : int
        The order ``N`` of the model: derivatives up to ``N - 1`` are traces.
    size : int
        The number ``n`` of components.
    parameters : iterable of str
        Parameter names allowed in coefficients.
    what : str
        How to name the expression in error messages.

    Returns
    -------
    sympy.Expr
        A linear form in the symbols of :func:`trace_symbol`, with no constant term.
    """
    check_text(text, what)
    a, b = _endpoints(interval)
    for name, value in (("order", order), ("size", size)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ExpressionError(f"{name} must be a positive integer; found {value!r}")

    try:
        expr = parse(text, name_resolver(parameters, False), trace_reader((a, b), order, size))
    except ExpressionError as error:
        raise ExpressionError(f"{what} {text!r}: {error}") from None
    linear_coefficients(expr, what=f"{what} {text!r}")
    return expr


def trace_reader(
    interval: tuple[sympy.Expr, sympy.Expr], order: int, size: int
) -> Callable[[Token], sympy.Expr]:
    """Return the parser's trace factory: a trace token as its symbol, checked.

    The component must lie in 1..``size``, the derivative below ``order`` and the point
    at an endpoint of ``interval`` (exact endpoints).
    """
    a, b = interval

    def make_trace(token: Token) -> sympy.Expr:
        component_text, primes, point = token.groups
        component, derivative = int(str(component_text)), len(str(primes))
        if not 1 <= component <= size:
            raise ExpressionError(
                f"component index in {token.text!r} is out of range; expected 1..{size}, "
                f"found {component}"
            )
        if derivative >= order:
            raise ExpressionError(
                f"{token.text!r} has derivative order {derivative}; traces of an order-{order} "
                f"model go up to order {order - 1}"
            )
        return trace_symbol(component, derivative, _side_of(str(point), a, b, token.text))

    return make_trace


_POINT_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?(?:/\d+)?\Z")


def _side_of(point: str, a: object, b: object, trace_text: str) -> Side:
    if point in ("a", "b"):
        return point  # type: ignore[return-value]
    if not _POINT_NUMBER.match(point) or len(point) > _POINT_TEXT_LIMIT:
        raise ExpressionError(
            f"point of {trace_text!r} must be a, b or an endpoint value; found {point!r}"
        )
    value = sympy.Rational(point)
    if value == a:
        return "a"
    if value == b:
        return "b"
    raise ExpressionError(
        f"{trace_text!r} is at an interior or outside point {point}; "
        f"expected an endpoint, {a} or {b}"
    )


def linear_coefficients(expr: sympy.Expr, what: str = "expression") -> dict[Trace, sympy.Expr]:
    """Split a trace expression into its coefficients, checking that it is linear.

    Raises
    ------
    ExpressionError
        If the expression has a constant term, a product or power of traces, a trace
        inside a function, no trace at all, or a coefficient depending on ``z``.
    """
    if not isinstance(expr, sympy.Expr):
        raise ExpressionError(
            f"{what} must be a sympy expression; found {type(expr).__name__} {brief(expr, 60)}"
        )
    symbols = {s for s in expr.free_symbols if trace_of(s) is not None}
    if not symbols:
        raise ExpressionError(f"{what} contains no trace; expected a combination like e1(0)")
    if expr.has(Z):
        raise ExpressionError(f"{what} depends on z; coefficients must be constants")
    sums: dict[sympy.Symbol, list[sympy.Expr]] = {}
    # one pass over the terms of the expansion (far cheaper than a Poly in 2Nn symbols)
    for term in sympy.Add.make_args(sympy.expand(expr)):
        traces, rest = [], []
        for factor in sympy.Mul.make_args(term):
            if factor in symbols:
                traces.append(factor)
            elif factor.free_symbols & symbols:
                if factor.is_Pow and factor.base in symbols and factor.exp.is_Integer:
                    raise ExpressionError(
                        f"{what} is not linear in the traces; found degree {factor.exp}"
                    )
                raise ExpressionError(
                    f"{what} is not linear in the traces (a trace appears inside a function)"
                )
            else:
                rest.append(factor)
        if not traces:
            raise ExpressionError(f"{what} has a constant term {term}; expected none")
        if len(traces) > 1:
            raise ExpressionError(
                f"{what} is not linear in the traces; found degree {len(traces)}"
            )
        sums.setdefault(traces[0], []).append(sympy.Mul(*rest))
    coefficients: dict[Trace, sympy.Expr] = {}
    for symbol in sorted(sums, key=lambda s: s.name):
        coefficient = sympy.Add(*sums[symbol])
        if coefficient != 0:
            coefficients[trace_of(symbol)] = coefficient  # type: ignore[index]
    if not coefficients:
        raise ExpressionError(f"{what} contains no trace; expected a combination like e1(0)")
    return coefficients
