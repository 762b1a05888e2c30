r"""Numeric evaluation of expressions in z without generating code, and interval enclosures.

:func:`evaluate` computes an expression of :math:`z` (parameters substituted) on an array
of points by walking its tree with numpy: it replaces :func:`sympy.lambdify`, which prints
an expression as Python source and executes it, so no expression a caller built can run
code. Only the grammar's operations are known (sums, products, powers, the functions of
:mod:`phdesign.symbolic.parser`, ``Abs`` and ``cot``); anything else is an
:class:`~phdesign.core.errors.ExpressionError`.

:func:`enclose` bounds the same expression on intervals :math:`[l_i, h_i]` (interval
arithmetic, rounded outwards by a few units in the last place per operation), which is
what makes the numeric definiteness check of :mod:`phdesign.symbolic.definiteness` a
proof on each cell rather than a sample.

Examples
--------
>>> import numpy as np, sympy
>>> from phdesign.symbolic.expressions import Z
>>> evaluate(sympy.exp(-Z) + 1, np.array([0.0, 1.0]))
array([2.        , 1.36787944])
>>> lo, hi = enclose(Z**2 - Z, np.array([0.0]), np.array([1.0]))
>>> bool(lo[0] <= -0.25 and hi[0] >= 0.0)
True
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import sympy

from phdesign.core.errors import ExpressionError
from phdesign.symbolic.expressions import Z

__all__ = ["enclose", "evaluate"]

_POINTWISE: dict[str, Callable[[Any], Any]] = {
    "exp": np.exp,
    "log": np.log,
    "sin": np.sin,
    "cos": np.cos,
    "tan": np.tan,
    "sinh": np.sinh,
    "cosh": np.cosh,
    "tanh": np.tanh,
    "atan": np.arctan,
    "Abs": np.abs,
    "cot": lambda x: 1.0 / np.tan(x),
}


def _unknown(node: sympy.Basic) -> ExpressionError:
    return ExpressionError(
        f"cannot evaluate {str(node)[:60]!r}: only numbers, z, +, *, powers and the "
        f"functions {', '.join(sorted(_POINTWISE))} are known"
    )


def evaluate(expr: sympy.Basic, z: np.ndarray, variable: sympy.Symbol = Z) -> np.ndarray:
    """Evaluate ``expr`` (in ``variable``, z by default) at the points ``z``.

    Returns an array shaped like ``z``.

    Raises
    ------
    ExpressionError
        If ``expr`` holds another symbol or an operation outside the grammar.
    """
    points = np.asarray(z, dtype=float)
    memo: dict[sympy.Basic, Any] = {}

    def value(node: sympy.Basic) -> Any:
        if node in memo:
            return memo[node]
        if node == variable:
            result: Any = points
        elif node.is_number:
            result = float(sympy.N(node, 17))
        elif node.is_Add:
            result = sum((value(a) for a in node.args[1:]), value(node.args[0]))
        elif node.is_Mul:
            result = value(node.args[0])
            for a in node.args[1:]:
                result = result * value(a)
        elif node.is_Pow:
            base, exponent = value(node.base), value(node.exp)
            result = np.power(np.asarray(base, dtype=float), exponent)
        elif isinstance(node, sympy.Function) and node.func.__name__ in _POINTWISE:
            result = _POINTWISE[node.func.__name__](value(node.args[0]))
        else:
            raise _unknown(node)
        memo[node] = result
        return result

    with np.errstate(all="ignore"):
        return np.broadcast_to(np.asarray(value(expr), dtype=float), points.shape).copy()


# --------------------------------------------------------------------------- intervals
_SLACK = 4 * np.finfo(float).eps
Pair = tuple[np.ndarray, np.ndarray]


def _outward(lo: np.ndarray, hi: np.ndarray) -> Pair:
    """Widen by a few units in the last place: every numpy operation rounds within one."""
    lo = lo - _SLACK * np.abs(lo) - 1e-300
    hi = hi + _SLACK * np.abs(hi) + 1e-300
    bad = np.isnan(lo) | np.isnan(hi)
    return np.where(bad, -np.inf, lo), np.where(bad, np.inf, hi)


def _mul(x: Pair, y: Pair) -> Pair:
    with np.errstate(invalid="ignore"):
        products = np.stack([x[0] * y[0], x[0] * y[1], x[1] * y[0], x[1] * y[1]])
    products = np.where(np.isnan(products), 0.0, products)  # 0 * inf inside an enclosure
    return _outward(products.min(axis=0), products.max(axis=0))


def _reciprocal(x: Pair) -> Pair:
    lo, hi = x
    straddles = (lo <= 0) & (hi >= 0)
    with np.errstate(divide="ignore"):
        r_lo, r_hi = 1.0 / hi, 1.0 / lo
    return _outward(np.where(straddles, -np.inf, r_lo), np.where(straddles, np.inf, r_hi))


def _integer_power(x: Pair, k: int) -> Pair:
    if k < 0:
        return _reciprocal(_integer_power(x, -k))
    if k == 0:
        return np.ones_like(x[0]), np.ones_like(x[0])
    lo, hi = x
    a, b = lo**k, hi**k
    if k % 2 == 1:
        return _outward(a, b)
    contains_zero = (lo <= 0) & (hi >= 0)
    return _outward(np.where(contains_zero, 0.0, np.minimum(a, b)), np.maximum(a, b))


def _monotone(f: Callable[[Any], Any], x: Pair, increasing: bool = True) -> Pair:
    a, b = f(x[0]), f(x[1])
    return _outward(a, b) if increasing else _outward(b, a)


def _periodic(f: Callable[[Any], Any], x: Pair, peak: float) -> Pair:
    """Enclose sin or cos: ``peak`` is a point where f = 1 (f = -1 at peak + pi), period 2 pi."""
    lo, hi = x
    a, b = f(lo), f(hi)
    low, high = np.minimum(a, b), np.maximum(a, b)
    two_pi = 2 * np.pi
    top = peak + two_pi * np.ceil((lo - peak) / two_pi - 1e-12)
    bottom = peak + np.pi + two_pi * np.ceil((lo - peak - np.pi) / two_pi - 1e-12)
    high = np.where(top <= hi + 1e-12 * (1 + np.abs(hi)), 1.0, high)
    low = np.where(bottom <= hi + 1e-12 * (1 + np.abs(hi)), -1.0, low)
    wide = hi - lo >= two_pi
    return _outward(np.where(wide, -1.0, low), np.where(wide, 1.0, high))


def _tangent(x: Pair, cotangent: bool = False) -> Pair:
    lo, hi = x
    shift = 0.0 if cotangent else np.pi / 2
    # a pole at shift + k pi inside [lo, hi] (with a margin) makes the enclosure infinite
    k = np.ceil((lo - shift) / np.pi - 1e-12)
    pole = shift + k * np.pi <= hi + 1e-12 * (1 + np.abs(hi))
    f = (lambda t: 1.0 / np.tan(t)) if cotangent else np.tan
    a, b = f(lo), f(hi)
    low, high = (b, a) if cotangent else (a, b)
    return _outward(np.where(pole, -np.inf, low), np.where(pole, np.inf, high))


def _function(name: str, x: Pair) -> Pair:
    if name in ("exp", "sinh", "tanh", "atan"):
        return _monotone(_POINTWISE[name], x)
    if name == "log":
        with np.errstate(divide="ignore", invalid="ignore"):
            lo, hi = _monotone(np.log, (np.maximum(x[0], 0.0), x[1]))
        return np.where(x[0] <= 0, -np.inf, lo), np.where(x[1] <= 0, np.inf, hi)
    if name == "cosh":
        a, b = np.cosh(x[0]), np.cosh(x[1])
        zero_inside = (x[0] <= 0) & (x[1] >= 0)
        return _outward(np.where(zero_inside, 1.0, np.minimum(a, b)), np.maximum(a, b))
    if name == "Abs":
        return _absolute(x)
    if name == "sin":
        return _periodic(np.sin, x, np.pi / 2)
    if name == "cos":
        return _periodic(np.cos, x, 0.0)
    if name == "tan":
        return _tangent(x)
    if name == "cot":
        return _tangent(x, cotangent=True)
    raise KeyError(name)


def _absolute(x: Pair) -> Pair:
    lo, hi = x
    inside = (lo <= 0) & (hi >= 0)
    low = np.where(inside, 0.0, np.minimum(np.abs(lo), np.abs(hi)))
    return _outward(low, np.maximum(np.abs(lo), np.abs(hi)))


def _power(base: Pair, exponent: sympy.Expr) -> Pair:
    if exponent.is_Integer:
        return _integer_power(base, int(exponent))
    if exponent.is_number:
        # x**r for a non-integer r: defined for x >= 0, monotone there
        r = float(sympy.N(exponent, 17))
        lo, hi = base
        negative = lo < 0
        with np.errstate(all="ignore"):
            a, b = np.power(np.maximum(lo, 0.0), r), np.power(np.maximum(hi, 0.0), r)
        low, high = (a, b) if r > 0 else (b, a)
        return _outward(np.where(negative, -np.inf, low), np.where(negative, np.inf, high))
    raise _unknown(exponent)


def enclose(expr: sympy.Basic, lo: np.ndarray, hi: np.ndarray) -> Pair:
    r"""Bound ``expr`` (in ``z`` only) on each interval ``[lo[i], hi[i]]``.

    Returns arrays ``(low, high)`` with :math:`\text{low}_i \le f(z) \le \text{high}_i`
    for every :math:`z \in [l_i, h_i]` (infinite where the expression has a pole there).

    Raises
    ------
    ExpressionError
        As :func:`evaluate`, for an operation outside the grammar.
    """
    cells = (np.asarray(lo, dtype=float), np.asarray(hi, dtype=float))
    memo: dict[sympy.Basic, Pair] = {}

    def value(node: sympy.Basic) -> Pair:
        if node in memo:
            return memo[node]
        if node == Z:
            result = cells
        elif node.is_number:
            c = float(sympy.N(node, 17))
            result = _outward(np.full_like(cells[0], c), np.full_like(cells[0], c))
        elif node.is_Add:
            result = value(node.args[0])
            for a in node.args[1:]:
                other = value(a)
                result = _outward(result[0] + other[0], result[1] + other[1])
        elif node.is_Mul:
            result = value(node.args[0])
            for a in node.args[1:]:
                result = _mul(result, value(a))
        elif node.is_Pow:
            if node.base.is_number and not node.exp.is_number:  # c**f(z) = exp(f log c)
                result = value(sympy.exp(node.exp * sympy.log(node.base)))
            else:
                result = _power(value(node.base), node.exp)
        elif isinstance(node, sympy.Function) and node.func.__name__ in _POINTWISE:
            result = _function(node.func.__name__, value(node.args[0]))
        else:
            raise _unknown(node)
        memo[node] = result
        return result

    with np.errstate(all="ignore"):
        low, high = value(expr)
    shape = cells[0].shape
    return np.broadcast_to(low, shape).copy(), np.broadcast_to(high, shape).copy()
