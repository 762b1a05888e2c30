r"""Safe parsing and printing of scalar expressions and boundary-trace expressions.

Users write matrix entries (``"1/rho"``, ``"EI*(1 + z/10)"``) and boundary
ports as trace expressions (``"-e2(0)"``, ``"(e1(0) - e2(0))/sqrt(2)"``,
``"EI*e2'(b)"``).  A trace ``e<i><primes>(<point>)`` is the value at an
endpoint of the ``k``-th :math:`z`-derivative (``k`` = number of primes) of the
``i``-th effort component :math:`e = \mathcal{H} x`.

The text is read by a small recursive-descent parser: user text is never
evaluated as Python (no :func:`eval`, no :func:`sympy.sympify` on raw text).
Printing goes through sympy's ``str`` with each trace symbol renamed to the
user syntax, so ``parse(format(expr)) == expr`` holds exactly.

Grammar (``**`` and ``^`` are both powers)::

    expr  := term (("+" | "-") term)*
    term  := unary (("*" | "/") unary)*
    unary := ("+" | "-") unary | power
    power := atom (("**" | "^") unary)?
    atom  := NUMBER | TRACE | NAME | NAME "(" expr ")" | "(" expr ")"

Examples
--------
>>> from sympy import Rational
>>> expr = parse_trace_expression("(e1(0) - e2'(1))/sqrt(2)", interval=(0, 1), order=2, size=2)
>>> format_expression(expr, interval=(0, 1))
"sqrt(2)*(e1(0) - e2'(1))/2"
>>> parse_scalar("1/rho + z**2", parameters=["rho"])
z**2 + 1/rho
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Literal

import sympy

from phdesign.errors import ExpressionError

__all__ = [
    "Trace",
    "Z",
    "canonical",
    "exact_number",
    "format_expression",
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

MAX_LENGTH = 10_000
MAX_DEPTH = 100
MAX_EXPONENT = 64
#: Largest bit length of the numerator or denominator of an exact number (about 1e300).
MAX_NUMBER_BITS = 1000

_FUNCTIONS: dict[str, Callable[[sympy.Expr], sympy.Expr]] = {
    "sqrt": sympy.sqrt,
    "exp": sympy.exp,
    "log": sympy.log,
    "sin": sympy.sin,
    "cos": sympy.cos,
    "tan": sympy.tan,
    "sinh": sympy.sinh,
    "cosh": sympy.cosh,
    "tanh": sympy.tanh,
    "atan": sympy.atan,
}
_CONSTANTS: dict[str, sympy.Expr] = {"pi": sympy.pi, "E": sympy.E}
#: Names a parameter may not take: they mean something else in expressions.
RESERVED_NAMES = frozenset({"z", "a", "b", *_FUNCTIONS, *_CONSTANTS})
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
        """Return the trace in user syntax, e.g. ``e2'(0)``, or ``ẽ2'(0)`` with ``tilde``."""
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
    """Convert an int, float or numeric string to an exact sympy number.

    Floats are read through their shortest decimal representation, so ``0.2``
    becomes :math:`1/5` exactly. NaN and infinities are refused.

    Examples
    --------
    >>> exact_number(0.2, "d")
    1/5
    """
    if isinstance(value, bool):
        raise ExpressionError(f"{what} must be a number; found the boolean {value}")
    if isinstance(value, int):
        return sympy.Integer(value)
    if isinstance(value, float):
        if value != value or value in (float("inf"), float("-inf")):
            raise ExpressionError(f"{what} must be a finite number; found {value}")
        return sympy.Rational(repr(value))
    if isinstance(value, sympy.Expr):
        expr = exactify(value)
        if not expr.is_number or expr.is_real is False:
            raise ExpressionError(f"{what} must be a real number; found {value}")
        if expr.has(sympy.nan, sympy.zoo, sympy.oo, -sympy.oo):
            raise ExpressionError(f"{what} must be a finite number; found {value}")
        return expr
    if isinstance(value, str):
        expr = parse_scalar(value, parameters=(), allow_z=False, what=what)
        return exact_number(expr, what)
    raise ExpressionError(f"{what} must be a number; found {type(value).__name__} {value!r}")


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
    e = sympy.sympify(expr)
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
    return expr.xreplace({f: sympy.Rational(repr(float(f))) for f in floats})


# --------------------------------------------------------------------------- tokenizer

_TOKEN = re.compile(
    r"""
    (?P<space>\s+)
  | (?P<trace>e(?P<comp>\d+)(?P<primes>'*)\(\s*(?P<point>[^()]*?)\s*\))
  | (?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)
  | (?P<name>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<op>\*\*|[-+*/^(),])
    """,
    re.VERBOSE,
)


@dataclass(frozen=True)
class _Token:
    kind: str
    text: str
    position: int
    groups: tuple[str | None, ...] = ()


def _tokenize(text: str) -> list[_Token]:
    tokens: list[_Token] = []
    position = 0
    while position < len(text):
        match = _TOKEN.match(text, position)
        if match is None:
            raise ExpressionError(
                f"cannot read {text!r}: unexpected character {text[position]!r} "
                f"at position {position}"
            )
        kind = match.lastgroup
        if kind == "point" or kind == "primes" or kind == "comp":
            kind = "trace"
        if kind != "space":
            groups = (match["comp"], match["primes"], match["point"]) if kind == "trace" else ()
            tokens.append(_Token(str(kind), match.group(), position, groups))
        position = match.end()
    return tokens


# --------------------------------------------------------------------------- parser


@dataclass(frozen=True)
class _Context:
    text: str
    parameters: frozenset[str]
    allow_z: bool
    trace_factory: Callable[[_Token], sympy.Expr] | None


class _Parser:
    """Recursive-descent parser building sympy expressions from whitelisted tokens."""

    def __init__(self, context: _Context) -> None:
        self.context = context
        self.tokens = _tokenize(context.text)
        self.index = 0
        self.depth = 0

    def parse(self) -> sympy.Expr:
        if not self.tokens:
            raise ExpressionError("empty expression; expected a number, symbol or trace")
        expr = self.expr()
        if self.index != len(self.tokens):
            token = self.tokens[self.index]
            raise ExpressionError(
                f"cannot read {self.context.text!r}: unexpected {token.text!r} "
                f"at position {token.position}"
            )
        return expr

    def peek(self) -> _Token | None:
        return self.tokens[self.index] if self.index < len(self.tokens) else None

    def take(self, *texts: str) -> _Token | None:
        token = self.peek()
        if token is not None and token.kind == "op" and token.text in texts:
            self.index += 1
            return token
        return None

    def expect(self, text: str) -> None:
        if self.take(text) is None:
            token = self.peek()
            found = "the end" if token is None else repr(token.text)
            raise ExpressionError(
                f"cannot read {self.context.text!r}: expected {text!r}, found {found}"
            )

    def enter(self) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise ExpressionError(f"expression nested deeper than {MAX_DEPTH} levels")

    def expr(self) -> sympy.Expr:
        self.enter()
        value = self.term()
        while (op := self.take("+", "-")) is not None:
            rhs = self.term()
            value = self.bounded(value + rhs if op.text == "+" else value - rhs)
        self.depth -= 1
        return value

    def bounded(self, value: sympy.Expr) -> sympy.Expr:
        """Refuse exact numbers too large to print or compute with (about 1e300)."""
        for number in value.atoms(sympy.Rational):
            if max(abs(number.p).bit_length(), number.q.bit_length()) > MAX_NUMBER_BITS:
                raise ExpressionError(
                    f"a number in {self.context.text!r} is out of range; "
                    "expected magnitudes between 1e-300 and 1e300"
                )
        return value

    def term(self) -> sympy.Expr:
        value = self.unary()
        while (op := self.take("*", "/")) is not None:
            rhs = self.unary()
            if op.text == "*":
                value = self.bounded(value * rhs)
            else:
                if rhs == 0:
                    raise ExpressionError(f"division by zero in {self.context.text!r}")
                value = self.bounded(value / rhs)
        return value

    def unary(self) -> sympy.Expr:
        self.enter()
        if (op := self.take("+", "-")) is not None:
            value = self.unary()
            result = -value if op.text == "-" else value
        else:
            result = self.power()
        self.depth -= 1
        return result

    def power(self) -> sympy.Expr:
        base = self.atom()
        if self.take("**", "^") is not None:
            exponent = self.unary()
            if exponent.is_number and abs(exponent) > MAX_EXPONENT:
                raise ExpressionError(
                    f"exponent {exponent} in {self.context.text!r} is too large; "
                    f"expected at most {MAX_EXPONENT} in magnitude"
                )
            if base == 0 and exponent.is_number and exponent.is_nonpositive:
                raise ExpressionError(f"division by zero in {self.context.text!r}")
            return self.bounded(base**exponent)
        return base

    def atom(self) -> sympy.Expr:
        token = self.peek()
        if token is None:
            raise ExpressionError(f"cannot read {self.context.text!r}: it ends too early")
        self.index += 1
        if token.kind == "number":
            mantissa, _, exponent = token.text.lower().partition("e")
            if len(mantissa) > 60 or (exponent and abs(int(exponent)) > 300):
                raise ExpressionError(
                    f"number {token.text!r} is out of range; expected magnitudes between "
                    "1e-300 and 1e300 with at most 60 digits"
                )
            return sympy.Rational(token.text)
        if token.kind == "trace":
            if self.context.trace_factory is None:
                raise ExpressionError(
                    f"trace {token.text!r} is not allowed here; expected an expression "
                    "in z and the parameters"
                )
            return self.context.trace_factory(token)
        if token.kind == "name":
            return self.name(token)
        if token.text == "(":
            value = self.expr()
            self.expect(")")
            return value
        raise ExpressionError(
            f"cannot read {self.context.text!r}: unexpected {token.text!r} "
            f"at position {token.position}"
        )

    def name(self, token: _Token) -> sympy.Expr:
        name = token.text
        if name in _FUNCTIONS:
            self.expect("(")
            argument = self.expr()
            self.expect(")")
            return _FUNCTIONS[name](argument)
        if name in _CONSTANTS:
            return _CONSTANTS[name]
        if name == "z":
            if not self.context.allow_z:
                raise ExpressionError(
                    f"the spatial variable z is not allowed in {self.context.text!r}"
                )
            return Z
        if name in self.context.parameters:
            return parameter_symbol(name)
        known = sorted(self.context.parameters)
        raise ExpressionError(
            f"unknown symbol {name!r} in {self.context.text!r}; "
            f"known parameters: {', '.join(known) if known else 'none'}"
        )


def _check_text(text: object, what: str) -> str:
    if not isinstance(text, str):
        raise ExpressionError(f"{what} must be text; found {type(text).__name__} {text!r}")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(
            f"{what} is {len(text)} characters long; expected at most {MAX_LENGTH}"
        )
    return text


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
    _check_text(text, what)
    context = _Context(text, frozenset(parameters), allow_z, None)
    try:
        return _Parser(context).parse()
    except ExpressionError as error:
        raise ExpressionError(f"{what}: {error}") from None


def _point_text(interval: Sequence[object], side: Side) -> str:
    return str(sympy.sympify(interval[0 if side == "a" else 1]))


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
    _check_text(text, what)
    a, b = (sympy.Rational(str(sympy.sympify(p))) if _is_rational(p) else p for p in interval)

    def make_trace(token: _Token) -> sympy.Expr:
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

    context = _Context(text, frozenset(parameters), False, make_trace)
    try:
        expr = _Parser(context).parse()
    except ExpressionError as error:
        raise ExpressionError(f"{what} {text!r}: {error}") from None
    linear_coefficients(expr, what=f"{what} {text!r}")
    return expr


def _is_rational(value: object) -> bool:
    try:
        return bool(sympy.sympify(value).is_rational)
    except (sympy.SympifyError, TypeError):
        return False


_POINT_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?(?:/\d+)?\Z")


def _side_of(point: str, a: object, b: object, trace_text: str) -> Side:
    if point in ("a", "b"):
        return point  # type: ignore[return-value]
    if not _POINT_NUMBER.match(point) or len(point) > 40:
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
    symbols = sorted(
        (s for s in expr.free_symbols if trace_of(s) is not None), key=lambda s: s.name
    )
    if not symbols:
        raise ExpressionError(f"{what} contains no trace; expected a combination like e1(0)")
    if expr.has(Z):
        raise ExpressionError(f"{what} depends on z; coefficients must be constants")
    try:
        poly = sympy.Poly(sympy.expand(expr), *symbols)
    except sympy.PolynomialError:
        raise ExpressionError(
            f"{what} is not linear in the traces (a trace appears inside a function)"
        ) from None
    if poly.total_degree() > 1:
        raise ExpressionError(
            f"{what} is not linear in the traces; found degree {poly.total_degree()}"
        )
    coefficients: dict[Trace, sympy.Expr] = {}
    for monomial, coefficient in poly.terms():
        if sum(monomial) == 0:
            raise ExpressionError(f"{what} has a constant term {coefficient}; expected none")
        symbol = symbols[monomial.index(1)]
        if coefficient.free_symbols & set(symbols):
            raise ExpressionError(f"{what} is not linear in the traces")
        coefficients[trace_of(symbol)] = coefficient  # type: ignore[index]
    return coefficients


def format_expression(expr: sympy.Expr, interval: Sequence[object] | None = None) -> str:
    """Print an expression in the syntax :func:`parse_trace_expression` reads.

    Traces are written at the numeric endpoints of ``interval`` (or as ``a``/``b``
    when no interval is given).
    """
    replacements = {}
    for symbol in expr.free_symbols:
        trace = trace_of(symbol)
        if trace is not None:
            replacements[symbol] = sympy.Symbol(trace.label(interval), real=True)
    return str(expr.xreplace(replacements))
