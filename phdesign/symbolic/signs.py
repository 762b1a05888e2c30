r"""Definiteness of matrix functions on [a, b]: exact where possible, on a grid otherwise.

One checker, :func:`check_definite`, serves every sign condition of a model:
:math:`\mathcal H(z) \succ 0`, :math:`P_0(z) + P_0(z)^\top \preceq 0` and the feedback's
:math:`K + K^\top \succeq 0`.

* Numeric entries: Sylvester's criteria, exactly (leading principal minors > 0 for a
  definite matrix, *every* principal minor >= 0 for a semidefinite one).
* Entries rational in z: the same minors as rational functions on [a, b].  A minor
  :math:`p/q` with :math:`q \ne 0` on [a, b] has the sign of the polynomial :math:`pq`,
  which is constant between consecutive real roots; sympy isolates the roots exactly and
  one rational sample point per piece decides (:func:`polynomial_sign_ok`).  A failure
  names the minor, its minimum and a point attaining it.
* Other entries (``exp``, ``sin``, ...): the eigenvalues on a grid of
  :data:`POSITIVITY_GRID_POINTS` points.

Entries holding parameters are checked at the parameter defaults, and the returned text
says so.

Examples
--------
>>> from phdesign.symbolic.expressions import Z
>>> check_definite(sympy.Matrix([[-Z]]), "P0 + P0^T", (0, 1), {}, sign=-1, strict=False)
'P0 + P0^T <= 0: exact on [a, b] at the parameter defaults (principal minors)'
>>> polynomial_sign_ok((Z - sympy.Rational(1, 2))**2, 0, 1, strict=False)
True
>>> smallest_on_interval(Z**2 - Z, 0, 1)
(-1/4, 1/2)
"""

from __future__ import annotations

from collections.abc import Mapping
from itertools import combinations, pairwise
from typing import Any

import sympy

from phdesign.errors import ModelError
from phdesign.symbolic.expressions import Z

__all__ = [
    "POSITIVITY_GRID_POINTS",
    "check_definite",
    "polynomial_sign_ok",
    "rational_between",
    "smallest_on_interval",
]

#: Points of the grid on which a matrix function is checked when exact signs are out of reach.
POSITIVITY_GRID_POINTS = 2001


def _at_defaults(matrix: sympy.MatrixBase, defaults: Mapping[sympy.Symbol, sympy.Expr]) -> Any:
    return matrix.xreplace(dict(defaults))


#: The relation each (sign, strict) pair of :func:`_check_definite` asserts.
_RELATIONS = {
    (1, True): ("positive definite", "> 0"),
    (1, False): ("positive semidefinite", ">= 0"),
    (-1, True): ("negative definite", "< 0"),
    (-1, False): ("negative semidefinite", "<= 0"),
}


def check_definite(
    S: sympy.MatrixBase,
    name: str,
    interval: tuple[sympy.Expr, sympy.Expr],
    defaults: Mapping[sympy.Symbol, sympy.Expr],
    *,
    sign: int = 1,
    strict: bool = True,
) -> str:
    r"""Check :math:`\pm S(z) \succ 0` (``strict``) or :math:`\succeq 0` on [a, b].

    The one definiteness checker of the model: :math:`\mathcal H \succ 0`,
    :math:`P_0 + P_0^\top \preceq 0` and the feedback's :math:`K + K^\top \succeq 0`.
    Exact for numeric entries (Sylvester: leading principal minors > 0 for definite,
    every principal minor >= 0 for semidefinite), exact on [a, b] for entries rational
    in z (the minors' signs on the interval, decided from their real roots), on a grid of
    :data:`POSITIVITY_GRID_POINTS` points otherwise; at the parameter defaults when the
    entries hold parameters.  Returns how the check was made.
    """
    relation, symbol = _RELATIONS[sign, strict]
    how = "exact"
    if S.free_symbols - {Z}:
        S, how = _at_defaults(S, defaults), "exact at the parameter defaults"
    S = sympy.ImmutableMatrix(sign * S)
    if Z not in S.free_symbols:
        if not all(_sign_ok(minor, strict) for _, minor in _minors(S, strict)):
            eigenvalues = sympy.ImmutableMatrix(sign * S).eigenvals()
            raise ModelError(
                f"{name} must be {relation} ({how}); found eigenvalues "
                f"{sorted(eigenvalues, key=sympy.default_sort_key)}"
            )
        return f"{name} {symbol}: {how}"
    exact = _check_definite_exactly(S, name, relation, interval, sign, strict)
    if exact is not None:
        return f"{name} {symbol}: {exact}"
    return f"{name} {symbol}: " + _check_definite_on_grid(
        S, name, relation, interval, sign, strict
    )


def _minors(S: sympy.MatrixBase, strict: bool) -> list[tuple[tuple[int, ...], sympy.Expr]]:
    """Leading principal minors (strict) or every principal minor (semidefinite)."""
    n = S.shape[0]
    if strict:
        subsets = [tuple(range(k)) for k in range(1, n + 1)]
    else:
        subsets = [c for k in range(1, n + 1) for c in combinations(range(n), k)]
    return [(c, sympy.cancel(S.extract(list(c), list(c)).det())) for c in subsets]


def _sign_ok(value: sympy.Expr, strict: bool) -> bool:
    value = sympy.nsimplify(value) if value.is_Float else value
    decided = value.is_positive if strict else value.is_nonnegative
    if decided is None:  # an algebraic number sympy cannot order: 50 digits decide
        number = sympy.N(value, 50)
        return bool(number > 0) if strict else bool(number >= -(sympy.Float(10) ** -45))
    return bool(decided)


def _minor_label(subset: tuple[int, ...], strict: bool) -> str:
    if strict:
        return f"leading principal minor {len(subset)}"
    return f"principal minor {{{', '.join(str(i + 1) for i in subset)}}}"


def _check_definite_exactly(
    S: sympy.MatrixBase,
    name: str,
    relation: str,
    interval: tuple[sympy.Expr, sympy.Expr],
    sign: int,
    strict: bool,
) -> str | None:
    """Decide the sign of every minor on [a, b] exactly, for entries rational in z.

    Returns ``None`` when an entry is not rational in z (then the grid check runs).
    """
    minors = _minors(S, strict)
    if not all(m.is_rational_function(Z) for _, m in minors):
        return None
    a, b = interval
    domain = sympy.Interval(a, b)
    for subset, minor in minors:
        numerator, denominator = sympy.fraction(sympy.cancel(minor))
        if sympy.solveset(denominator, Z, domain) != sympy.EmptySet:
            raise ModelError(
                f"{name} must be bounded on [{a}, {b}]; its {_minor_label(subset, strict)} = "
                f"{minor} has a pole there (parameter defaults)"
            )
        worst, at = smallest_on_interval(minor, a, b)
        if not polynomial_sign_ok(numerator * denominator, a, b, strict):
            value = worst if worst.is_Rational else sympy.N(worst, 6)
            of = "" if sign > 0 else f" of -({name})"
            raise ModelError(
                f"{name} must be {relation} on [{a}, {b}]; found "
                f"{_minor_label(subset, strict)}{of} = {minor} "
                f"with minimum {value} at z = {at} (parameter defaults)"
            )
    kind = "leading principal minors" if strict else "principal minors"
    return f"exact on [a, b] at the parameter defaults ({kind})"


def _check_definite_on_grid(
    S: sympy.MatrixBase,
    name: str,
    relation: str,
    interval: tuple[sympy.Expr, sympy.Expr],
    sign: int,
    strict: bool,
) -> str:
    import numpy as np  # only for the grid check of a non-rational matrix function

    a, b = interval
    grid = np.linspace(float(a), float(b), POSITIVITY_GRID_POINTS)
    evaluate = sympy.lambdify(Z, S, modules="numpy")
    with np.errstate(all="ignore"):
        values = np.array([np.asarray(evaluate(z), dtype=float) for z in grid])
    if not np.all(np.isfinite(values)):
        bad = grid[~np.all(np.isfinite(values), axis=(1, 2))][0]
        raise ModelError(
            f"{name} must be bounded on [{a}, {b}]; found a non-finite entry at z = {bad:g}"
        )
    smallest = np.linalg.eigvalsh(0.5 * (values + values.transpose(0, 2, 1))).min(axis=1)
    worst = int(np.argmin(smallest))
    scale = max(1.0, float(np.max(np.abs(values))))
    failed = smallest[worst] <= 0 if strict else smallest[worst] < -1e-12 * scale
    word = "smallest" if sign > 0 else "largest"
    if failed:
        raise ModelError(
            f"{name} must be {relation} on [{a}, {b}]; found {word} eigenvalue "
            f"{sign * smallest[worst]:.6g} at z = {grid[worst]:g} (parameter defaults)"
        )
    return (
        f"on a grid of {POSITIVITY_GRID_POINTS} points at the parameter defaults "
        f"({word} eigenvalue {sign * smallest[worst]:.6g} at z = {grid[worst]:g})"
    )


def smallest_on_interval(
    f: sympy.Expr, a: sympy.Expr, b: sympy.Expr
) -> tuple[sympy.Expr, sympy.Expr]:
    """Minimum of a rational function on [a, b] and a point attaining it (for messages)."""
    a, b = sympy.sympify(a), sympy.sympify(b)
    points = [a, b]
    derivative_numerator = sympy.fraction(sympy.cancel(sympy.diff(f, Z)))[0]
    if derivative_numerator.has(Z):
        points += [r for r in sympy.Poly(derivative_numerator, Z).real_roots() if a < r < b]
    values = [(sympy.cancel(f.subs(Z, p)), p) for p in points]
    value, point = min(values, key=lambda item: float(sympy.N(item[0], 30)))
    shown = point if point.is_Rational else sympy.N(point, 6)
    return value, shown


def polynomial_sign_ok(p: sympy.Expr, a: sympy.Expr, b: sympy.Expr, strict: bool) -> bool:
    """Whether the polynomial ``p`` is > 0 (``strict``) or >= 0 on [a, b], exactly.

    Between consecutive real roots the sign is constant: test it at one rational point of
    each piece (the roots come isolated by rational intervals), and at the roots
    themselves for the strict test.
    """
    a, b = sympy.sympify(a), sympy.sympify(b)
    poly = sympy.Poly(p, Z)
    if poly.is_zero:
        return not strict
    roots = [r for r in poly.real_roots() if a <= r <= b]
    if strict and roots:
        return False
    cuts = sorted(set(roots), key=lambda r: sympy.N(r, 30))
    samples = [a, b]
    edges = [a, *cuts, b]
    for left, right in pairwise(edges):
        samples.append(rational_between(left, right))
    return all(poly.eval(x) > 0 if strict else poly.eval(x) >= 0 for x in samples)


def rational_between(left: sympy.Expr, right: sympy.Expr) -> sympy.Rational:
    """Return a rational number strictly between two real algebraic numbers (or at them)."""
    lo, hi = sympy.N(left, 40), sympy.N(right, 40)
    if lo == hi:
        return sympy.nsimplify(left) if left.is_Rational else sympy.Rational(str(lo))
    return sympy.Rational(str(sympy.N((lo + hi) / 2, 30)))
