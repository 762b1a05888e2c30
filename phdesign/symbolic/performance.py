r"""Performance outputs: the quantities a design is judged on, read exactly.

A performance output (``[performance] outputs`` of a model file) is

.. math::

    z_p = \int_a^b \big(c(z)^\top e + d(z)^\top x\big)\, dz
    + \sum_j r_j\, \partial_z^{k_j} e_{i_j}(\text{end}_j) + \sum_l s_l\, f_l(z_l),

written in the grammar of :mod:`phdesign.symbolic.parser`: ``integral(expr)`` is
:math:`\int_a^b \text{expr}\, dz` with expr linear in the efforts ``e<i>`` or the states
``x<i>`` (coefficients in ``z`` and the parameters), a trace ``e1(1)``, ``e2'(0)`` is a
boundary value (:mod:`phdesign.symbolic.traces`), and ``w(1)``, ``rotation(0.5)`` the
displacement or a named field at a point (:mod:`phdesign.symbolic.fields`); an output is
a linear combination of these with constant coefficients (numbers and parameters).
``integral()`` of a trace, a product or a function of efforts, a constant term and ``z``
outside ``integral()`` are refused with a message that names the output.

Examples
--------
>>> out = parse_performance_output("2*integral(z*e2) - e1(1)", (0, 1), 1, 2)
>>> out.effort_weights, out.traces
((0, 2*z), -e1(b))
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import sympy

from phdesign.core.errors import ExpressionError, ModelError
from phdesign.symbolic.expressions import Z, exact_number, name_resolver
from phdesign.symbolic.parser import Token, brief, check_text, parse
from phdesign.symbolic.traces import trace_of, trace_reader

__all__ = ["PerformanceOutput", "parse_performance", "parse_performance_output"]

_COMPONENT = re.compile(r"([ex])(\d+)\Z")
_ZERO = sympy.Integer(0)


@dataclass(frozen=True)
class PerformanceOutput:
    r"""One performance output :math:`z_p` (module docstring), read exactly.

    Attributes
    ----------
    text : str
        As written (spaces normalized): how reports name it and files write it.
    effort_weights, state_weights : tuple of sympy.Expr
        :math:`c(z)` and :math:`d(z)`, one per component: the integral part is
        :math:`\int_a^b (c^\top e + d^\top x)\, dz`.
    traces : sympy.Expr
        The boundary part, linear in the trace symbols (0 when there is none).
    points : tuple of (str, sympy.Expr, sympy.Expr)
        ``(field, point, coefficient)``: ``("w", 1, 1)`` is the displacement at 1.
    """

    text: str
    effort_weights: tuple[sympy.Expr, ...]
    state_weights: tuple[sympy.Expr, ...]
    traces: sympy.Expr = _ZERO
    points: tuple[tuple[str, sympy.Expr, sympy.Expr], ...] = ()

    @property
    def has_integral(self) -> bool:
        """Whether the output integrates along the domain."""
        return any(c != 0 for c in (*self.effort_weights, *self.state_weights))


# ----------------------------------------------------------------------------- performance


def parse_performance(
    items: Iterable[str | PerformanceOutput] | None,
    interval: Sequence[object],
    order: int,
    size: int,
    parameters: Iterable[str] = (),
    fields: Iterable[str] = (),
) -> tuple[PerformanceOutput, ...]:
    """Read the performance outputs (``performance.outputs[i]`` in the messages).

    Raises
    ------
    ModelError
        Not a list, or an output given twice.
    ExpressionError
        An output that cannot be read (see :func:`parse_performance_output`).
    """
    if items is None:
        return ()
    if isinstance(items, str) or not isinstance(items, Iterable):
        raise ModelError(
            f'performance outputs must be a list of expressions such as ["integral(e1)", '
            f'"w(1)"]; found {brief(items, 60)}'
        )
    names, fields = list(parameters), list(fields)
    out = tuple(
        item
        if isinstance(item, PerformanceOutput)
        else parse_performance_output(
            item, interval, order, size, names, fields, what=f"performance.outputs[{i + 1}]"
        )
        for i, item in enumerate(items)
    )
    texts = [o.text for o in out]
    twice = sorted({t for t in texts if texts.count(t) > 1})
    if twice:
        raise ModelError(f"performance outputs: {', '.join(twice)} given twice")
    return out


def parse_performance_output(
    text: object,
    interval: Sequence[object],
    order: int,
    size: int,
    parameters: Iterable[str] = (),
    fields: Iterable[str] = ("w",),
    what: str = "performance output",
) -> PerformanceOutput:
    """Read one performance output (the grammar of the module docstring).

    Raises
    ------
    ExpressionError
        Naming ``what`` and the text: an unreadable expression, ``integral()`` of a trace,
        an output that is not linear in the efforts and states (a product, a power, a
        function of them, a constant term), ``z`` outside ``integral()``, a point outside
        the interval or a field the model does not define.
    """
    if not isinstance(text, str):
        raise ExpressionError(
            f"{what} must be text such as 'integral(e1)' or 'w(1)'; found "
            f"{type(text).__name__} {brief(text, 60)}"
        )
    check_text(text, what)
    a, b = (exact_number(p, "interval endpoint") for p in interval)
    names = list(parameters)
    parts: dict[sympy.Symbol, Any] = {}

    def integral(argument: str) -> sympy.Expr:
        symbol = sympy.Dummy(f"integral{len(parts)}")
        parts[symbol] = _integrand(argument, size, names, what, text)
        return symbol

    fields = list(fields)

    def at(field: str) -> Any:
        def read(argument: str) -> sympy.Expr:
            if field not in fields:
                raise ExpressionError(
                    f"{field}({argument}): the model defines no displacement (a "
                    "[displacement] section); give an integral() or a trace instead"
                )
            symbol = sympy.Dummy(f"{field}{len(parts)}")
            parts[symbol] = (field, _point(argument, a, b, what, field))
            return symbol

        return read

    calls = {"integral": integral, **{name: at(name) for name in ("w", *fields)}}
    try:
        expr = parse(text, name_resolver(names, False), trace_reader((a, b), order, size), calls)
    except ExpressionError as error:
        raise ExpressionError(f"{what} {text!r}: {error}") from None
    traces = {s for s in expr.free_symbols if trace_of(s) is not None}
    coefficients = _linear(expr, {*traces, *parts}, f"{what} {text!r}", set())
    return _assemble(" ".join(text.split()), coefficients, parts, traces, size)


def _assemble(
    text: str,
    coefficients: dict[sympy.Symbol, sympy.Expr],
    parts: dict[sympy.Symbol, Any],
    traces: set[sympy.Symbol],
    size: int,
) -> PerformanceOutput:
    """Sum the integrals' weights, the traces and the field values with their coefficients."""
    effort = [_ZERO] * size
    state = [_ZERO] * size
    points = []
    for symbol, c in coefficients.items():
        if symbol in traces:
            continue
        part = parts[symbol]
        if isinstance(part[0], str):
            points.append((part[0], part[1], c))
            continue
        for i in range(size):
            effort[i] += c * part[0][i]
            state[i] += c * part[1][i]
    boundary = sympy.Add(*(c * s for s, c in coefficients.items() if s in traces))
    return PerformanceOutput(
        text,
        tuple(sympy.expand(x) for x in effort),
        tuple(sympy.expand(x) for x in state),
        boundary,
        tuple(points),
    )


def _integrand(
    argument: str, size: int, parameters: list[str], what: str, text: str
) -> tuple[list[sympy.Expr], list[sympy.Expr]]:
    """Return the weights (c, d) of ``integral(argument)``: linear in e_i and x_i."""
    base = name_resolver(parameters, True)
    symbols: dict[str, sympy.Symbol] = {}

    def resolve(name: str, whole: str) -> sympy.Expr:
        match = _COMPONENT.match(name)
        if match is None:
            return base(name, whole)
        if not 1 <= int(match[2]) <= size:
            raise ExpressionError(
                f"{name} in integral({argument}) is out of range; expected components 1..{size}"
            )
        return symbols.setdefault(name, sympy.Symbol(name, real=True))

    def no_trace(token: Token) -> sympy.Expr:
        raise ExpressionError(
            f"integral() of a trace: {token.text} is a boundary value, not a function of z; "
            f"write it outside integral(), e.g. {token.text!r} itself"
        )

    try:
        integrand = parse(argument, resolve, no_trace)
    except ExpressionError as error:
        raise ExpressionError(f"{what} {text!r}: {error}") from None
    atoms = {sympy.Symbol(f"{k}{i + 1}", real=True) for k in "ex" for i in range(size)}
    weights = _linear(integrand, atoms, f"{what} {text!r}: integral({argument})", {Z})
    effort = [weights.get(sympy.Symbol(f"e{i + 1}", real=True), _ZERO) for i in range(size)]
    state = [weights.get(sympy.Symbol(f"x{i + 1}", real=True), _ZERO) for i in range(size)]
    return effort, state


def _linear(
    expr: sympy.Expr, atoms: set[sympy.Symbol], what: str, allowed: set[sympy.Symbol]
) -> dict[sympy.Symbol, sympy.Expr]:
    """Split ``expr`` into coefficients of ``atoms``, refusing what is not linear in them.

    A coefficient may hold the parameters and ``allowed`` (``z`` inside an integral);
    no constant term may remain.
    """
    present = sorted(expr.free_symbols & atoms, key=str)
    if not present:
        raise ExpressionError(
            f"{what} holds no effort, state, trace or field; expected a linear "
            "combination such as integral(e1) or e1(1)"
        )
    coefficients = {}
    for symbol in present:
        c = sympy.diff(expr, symbol)
        if c.free_symbols & atoms:
            raise ExpressionError(
                f"{what} is not linear in the efforts (found {brief(c, 40)} as the "
                f"coefficient of {symbol}); expected a linear combination"
            )
        if Z in c.free_symbols and Z not in allowed:
            raise ExpressionError(f"{what}: z may appear only inside integral()")
        coefficients[symbol] = c
    rest = sympy.expand(expr - sum(c * s for s, c in coefficients.items()))
    if rest != 0:
        raise ExpressionError(
            f"{what} is not linear in the efforts: it has the term {brief(rest, 40)} "
            "without an effort or a state"
        )
    return coefficients


def _point(argument: str, a: sympy.Expr, b: sympy.Expr, what: str, field: str) -> sympy.Expr:
    """Return the exact point of ``field(argument)``: a, b or a number of [a, b]."""
    text = argument.strip()
    if text in ("a", "b"):
        return a if text == "a" else b
    try:
        value = parse(text, name_resolver((), False))
    except ExpressionError as error:
        raise ExpressionError(
            f"{what}: {field}({argument}) needs a point of [{a}, {b}]: {error}"
        ) from None
    if not value.is_number or not bool(a <= value) or not bool(value <= b):
        raise ExpressionError(
            f"{what}: {field}({argument}) is outside the interval [{a}, {b}]; expected a "
            "point of it"
        )
    return value
