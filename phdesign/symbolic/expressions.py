r"""Safe parsing and printing of scalar expressions and boundary-trace expressions.

Users write matrix entries (``"1/rho"``, ``"EI*(1 + z/10)"``) and boundary
ports as trace expressions (``"-e2(0)"``, ``"(e1(0) - e2(0))/sqrt(2)"``,
``"EI*e2'(b)"``).  A trace ``e<i><primes>(<point>)`` is the value at an
endpoint of the ``k``-th :math:`z`-derivative (``k`` = number of primes) of the
``i``-th effort component :math:`e = \mathcal{H} x`.

The text is read by a small recursive-descent parser: user text is never
evaluated as Python (no :func:`eval`, no :func:`sympy.sympify` on raw text).
Printing (:mod:`phdesign.symbolic.printing`) goes through sympy's ``str`` with each trace
symbol renamed to the user syntax, so ``parse(format(expr)) == expr`` holds exactly.

The grammar and its limits live in :mod:`phdesign.symbolic.parser`.

Examples
--------
>>> from phdesign.symbolic.printing import format_expression
>>> expr = parse_trace_expression("(e1(0) - e2'(1))/sqrt(2)", interval=(0, 1), order=2, size=2)
>>> format_expression(expr, interval=(0, 1))
"sqrt(2)*(e1(0) - e2'(1))/2"
>>> parse_scalar("1/rho + z**2", parameters=["rho"])
z**2 + 1/rho
"""

from __future__ import annotations

import fractions
import math
import numbers
import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Literal

import sympy

from phdesign.core.checks import not_bytes
from phdesign.core.errors import ExpressionError
from phdesign.core.limits import MAX_NUMBER_OPERATIONS
from phdesign.symbolic.parser import CONSTANTS, FUNCTIONS, Token, brief, check_text, parse

__all__ = [
    "Trace",
    "Z",
    "canonical",
    "exact_matrix",
    "exact_number",
    "linear_coefficients",
    "parameter_symbol",
    "parse_scalar",
    "parse_trace_expression",
    "trace_of",
    "trace_symbol",
    "vanishes",
]

Side = Literal["a", "b"]

#: The spatial variable of every model.
Z = sympy.Symbol("z", real=True)

#: Names a parameter may not take: they mean something else in expressions.
RESERVED_NAMES = frozenset({"z", "a", "b", *FUNCTIONS, *CONSTANTS})
_TRACE_NAME = re.compile(r"e\d+\Z")
_PARAMETER_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


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
        match[3],  # type: ignore[arg-type]
    ):
        return None
    return Trace(int(match[1]), len(match[2]), match[3])  # type: ignore[arg-type]


@lru_cache(maxsize=1024)
def parameter_symbol(name: str) -> sympy.Symbol:
    """Return the real symbol used for parameter ``name``."""
    return sympy.Symbol(name, real=True)


def check_parameter_name(name: str) -> None:
    """Raise :class:`ExpressionError` unless ``name`` can name a parameter."""
    if not isinstance(name, str) or not _PARAMETER_NAME.match(name):
        raise ExpressionError(
            f"parameter name {name!r} is not an identifier (letters, digits, underscore)"
        )
    if name in RESERVED_NAMES or _TRACE_NAME.match(name):
        raise ExpressionError(
            f"parameter name {name!r} is reserved (z, a, b, e<i>, functions and constants)"
        )


def exact_number(value: object, what: str) -> sympy.Expr:
    """Convert an int, float, fraction, sympy number or numeric string to an exact number.

    Floats are read through their shortest decimal representation, so ``0.2``
    becomes :math:`1/5` exactly; strings go through the safe parser. NaN, infinities,
    non-real values and magnitudes outside 1e-300..1e300 (other than 0) are refused.

    Examples
    --------
    >>> exact_number(0.2, "d")
    1/5
    >>> exact_number("sqrt(2)/2", "gain")
    sqrt(2)/2
    """
    if isinstance(value, bool):
        raise ExpressionError(f"{what} must be a number; found the boolean {value}")
    if isinstance(value, str):
        expr = parse_scalar(value, parameters=(), allow_z=False, what=what)
    elif isinstance(value, numbers.Integral):
        expr = sympy.Integer(int(value))
    elif isinstance(value, fractions.Fraction):
        expr = sympy.Rational(value.numerator, value.denominator)
    elif isinstance(value, numbers.Real) and not isinstance(value, sympy.Basic):
        number = float(value)
        if not math.isfinite(number):
            raise ExpressionError(f"{what} must be a finite number; found {value}")
        expr = sympy.Rational(repr(number))
    elif isinstance(value, sympy.Expr):
        expr = exactify(value)
        if expr.has(sympy.nan, sympy.zoo, sympy.oo, -sympy.oo):
            raise ExpressionError(f"{what} must be a finite number; found {value}")
        if not expr.is_number or expr.is_real is False or expr.has(sympy.I):
            raise ExpressionError(f"{what} must be a real number; found {_brief(expr)}")
    else:
        raise ExpressionError(
            f"{what} must be a number; found {type(value).__name__} {_brief(value)}"
        )
    _check_range(expr, what)
    return expr


def _check_range(expr: sympy.Expr, what: str) -> None:
    """Refuse a non-zero number whose magnitude lies outside 1e-300..1e300."""
    if expr.is_zero:
        return
    if not expr.is_Rational and expr.count_ops() > MAX_NUMBER_OPERATIONS:
        raise ExpressionError(f"{what} has more than {MAX_NUMBER_OPERATIONS} operations")
    value = expr if expr.is_Rational else sympy.N(expr, 15)  # exact comparison if rational
    if not value.is_Number:
        raise ExpressionError(f"{what} must be a real number; found {_brief(expr)}")
    if sympy.Rational(1, 10**300) <= abs(value) <= 10**300:
        return
    raise ExpressionError(
        f"{what} is out of range; expected magnitudes between 1e-300 and 1e300 (or 0); "
        f"found {_brief(expr)}"
    )


def _brief(value: object) -> str:
    return brief(value, 60)


def exact_matrix(value: object, what: str, symbols: bool = False) -> sympy.ImmutableMatrix:
    """Convert a matrix (nested lists, sympy or numpy) to an exact sympy matrix, safely.

    Entries go through :func:`exact_number` (text through the safe parser, never
    :func:`sympy.sympify`); with ``symbols`` true, sympy expressions holding symbols are
    kept as they are (e.g. symbolic gains).

    Raises
    ------
    ExpressionError
        If ``value`` is not a non-empty rectangular matrix of finite real numbers.

    Examples
    --------
    >>> exact_matrix([[0.5, "1/3"]], "C_m")
    Matrix([[1/2, 1/3]])
    """
    if isinstance(value, sympy.MatrixBase):
        rows: object = value.tolist()
    elif hasattr(value, "tolist") and not isinstance(value, str | sympy.Basic):
        rows = value.tolist()  # numpy arrays, without importing numpy here
    else:
        rows = value
    if isinstance(rows, str | bytes) or not isinstance(rows, Sequence) or not rows:
        raise ExpressionError(
            f"{what} must be a non-empty matrix (a list of rows); found {_brief(value)}"
        )
    for i, r in enumerate(rows):
        not_bytes(r, f"{what} row {i + 1}", ExpressionError)
    table = [list(r) if isinstance(r, Sequence) and not isinstance(r, str) else r for r in rows]
    if not all(isinstance(r, list) and r for r in table):
        raise ExpressionError(
            f"{what} must be a non-empty list of non-empty rows; found {_brief(value)}"
        )
    width = len(table[0])
    for i, row in enumerate(table):
        if len(row) != width:
            raise ExpressionError(
                f"{what} row {i + 1} has {len(row)} entries; expected {width} like row 1"
            )
    entries = []
    for i, row in enumerate(table):
        converted = []
        for j, x in enumerate(row):
            where = f"{what}[{i + 1},{j + 1}]"
            if symbols and isinstance(x, sympy.Expr) and x.free_symbols:
                converted.append(exactify(x))
            else:
                converted.append(exact_number(x, where))
        entries.append(converted)
    return sympy.ImmutableMatrix(entries)


def canonical(expr: sympy.Expr) -> sympy.Expr:
    """Return ``cancel(expand(expr))``, far cheaper than :func:`sympy.simplify`.

    It is canonical for rational functions of the parameters with algebraic coefficients.
    """
    if expr.is_Number:
        return expr
    return sympy.cancel(sympy.expand(expr))


def vanishes(expr: object) -> bool:
    """Decide exactly whether ``expr`` is identically zero, cheaply when possible.

    Rational functions (of gains or parameters) and algebraic numbers are settled by
    :func:`canonical`; :func:`sympy.simplify` is the last resort, for transcendental
    entries (it is slow, and imports ``sympy.physics`` on first use).
    """
    try:
        e = sympy.sympify(expr, strict=True)  # strict: text is never parsed here
    except sympy.SympifyError:
        raise ExpressionError(
            f"expected a sympy expression or a number; found {type(expr).__name__}"
        ) from None
    if e == 0:
        return True
    if e.is_Number:
        return False
    e = canonical(e)
    if e == 0:
        return True
    if e.is_number and e.is_zero is not None:
        return bool(e.is_zero)
    if e.is_rational_function():
        return False
    return bool(sympy.simplify(e) == 0)


def exactify(expr: sympy.Expr) -> sympy.Expr:
    """Replace every sympy Float in ``expr`` by the exact rational of its decimal form."""
    floats = expr.atoms(sympy.Float)
    if not floats:
        return expr
    exact = {}
    for f in floats:
        number = float(f)
        if not math.isfinite(number):
            raise ExpressionError(f"a floating-point number in {_brief(expr)} is not finite")
        exact[f] = sympy.Rational(repr(number))
    return expr.xreplace(exact)


def parse_scalar(
    text: str, parameters: Iterable[str] = (), allow_z: bool = True, what: str = "expression"
) -> sympy.Expr:
    """Parse an expression in :math:`z` and the named parameters.

    Parameters
    ----------
    text : str
        The expression, e.g. ``"1/rho"`` or ``"EI*(1 + z/10)"``.
    parameters : iterable of str
        Names that may appear; any other name is an error that names it.
    allow_z : bool
        Whether the spatial variable ``z`` may appear.
    what : str
        How to name the expression in error messages.

    Returns
    -------
    sympy.Expr
        The exact expression (decimals become rationals).
    """
    check_text(text, what)
    names = _names(parameters)
    try:
        return parse(text, _name_resolver(names, allow_z))
    except ExpressionError as error:
        raise ExpressionError(f"{what}: {error}") from None


def _names(parameters: object) -> frozenset[str]:
    """Return the parameter names a caller allows, refusing anything but text."""
    if isinstance(parameters, str) or not isinstance(parameters, Iterable):
        raise ExpressionError(f"parameters must be a list of names; found {_brief(parameters)}")
    names = list(parameters)
    if not all(isinstance(name, str) for name in names):
        raise ExpressionError(f"parameters must be a list of names; found {_brief(names)}")
    return frozenset(names)


def _name_resolver(parameters: frozenset[str], allow_z: bool) -> Callable[[str, str], sympy.Expr]:
    """Resolve ``z`` and parameter names; any other name is an error that lists the known ones."""

    def resolve(name: str, text: str) -> sympy.Expr:
        if name == "z":
            if not allow_z:
                raise ExpressionError(f"the spatial variable z is not allowed in {text!r}")
            return Z
        if name in parameters:
            return parameter_symbol(name)
        known = sorted(parameters)
        raise ExpressionError(
            f"unknown symbol {name!r} in {text!r}; "
            f"known parameters: {', '.join(known) if known else 'none'}"
        )

    return resolve


def _endpoints(interval: object) -> tuple[sympy.Expr, sympy.Expr]:
    """Return the exact endpoints of a caller's interval (numbers, or text for the parser)."""
    if isinstance(interval, str) or not isinstance(interval, Sequence) or len(interval) != 2:
        raise ExpressionError(f"interval must be a pair (a, b); found {_brief(interval)}")
    a, b = (exact_number(p, "interval endpoint") for p in interval)
    return a, b


def _point_text(interval: Sequence[object], side: Side) -> str:
    try:  # a model prints every trace at its interval: read the endpoints once
        return _cached_point_text(tuple(interval), side)
    except TypeError:  # an unhashable endpoint
        from phdesign.symbolic.printing import format_expression

        return format_expression(_endpoints(interval)[0 if side == "a" else 1])


#: Longest endpoint text a trace's point may hold (:func:`_side_of` reads no longer one).
_POINT_TEXT_LIMIT = 40


@lru_cache(maxsize=256)
def _cached_point_text(interval: tuple[object, ...], side: Side) -> str:
    from phdesign.symbolic.printing import format_expression  # printing reads traces here

    text = format_expression(_endpoints(interval)[0 if side == "a" else 1])
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

    try:
        expr = parse(text, _name_resolver(_names(parameters), False), make_trace)
    except ExpressionError as error:
        raise ExpressionError(f"{what} {text!r}: {error}") from None
    linear_coefficients(expr, what=f"{what} {text!r}")
    return expr


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
            f"{what} must be a sympy expression; found {type(expr).__name__} {_brief(expr)}"
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
