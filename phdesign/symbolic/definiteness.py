r"""One checker for "a matrix function of z is definite on [a, b]".

:func:`check_definite` decides, for a symmetric matrix :math:`M(z)` whose entries are
expressions in :math:`z` and the parameters (substituted by their defaults), one of

.. math::

    M(z) \succ 0, \quad M(z) \succeq 0, \quad M(z) \prec 0, \quad M(z) \preceq 0
    \qquad \text{for every } z \in [a, b],

and returns one line saying how it was verified (it goes into ``BCPHS.checks``), or
raises :class:`~phdesign.core.errors.ModelError` naming the matrix and giving what was found.
The model uses it for :math:`\mathcal H(z) \succ 0` and :math:`P_0 + P_0^\top \preceq 0`.
With :math:`S = \pm M` the relation is :math:`S \succ 0` (or :math:`\succeq 0`):

*Constant* :math:`S`: sympy's exact test (``is_positive_definite``).

*Rational in z with rational coefficients*, within the budgets
``EXACT_DEFINITENESS_*`` of :mod:`phdesign.core.limits` (estimated before any work): every
denominator must be free of roots on :math:`[a, b]` (else :math:`M` is unbounded there);
multiplying row :math:`i` by the least common multiple :math:`\ell_i` of its denominators
(of constant sign on :math:`[a, b]`) turns each minor into a polynomial :math:`p`, and
:math:`S \succ 0` iff every leading principal minor has :math:`p(a) > 0` and no real root
in :math:`[a, b]` (real-root isolation, exact). :math:`S \succeq 0` iff every principal
minor is :math:`\ge 0`: no factor of odd multiplicity has a root inside :math:`(a, b)`,
and :math:`p > 0` at a point where it does not vanish.

*Otherwise* (transcendental entries, algebraic coefficients, or over budget, which the
returned line says): the smallest eigenvalue on a grid, then a proof on every cell
between its points by interval bounds (Weyl's inequality and Gershgorin's discs), for
:math:`\succeq 0` to a tolerance :math:`\tau` that counts as 0
(:mod:`phdesign.symbolic.grid_proof`).  A cell that cannot be closed is refused with its
location, never accepted on the strength of samples.

Examples
--------
>>> import sympy
>>> from phdesign.symbolic.expressions import Z
>>> check_definite(sympy.Matrix([[1 + Z**2]]), "H", (0, 1))
'H > 0: exact on [a, b] at the parameter defaults (leading principal minors)'
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from typing import Any

import sympy
from sympy.polys.matrices import DomainMatrix

from phdesign.core.errors import ModelError
from phdesign.core.limits import (
    EXACT_DEFINITENESS_BITS,
    EXACT_DEFINITENESS_DEGREE,
    EXACT_DEFINITENESS_SIZE,
)
from phdesign.symbolic.expressions import Z, exact_matrix, exact_number
from phdesign.symbolic.grid_proof import Question, on_grid
from phdesign.symbolic.parser import brief

__all__ = ["check_definite"]

_KINDS = {
    (1, True): ("positive definite", ">"),
    (1, False): ("positive semidefinite", ">="),
    (-1, True): ("negative definite", "<"),
    (-1, False): ("negative semidefinite", "<="),
}


def check_definite(
    matrix: sympy.MatrixBase,
    name: str,
    interval: Sequence[Any],
    defaults: Mapping[sympy.Symbol, sympy.Expr] | None = None,
    *,
    sign: int = 1,
    strict: bool = True,
) -> str:
    r"""Check that ``sign * matrix`` is positive (semi)definite on ``interval``.

    The one definiteness checker of the model: :math:`\mathcal H \succ 0`,
    :math:`P_0 + P_0^\top \preceq 0` and a feedback's :math:`K + K^\top \succeq 0`.

    Parameters
    ----------
    matrix : sympy matrix
        Symmetric, entries in :math:`z` and the parameters.
    name : str
        The matrix as the user knows it (``"H"``, ``"P0 + P0^T"``).
    interval : (a, b)
        Exact endpoints.
    defaults : mapping, optional
        Parameter values substituted before the check.
    sign : {1, -1}
        ``1`` for :math:`\succ 0` / :math:`\succeq 0`, ``-1`` for :math:`\prec 0` /
        :math:`\preceq 0`.
    strict : bool
        Definite (``True``) or semidefinite (``False``).

    Returns
    -------
    str
        ``"<name> <relation> 0: <how>"``.

    Raises
    ------
    ModelError
        If the condition fails, with the eigenvalues, minor or point that shows it.
    """
    if (sign, bool(strict)) not in _KINDS:
        raise ValueError(f"sign must be 1 or -1; found {sign!r}")
    kind, relation = _KINDS[sign, bool(strict)]
    if isinstance(interval, str) or not isinstance(interval, Sequence) or len(interval) != 2:
        raise ModelError(f"{name}: the interval must be a pair (a, b); found {interval!r}")
    a, b = (exact_number(p, "interval endpoint") for p in interval)
    if not a < b:
        raise ModelError(f"{name}: the interval must have a < b; found [{a}, {b}]")
    if defaults is not None and not isinstance(defaults, Mapping):
        raise ModelError(f"{name}: defaults must map parameters to values; found {defaults!r}")
    check = _Check(name, kind, sign, bool(strict), a, b)
    M = exact_matrix(matrix, name, symbols=True)
    if M.rows != M.cols:
        raise ModelError(f"{name} must be square; found {M.rows} x {M.cols}")
    at = " at the parameter defaults" if M.free_symbols - {Z} else ""
    M = M.xreplace(dict(defaults or {}))
    left = M.free_symbols - {Z}
    if left:
        raise ModelError(
            f"{name} holds symbols {', '.join(sorted(map(str, left)))} without a value"
        )
    return f"{name} {relation} 0: " + check.run(M, at)


class _Check(Question):
    """A definiteness question with its two paths: exact (here) and on a grid."""

    # ------------------------------------------------------------------ dispatch
    def run(self, M: sympy.ImmutableMatrix, at: str) -> str:
        S = M if self.sign == 1 else -M
        if not M.has(Z):
            return self.constant(M, S, at)
        exact, reason = self.exactly(M, S)
        if exact is not None:
            return exact
        how = on_grid(self, S)
        return how if reason is None else f"{how}; exact check skipped: {reason}"

    def constant(self, M: sympy.MatrixBase, S: sympy.MatrixBase, at: str) -> str:
        decided = S.is_positive_definite if self.strict else S.is_positive_semidefinite
        how = f"exact{at}"
        if decided:
            return how
        if decided is None:  # sympy cannot decide these constants exactly: evaluate them
            return on_grid(self, S)
        raise ModelError(
            f"{self.name} must be {self.kind} ({how}); found eigenvalues {_eigenvalues(M)}"
            f"{_failing_minor(S, self.strict)}"
        )

    # ------------------------------------------------------------------ exact path
    def exactly(self, M: sympy.MatrixBase, S: sympy.MatrixBase) -> tuple[str | None, str | None]:
        """Decide with minors and real roots; ``(None, reason)`` when out of reach."""
        n = S.rows
        if n > EXACT_DEFINITENESS_SIZE:
            return None, f"size {n} > {EXACT_DEFINITENESS_SIZE} (EXACT_DEFINITENESS_SIZE)"
        fractions = [[_fraction(S[i, j]) for j in range(n)] for i in range(n)]
        if any(f is None for row in fractions for f in row):
            return None, None  # not rational in z with rational coefficients: numeric
        degree_estimate, bits_estimate = 0, 0
        scaled_rows = []
        for i in range(n):
            row = [f for f in fractions[i] if f is not None]
            for j, (p, q) in enumerate(row):
                if max(p.degree(), q.degree()) > EXACT_DEFINITENESS_DEGREE:
                    return None, (
                        f"{self.name}[{i + 1},{j + 1}] has degree "
                        f"{max(p.degree(), q.degree())} > {EXACT_DEFINITENESS_DEGREE} "
                        "(EXACT_DEFINITENESS_DEGREE)"
                    )
            lcm = sympy.Poly(1, Z, domain="QQ")
            for _, q in row:
                lcm = lcm.lcm(q)
            scaled = [p * lcm.exquo(q) for p, q in row]
            degree_estimate += max(max(s.degree(), 0) for s in scaled)
            bits_estimate += max(_bits(s) for s in scaled) + 1
            if degree_estimate > EXACT_DEFINITENESS_DEGREE:
                return None, (
                    f"its minors may reach degree {degree_estimate} > "
                    f"{EXACT_DEFINITENESS_DEGREE} (EXACT_DEFINITENESS_DEGREE)"
                )
            if bits_estimate > EXACT_DEFINITENESS_BITS:
                return None, (
                    f"its minors may reach {bits_estimate}-bit coefficients > "
                    f"{EXACT_DEFINITENESS_BITS} (EXACT_DEFINITENESS_BITS)"
                )
            scaled_rows.append((lcm, scaled))
        for i in range(n):
            for j, (_, q) in enumerate(fractions[i]):  # type: ignore[misc]
                if q.degree() > 0 and self.roots_in(q, closed=True):
                    raise ModelError(
                        f"{self.name} must be bounded on {self.where}; its entry "
                        f"{self.name}[{i + 1},{j + 1}] = {_brief(M[i, j])} has a pole there "
                        "(parameter defaults)"
                    )
        signs = [_sign_at(lcm, self.a) for lcm, _ in scaled_rows]
        subsets = (
            [tuple(range(k)) for k in range(1, n + 1)]
            if self.strict
            else [c for k in range(1, n + 1) for c in itertools.combinations(range(n), k)]
        )
        for rows in subsets:
            det = _determinant([[scaled_rows[i][1][j] for j in rows] for i in rows])
            sign = math.prod(signs[i] for i in rows)
            ok = self.positive(det * sign) if self.strict else self.nonnegative(det * sign)
            if not ok:
                scale = sympy.Poly(1, Z, domain="QQ")
                for i in rows:
                    scale = scale * scaled_rows[i][0]
                self.fail_minor(rows, det * sign, scale * sign)
        which = "leading principal minors" if self.strict else "principal minors"
        return f"exact on [a, b] at the parameter defaults ({which})", None

    def roots_in(self, p: sympy.Poly, closed: bool) -> bool:
        """Whether ``p`` has a real root in [a, b] (``closed``) or in (a, b)."""
        if p.is_zero:
            return True
        if p.degree() == 0:
            return False
        square_free = p.sqf_part()
        count = len(square_free.intervals(inf=self.a, sup=self.b))
        at_ends = int(square_free.eval(self.a) == 0) + int(square_free.eval(self.b) == 0)
        if closed:
            return count > 0 or at_ends > 0
        return count - at_ends > 0

    def positive(self, p: sympy.Poly) -> bool:
        return bool(p.eval(self.a) > 0) and not self.roots_in(p, closed=True)

    def nonnegative(self, p: sympy.Poly) -> bool:
        if p.is_zero:
            return True
        _, factors = p.sqf_list()
        if any(m % 2 == 1 and self.roots_in(f, closed=False) for f, m in factors):
            return False
        for k in range(1, 64):  # a point of (a, b) where p does not vanish
            c = self.a + (self.b - self.a) * sympy.Rational(k, 65)
            value = p.eval(c)
            if value != 0:
                return bool(value > 0)
        return False  # unreachable: p has at most its degree (<= the budget) roots

    def fail_minor(self, rows: tuple[int, ...], p: sympy.Poly, denominator: sympy.Poly) -> None:
        minor = sympy.cancel(p.as_expr() / denominator.as_expr())
        of = "" if self.sign == 1 else f" of -({self.name})"
        label = "leading principal minor" if self.strict else "principal minor"
        index = len(rows) if self.strict else "{" + ", ".join(str(i + 1) for i in rows) + "}"
        raise ModelError(
            f"{self.name} must be {self.kind} on {self.where}; found {label} {index}{of} = "
            f"{_brief(minor)} with minimum {_minimum(minor, self.a, self.b)} "
            "(parameter defaults)"
        )


# ---------------------------------------------------------------------- helpers
def _fraction(entry: sympy.Expr) -> tuple[sympy.Poly, sympy.Poly] | None:
    """``(p, q)`` with entry = p/q, polynomials in z over the rationals, or ``None``."""
    if not entry.is_rational_function(Z):
        return None
    p, q = sympy.fraction(sympy.cancel(sympy.together(entry)))
    try:
        return sympy.Poly(p, Z, domain="QQ"), sympy.Poly(q, Z, domain="QQ")
    except (sympy.PolynomialError, sympy.CoercionFailed):
        return None  # algebraic or transcendental coefficients


def _bits(p: sympy.Poly) -> int:
    if p.is_zero:
        return 0
    clear = p.clear_denoms()[1]
    largest = max(abs(int(c)).bit_length() for c in clear.coeffs())
    return largest + int(p.degree() + 1).bit_length()


def _determinant(rows: list[list[sympy.Poly]]) -> sympy.Poly:
    """Exact determinant of a small matrix of polynomials (fraction-free, over QQ[z])."""
    k = len(rows)
    ring = sympy.QQ[Z]
    dm = DomainMatrix([[ring.from_sympy(p.as_expr()) for p in row] for row in rows], (k, k), ring)
    return sympy.Poly(ring.to_sympy(dm.det()), Z, domain="QQ")


def _sign_at(p: sympy.Poly, point: sympy.Expr) -> int:
    return 1 if p.eval(point) > 0 else -1


def _minimum(minor: sympy.Expr, a: sympy.Expr, b: sympy.Expr) -> str:
    """Return the minimum on [a, b] and where it is attained (for the message).

    Exact (endpoints and the derivative's real roots) for small degrees, else sampled.
    """
    numerator, denominator = sympy.fraction(sympy.cancel(minor))
    if sympy.degree(numerator, Z) + sympy.degree(denominator, Z) <= 8:
        slope = sympy.fraction(sympy.cancel(sympy.diff(minor, Z)))[0]
        points = [a, b]
        if slope.has(Z):
            points += [r for r in sympy.Poly(slope, Z).real_roots() if a < r < b]
        value, point = min(
            ((sympy.cancel(minor.subs(Z, c)), c) for c in points),
            key=lambda item: float(sympy.N(item[0], 30)),
        )
        shown = value if value.is_Rational else sympy.N(value, 6)
        where = point if point.is_Rational else sympy.N(point, 6)
        return f"{shown} at z = {where}"
    samples = [a + (b - a) * sympy.Rational(k, 400) for k in range(401)]
    lowest = min(samples, key=lambda c: float(minor.subs(Z, c)))
    return f"about {float(minor.subs(Z, lowest)):.6g} at z = {float(lowest):g}"


def _failing_minor(S: sympy.MatrixBase, strict: bool) -> str:
    r"""Name the first principal minor of a constant ``S`` that refutes the relation.

    Sylvester's criterion: :math:`S \succ 0` iff every leading principal minor is
    :math:`> 0`; :math:`S \succeq 0` iff every principal minor is :math:`\ge 0`.
    """
    n = S.rows
    if strict:
        candidates: Sequence[tuple[int, ...]] = [tuple(range(k)) for k in range(1, n + 1)]
    else:
        candidates = [c for k in range(1, n + 1) for c in itertools.combinations(range(n), k)]
    for rows in candidates:
        minor = sympy.expand(S.extract(list(rows), list(rows)).det())
        if (minor <= 0) if strict else (minor < 0):
            kind = "leading principal minor" if strict else "principal minor"
            where = ", ".join(str(i + 1) for i in rows)
            return f"; its {kind} on rows and columns {{{where}}} is {_brief(minor)}"
    return ""


def _eigenvalues(M: sympy.MatrixBase) -> str:
    import numpy as np

    values = np.linalg.eigvalsh(np.array(M.evalf(17).tolist(), dtype=float))
    return "[" + ", ".join(f"{v:.6g}" for v in values) + "]"


def _brief(value: object) -> str:
    return brief(value, 80)
