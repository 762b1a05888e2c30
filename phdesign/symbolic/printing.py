r"""Printing expressions in the syntax the parser reads, so that reading gives them back.

:func:`format_expression` writes an expression as the grammar reads it
(:func:`phdesign.symbolic.parser.unparse`) with each boundary-trace symbol written at the
model's endpoints (``e2'(1)``, :mod:`phdesign.symbolic.traces`), so
``parse(format_expression(expr)) == expr`` exactly; :func:`format_number` prints exact
numbers short enough as they are and long ones in scientific notation.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy

from phdesign.core.errors import ExpressionError
from phdesign.symbolic.parser import unparse
from phdesign.symbolic.traces import trace_of

__all__ = ["format_expression", "format_number"]


def format_number(value: object, width: int = 28) -> str:
    """Print a number exactly when it is short, else with 6 digits in scientific notation.

    Unlike a float, the scientific form never underflows or overflows: a κ* of 1e-500
    prints as ``1.0e-500``, not ``0``.

    Examples
    --------
    >>> format_number(sympy.Rational(1, 4))
    '1/4'
    >>> format_number(sympy.Rational(1, 10**500))
    '1.0e-500'
    """
    if isinstance(value, float):
        return f"{value:.6g}"
    if not isinstance(value, sympy.Expr):
        return str(value)
    text = format_expression(value)
    if len(text) <= width or not value.is_number:
        return text
    import mpmath

    approximation = sympy.N(value, 15)
    if not approximation.is_Number:
        return text
    return str(mpmath.nstr(approximation._to_mpmath(53), 6))


def format_expression(expr: sympy.Basic, interval: Sequence[object] | None = None) -> str:
    """Print an expression in the syntax the parser reads, so that reading it gives it back.

    Traces are written at the numeric endpoints of ``interval`` (or as ``a``/``b``
    when no interval is given).

    Examples
    --------
    >>> from phdesign.symbolic.expressions import Z
    >>> format_expression(sympy.exp(1) * Z)
    'exp(1)*z'
    """
    if not isinstance(expr, sympy.Basic):
        raise ExpressionError(
            f"format_expression needs a sympy expression; found {type(expr).__name__}"
        )
    replacements = {}
    for symbol in expr.free_symbols:
        trace = trace_of(symbol)
        if trace is not None:
            replacements[symbol] = sympy.Symbol(trace.label(interval), real=True)
    return unparse(expr.xreplace(replacements))
