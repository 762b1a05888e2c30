"""The safe expression grammar shared by matrix entries, trace expressions and initial states.

A small recursive-descent parser over whitelisted tokens: user text is never evaluated as
Python (no :func:`eval`, no :func:`sympy.sympify` on raw text). Names other than the
functions and constants below are resolved by the caller (parameters, ``z``), and traces
``e<i><primes>(<point>)`` by a caller-supplied factory. Sizes are bounded so hostile text
cannot exhaust time or memory: length, nesting depth, exponents and number magnitudes.

Grammar (``**`` and ``^`` are both powers)::

    expr  := term (("+" | "-") term)*
    term  := unary (("*" | "/") unary)*
    unary := ("+" | "-") unary | power
    power := atom (("**" | "^") unary)?
    atom  := NUMBER | TRACE | NAME | NAME "(" expr ")" | "(" expr ")"

Examples
--------
>>> import sympy
>>> parse("2*sqrt(x)", lambda name, text: sympy.Symbol(name))
2*sqrt(x)
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

import sympy

from phdesign.errors import ExpressionError

__all__ = ["CONSTANTS", "FUNCTIONS", "MAX_LENGTH", "Token", "check_text", "parse", "tokenize"]

MAX_LENGTH = 10_000
MAX_DEPTH = 100
MAX_EXPONENT = 64
#: Largest bit length of the numerator or denominator of an exact number (about 1e300).
MAX_NUMBER_BITS = 1000

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
CONSTANTS: dict[str, sympy.Expr] = {"pi": sympy.pi, "E": sympy.E}

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
        return expr

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

    def name(self, token: Token) -> sympy.Expr:
        name = token.text
        if name in FUNCTIONS:
            self.expect("(")
            argument = self.expr()
            self.expect(")")
            return FUNCTIONS[name](argument)
        if name in CONSTANTS:
            return CONSTANTS[name]
        return self.context.resolve_name(name, self.context.text)


def check_text(text: object, what: str) -> str:
    """Return ``text`` if it is a string of at most :data:`MAX_LENGTH` characters."""
    if not isinstance(text, str):
        raise ExpressionError(f"{what} must be text; found {type(text).__name__} {text!r}")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(
            f"{what} is {len(text)} characters long; expected at most {MAX_LENGTH}"
        )
    return text


def parse(
    text: str,
    resolve_name: Callable[[str, str], sympy.Expr],
    trace_factory: Callable[[Token], sympy.Expr] | None = None,
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
    """
    return _Parser(_Context(text, resolve_name, trace_factory)).parse()
