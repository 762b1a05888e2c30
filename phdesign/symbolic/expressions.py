r"""Safe parsing of scalar expressions, and the exact numbers and zero tests phdesign uses.

Users write matrix entries (``"1/rho"``, ``"EI*(1 + z/10)"``) in :math:`z` and named
parameters.  The text is read by a small recursive-descent parser: user text is never
evaluated as Python (no :func:`eval`, no :func:`sympy.sympify` on raw text); the grammar
and its limits live in :mod:`phdesign.symbolic.parser`.  Numbers become exact
(:func:`exact_number`: ``0.2`` is :math:`1/5`), and :func:`canonical` and :func:`vanishes`
decide zero exactly.  Boundary-trace expressions (``"-e2(0)"``) are read on top of this, by
:mod:`phdesign.symbolic.traces`, and printed back by :mod:`phdesign.symbolic.printing`.

Examples
--------
>>> parse_scalar("1/rho + z**2", parameters=["rho"])
z**2 + 1/rho
>>> exact_number(0.2, "d")
1/5
"""

from __future__ import annotations

import fractions
import math
import numbers
import re
from collections.abc import Callable, Iterable, Sequence
from functools import lru_cache

import sympy

from phdesign.core.checks import not_bytes
from phdesign.core.errors import ExpressionError
from phdesign.core.limits import MAX_NUMBER_OPERATIONS
from phdesign.symbolic.parser import CONSTANTS, FUNCTIONS, brief, check_text, parse

__all__ = [
    "Z",
    "canonical",
    "check_parameter_name",
    "exact_matrix",
    "exact_number",
    "exactify",
    "name_resolver",
    "parameter_symbol",
    "parse_scalar",
    "vanishes",
]


#: The spatial variable of every model.
Z = sympy.Symbol("z", real=True)

#: Names a parameter may not take: they mean something else in expressions.
RESERVED_NAMES = frozenset({"z", "a", "b", *FUNCTIONS, *CONSTANTS})
_TRACE_NAME = re.compile(r"e\d+\Z")
_PARAMETER_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


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
    resolve = name_resolver(parameters, allow_z)
    try:
        return parse(text, resolve)
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


def name_resolver(parameters: Iterable[str], allow_z: bool) -> Callable[[str, str], sympy.Expr]:
    """Return the parser's name resolver for ``z`` and the named parameters.

    Any other name is an error that lists the known ones.

    Raises
    ------
    ExpressionError
        If ``parameters`` is not a list of names.
    """
    known_names = _names(parameters)

    def resolve(name: str, text: str) -> sympy.Expr:
        if name == "z":
            if not allow_z:
                raise ExpressionError(f"the spatial variable z is not allowed in {text!r}")
            return Z
        if name in known_names:
            return parameter_symbol(name)
        known = sorted(known_names)
        raise ExpressionError(
            f"unknown symbol {name!r} in {text!r}; "
            f"known parameters: {', '.join(known) if known else 'none'}"
        )

    return resolve
