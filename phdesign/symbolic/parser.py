"""The safe expression grammar shared by matrix entries, trace expressions and initial states.

A small recursive-descent parser over whitelisted tokens: user text is never evaluated as
Python (no :func:`eval`, no :func:`sympy.sympify` on raw text). Names other than the
functions and the constant ``pi`` are resolved by the caller (parameters, ``z``), and
traces ``e<i><primes>(<point>)`` by a caller-supplied factory. Euler's number is written
``exp(1)``: ``E`` is an ordinary name (Young's modulus is a parameter like any other).

Sizes are bounded so that hostile text cannot exhaust time or memory (the budgets of
:mod:`phdesign.core.limits`): length, nesting depth, exponents as written, the degree of the
built expression (``z*z*…*z`` is ``z**k``), the bits of exact numbers, and the magnitude of
constants (``exp(exp(exp(5)))`` and ``exp(1e300)`` are refused before they are evaluated).
The result is real: ``sqrt(-1)``, ``log(0)`` and ``tan(pi/2)`` are refused.

Grammar (``**`` and ``^`` are both powers)::

    expr  := term (("+" | "-") term)*
    term  := unary (("*" | "/") unary)*
    unary := ("+" | "-") unary | power
    power := atom (("**" | "^") unary)?
    atom  := NUMBER | TRACE | NAME | NAME "(" expr ")" | CALL | "(" expr ")"

Examples
--------
>>> import sympy
>>> parse("2*sqrt(x)", lambda name, text: sympy.Symbol(name))
2*sqrt(x)
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import sympy
from sympy.printing.str import StrPrinter

from phdesign.core.errors import ExpressionError
from phdesign.core.limits import (
    MAX_DEGREE,
    MAX_DEPTH,
    MAX_EXPONENT,
    MAX_EXPRESSION_LENGTH,
    MAX_MAGNITUDE,
    MAX_NUMBER_BITS,
    MAX_NUMBER_DIGITS,
)

__all__ = [
    "CONSTANTS",
    "FUNCTIONS",
    "Token",
    "brief",
    "check_expression",
    "check_text",
    "degree_bound",
    "parse",
    "tokenize",
    "unparse",
]

#: The largest argument of exp, sinh and cosh whose value stays within MAX_MAGNITUDE.
_LARGEST_EXPONENTIAL_ARGUMENT = math.log(MAX_MAGNITUDE) + math.log(2)
_GROWING = frozenset({"exp", "sinh", "cosh"})

FUNCTIONS: dict[str, Callable[[sympy.Expr], sympy.Expr]] = {
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
CONSTANTS: dict[str, sympy.Expr] = {"pi": sympy.pi}

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
class Token:
    """One token; for a trace, ``groups`` holds (component, primes, point) as written."""

    kind: str
    text: str
    position: int
    groups: tuple[str | None, ...] = ()


def tokenize(text: str) -> list[Token]:
    """Split ``text`` into whitelisted tokens; anything else is an :class:`ExpressionError`."""
    tokens: list[Token] = []
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
            tokens.append(Token(str(kind), match.group(), position, groups))
        position = match.end()
    return tokens


# --------------------------------------------------------------------------- parser


@dataclass(frozen=True)
class _Context:
    text: str
    resolve_name: Callable[[str, str], sympy.Expr]
    trace_factory: Callable[[Token], sympy.Expr] | None
    calls: Mapping[str, Callable[[str], sympy.Expr]]


class _Parser:
    """Recursive-descent parser building sympy expressions from whitelisted tokens."""

    def __init__(self, context: _Context) -> None:
        self.context = context
        self.tokens = tokenize(context.text)
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
        return check_expression(expr, repr(self.context.text))

    def peek(self) -> Token | None:
        return self.tokens[self.index] if self.index < len(self.tokens) else None

    def take(self, *texts: str) -> Token | None:
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
        terms = [self.term()]
        while (op := self.take("+", "-")) is not None:
            rhs = self.term()
            terms.append(rhs if op.text == "+" else -rhs)
        # one Add of all the terms: adding them one by one re-sorts the sum each time
        value = terms[0] if len(terms) == 1 else self.bounded(sympy.Add(*terms))
        self.depth -= 1
        return value

    def bounded(self, value: sympy.Expr) -> sympy.Expr:
        """Refuse exact numbers too large to print or compute with (about 1e300)."""
        numbers = (value,) if value.is_Rational else value.atoms(sympy.Rational)
        for number in numbers:
            if max(abs(number.p).bit_length(), number.q.bit_length()) > MAX_NUMBER_BITS:
                raise ExpressionError(
                    f"a number in {self.context.text!r} is out of range; "
                    "expected magnitudes between 1e-300 and 1e300"
                )
        return value

    def constant(self, value: sympy.Expr) -> sympy.Expr:
        """Refuse a constant function value or power outside 1e-300..1e300, or not real."""
        if not value.is_number or value.is_Rational:
            return value
        size = _magnitude(value)
        if size is None:
            raise ExpressionError(
                f"{brief(value)} in {self.context.text!r} is not a finite real number"
            )
        if size != -math.inf and abs(size) > math.log(MAX_MAGNITUDE):
            raise ExpressionError(
                f"{brief(value)} in {self.context.text!r} is out of range; expected magnitudes "
                "between 1e-300 and 1e300"
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
            return self.constant(self.bounded(base**exponent))
        return base

    def atom(self) -> sympy.Expr:
        token = self.peek()
        if token is None:
            raise ExpressionError(f"cannot read {self.context.text!r}: it ends too early")
        self.index += 1
        if token.kind == "number":
            mantissa, _, exponent = token.text.lower().partition("e")
            if len(mantissa) > MAX_NUMBER_DIGITS or (exponent and abs(int(exponent)) > 300):
                raise ExpressionError(
                    f"number {token.text!r} is out of range; expected magnitudes between "
                    f"1e-300 and 1e300 with at most {MAX_NUMBER_DIGITS} digits"
                )
            return self.bounded(sympy.Rational(token.text))
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

    def call(self, name: str) -> sympy.Expr:
        self.expect("(")  # the text between the parentheses goes to the caller's reader
        start, depth = self.index, 1
        while self.index < len(self.tokens) and depth:
            text = self.tokens[self.index].text if self.tokens[self.index].kind == "op" else ""
            depth += (text == "(") - (text == ")")
            self.index += 1
        if depth or self.index - 1 == start:  # not closed, or empty
            raise ExpressionError(f"cannot read {self.context.text!r}: {name}(...) expected")
        first, closing = self.tokens[start], self.tokens[self.index - 1]
        return self.context.calls[name](self.context.text[first.position : closing.position])

    def name(self, token: Token) -> sympy.Expr:
        name = token.text
        following = self.peek()
        if name in self.context.calls and following is not None and following.text == "(":
            return self.call(name)
        if name in FUNCTIONS:
            self.expect("(")
            argument = self.expr()
            self.expect(")")
            if name in _GROWING and argument.is_number:
                size = _magnitude(argument)
                if size is None or size > math.log(_LARGEST_EXPONENTIAL_ARGUMENT):
                    raise ExpressionError(
                        f"{name}({brief(argument)}) in {self.context.text!r} is out of range; "
                        f"expected an argument of magnitude at most "
                        f"{_LARGEST_EXPONENTIAL_ARGUMENT:.4g} (values between 1e-300 and 1e300)"
                    )
            return self.constant(FUNCTIONS[name](argument))
        if name in CONSTANTS:
            return CONSTANTS[name]
        return self.context.resolve_name(name, self.context.text)


def brief(value: object, width: int = 40) -> str:
    """Return ``value`` as text for a message, cut to ``width`` characters.

    Examples
    --------
    >>> brief("x" * 50, 10)
    "'xxxxxx..."
    """
    text = repr(value) if isinstance(value, str) else str(value)
    return text if len(text) <= width else f"{text[: width - 3]}..."


def _magnitude(value: sympy.Expr) -> float | None:
    """Natural log of ``|value|`` for a constant (``-inf`` for zero); ``None`` if not real.

    The constant's own parts were checked when they were built, so evaluating it to 15
    digits is cheap (mpmath has no exponent range to overflow).
    """
    if value.is_zero:
        return -math.inf
    approximation = sympy.N(value, 15)
    if approximation.has(sympy.I, sympy.zoo, sympy.nan, sympy.oo, -sympy.oo):
        return None
    if not approximation.is_Number:
        return None
    if approximation == 0:
        return -math.inf
    return float(sympy.log(abs(approximation)).evalf(15))


def degree_bound(expr: sympy.Basic) -> int:
    """Bound the total degree of ``expr`` in its symbols once every power is expanded.

    Sums take the largest degree of their terms, products the sum, integer powers the
    multiple; a function or a symbolic exponent counts as the degree of its arguments.

    Examples
    --------
    >>> z = sympy.Symbol("z")
    >>> degree_bound((1 + z + z**2)**3 / (z + 1))
    7
    """
    memo: dict[sympy.Basic, int] = {}

    def bound(node: sympy.Basic) -> int:
        if node in memo:
            return memo[node]
        if node.is_Symbol:
            result = 1
        elif node.is_Atom or not node.args:
            result = 0
        elif node.is_Add:
            result = max(bound(a) for a in node.args)
        elif node.is_Mul:
            result = sum(bound(a) for a in node.args)
        elif node.is_Pow and node.exp.is_Rational:
            result = math.ceil(bound(node.base) * abs(node.exp))
        else:
            result = max(bound(a) for a in node.args)
        memo[node] = result
        return result

    return bound(expr)


#: Functions sympy forms by itself from the grammar (``sqrt(z**2)`` is ``Abs(z)``,
#: ``tan(pi/2 - z)`` is ``cot(z)``); the printer writes them back in the grammar.
_FORMED = frozenset({"Abs", "cot"})


def check_expression(expr: sympy.Expr, what: str) -> sympy.Expr:
    """Return ``expr`` if it is what the parser could have built, within the budgets.

    The same checks apply to expressions a caller builds with sympy: finite and real,
    only the grammar's functions, exact numbers within ``MAX_NUMBER_BITS`` and a degree
    within ``MAX_DEGREE`` (:mod:`phdesign.core.limits`).

    Raises
    ------
    ExpressionError
        Naming ``what`` and what was found.
    """
    if not isinstance(expr, sympy.Expr):
        raise ExpressionError(f"{what} must be an expression; found {type(expr).__name__}")
    if expr.has(sympy.I, sympy.zoo, sympy.nan, sympy.oo, -sympy.oo):
        raise ExpressionError(f"{what} is not a finite real expression; found {brief(expr)}")
    for function in expr.atoms(sympy.Function):
        name = type(function).__name__
        if name not in FUNCTIONS and name not in _FORMED:
            raise ExpressionError(
                f"{what} uses the function {name}; expected only {', '.join(sorted(FUNCTIONS))}"
            )
    for number in expr.atoms(sympy.Rational):
        if max(abs(number.p).bit_length(), number.q.bit_length()) > MAX_NUMBER_BITS:
            raise ExpressionError(
                f"a number in {what} is out of range; expected magnitudes between 1e-300 and 1e300"
            )
    if expr.atoms(sympy.Float):
        raise ExpressionError(f"{what} holds a floating-point number; expected exact numbers")
    degree = degree_bound(expr)
    if degree > MAX_DEGREE:
        raise ExpressionError(
            f"{what} has degree {degree} once built; expected at most "
            f"{MAX_DEGREE} (the budget phdesign.core.limits.MAX_DEGREE)"
        )
    return expr


class _Printer(StrPrinter):
    """sympy's printer, writing what sympy forms on its own in the grammar's syntax.

    Euler's number is ``exp(1)`` (``E`` is an ordinary name); sympy turns ``sqrt(x**2)``
    into ``Abs(x)`` and ``tan(pi/2 - x)`` into ``cot(x)`` (:data:`_FORMED`): both are
    written back in the form that builds them again, so reading the text gives the same
    expression.
    """

    def _print_Exp1(self, expr: sympy.Expr) -> str:
        return "exp(1)"

    def _print_Abs(self, expr: sympy.Expr) -> str:
        return f"sqrt(({self._print(expr.args[0])})**2)"

    def _print_cot(self, expr: sympy.Expr) -> str:
        return f"tan(pi/2 - ({self._print(expr.args[0])}))"


_PRINTER = _Printer()


def unparse(expr: sympy.Basic) -> str:
    """Write ``expr`` in the grammar's syntax, so that :func:`parse` builds it again.

    Symbols are written by their names: a trace symbol is named in the user syntax at
    the symbolic points ``a`` and ``b`` (:mod:`phdesign.symbolic.traces`);
    :func:`phdesign.symbolic.printing.format_expression` writes traces at a model's
    endpoints.

    Examples
    --------
    >>> unparse(sympy.exp(1) * sympy.Abs(sympy.Symbol("x")))
    'exp(1)*sqrt((x)**2)'
    """
    return str(_PRINTER.doprint(expr))


def check_text(text: object, what: str) -> str:
    """Return ``text`` if it is a string of at most ``MAX_EXPRESSION_LENGTH`` characters."""
    if not isinstance(text, str):
        raise ExpressionError(f"{what} must be text; found {type(text).__name__} {text!r}")
    if len(text) > MAX_EXPRESSION_LENGTH:
        raise ExpressionError(
            f"{what} is {len(text)} characters long; expected at most {MAX_EXPRESSION_LENGTH}"
        )
    return text


def parse(
    text: str,
    resolve_name: Callable[[str, str], sympy.Expr],
    trace_factory: Callable[[Token], sympy.Expr] | None = None,
    calls: Mapping[str, Callable[[str], sympy.Expr]] | None = None,
) -> sympy.Expr:
    """Parse ``text`` by the grammar of the module docstring.

    Parameters
    ----------
    text : str
        The expression (checked with :func:`check_text` by the callers).
    resolve_name : callable
        ``resolve_name(name, text)`` returns the symbol a bare name stands for, or raises
        :class:`ExpressionError`; functions and constants are resolved here.
    trace_factory : callable, optional
        Turns a trace token into a symbol; without it, traces are refused.
    calls : mapping {name: reader}, optional
        A CALL ``name(...)`` (``integral(e1)``): ``reader(text between the parentheses)``
        returns the symbol that stands for it.
    """
    return _Parser(_Context(text, resolve_name, trace_factory, calls or {})).parse()
