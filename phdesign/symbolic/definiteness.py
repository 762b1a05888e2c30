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
returned line says): for :math:`\succ 0`, the smallest eigenvalue on a grid of
:data:`POSITIVITY_GRID_POINTS` points, then a proof on every cell :math:`[z_i, z_{i+1}]`:

.. math::

    \lambda_{\min}(S(z)) \ge \lambda_{\min}(S(m)) - \|R\|_F, \qquad
    R_{jk} = \max_{z \in [z_i, z_{i+1}]} |S_{jk}(z) - S_{jk}(m)|,

(Weyl's inequality, :math:`m` the midpoint, :math:`R` bounded by interval arithmetic,
:mod:`phdesign.symbolic.evaluation`); a cell that this does not prove positive is halved,
so a sharp dip between grid points is found (and refused with its location) instead of
being stepped over.  Gershgorin's discs of the enclosed entries,
:math:`\lambda_{\min} \ge \min_i (\underline{S_{ii}} - \sum_{j \ne i} \max |S_{ij}|)`, give
a second bound, and each cell keeps the better of the two.

For :math:`\succeq 0` the same proof runs with the threshold :math:`-\tau` instead of 0,
:math:`\tau = 10^{-12}` times the matrix's scale: floating point cannot prove an
eigenvalue that touches 0 non-negative, so what is proved is
:math:`\lambda_{\min}(S(z)) \ge -\tau` for every :math:`z \in [a, b]` (cells near a
touching point shrink until their bound meets :math:`-\tau`).  A constant kernel of
:math:`S` (a damping on some components only, or on a fixed combination of them) is set
aside first, exactly (``_without_constant_kernel``): it adds the eigenvalue 0 and
nothing else, and would otherwise keep every bound below 0.  A cell the budget cannot
close is refused with its location, never accepted on the strength of samples; so is
any sample below :math:`-\tau`, which is how a narrow violation between grid points (a
bump of width :math:`10^{-5}`) is found.

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

from phdesign.core.errors import ExpressionError, ModelError
from phdesign.core.limits import (
    EXACT_DEFINITENESS_BITS,
    EXACT_DEFINITENESS_DEGREE,
    EXACT_DEFINITENESS_SIZE,
)
from phdesign.symbolic.expressions import Z, exact_matrix, exact_number
from phdesign.symbolic.parser import brief

__all__ = ["POSITIVITY_GRID_POINTS", "check_definite"]

#: Points of the first grid of the numeric check (cells between them are then proved).
POSITIVITY_GRID_POINTS = 2001
#: Halvings of a cell the numeric proof may make, and cells it may examine in all.
_MAX_HALVINGS = 40
_MAX_CELLS = 400_000
#: Relative size under which an eigenvalue counts as zero in the semidefinite check.
_SEMIDEFINITE_TOLERANCE = 1e-12

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
    check = _Check(name, kind, sign, bool(strict), (a, b))
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


class _Check:
    """One definiteness question: the matrix's name, the relation and the interval."""

    def __init__(self, name: str, kind: str, sign: int, strict: bool, interval: Any) -> None:
        self.name, self.kind, self.sign, self.strict = name, kind, sign, strict
        self.a, self.b = interval
        self.where = f"[{self.a}, {self.b}]"

    # ------------------------------------------------------------------ dispatch
    def run(self, M: sympy.ImmutableMatrix, at: str) -> str:
        S = M if self.sign == 1 else -M
        if not M.has(Z):
            return self.constant(M, S, at)
        exact, reason = self.exactly(M, S)
        if exact is not None:
            return exact
        how = self.numerically(M, S)
        return how if reason is None else f"{how}; exact check skipped: {reason}"

    def constant(self, M: sympy.MatrixBase, S: sympy.MatrixBase, at: str) -> str:
        decided = S.is_positive_definite if self.strict else S.is_positive_semidefinite
        how = f"exact{at}"
        if decided:
            return how
        if decided is None:  # sympy cannot decide these constants exactly: evaluate them
            return self.numerically(M, S)
        raise ModelError(
            f"{self.name} must be {self.kind} ({how}); found eigenvalues {_eigenvalues(M)}"
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

    # ------------------------------------------------------------------ numeric path
    def numerically(self, M: sympy.MatrixBase, S: sympy.MatrixBase) -> str:
        """Decide on a grid, then prove every cell between its points by interval bounds.

        Strict: every cell must have a bound > 0.  Semidefinite: rows and columns that
        are identically zero are set aside first (a zero row of a symmetric matrix adds
        the eigenvalue 0 and nothing else), and every cell of the rest must have a bound
        of at least ``-tolerance`` (:data:`_SEMIDEFINITE_TOLERANCE` times the matrix's
        scale), the eigenvalue that "counts as 0": where an eigenvalue touches 0 the cells
        shrink until the bound meets it.  A cell that cannot be closed within the budget
        is refused, never accepted on the strength of its samples.
        """
        import numpy as np  # the numeric check only (the symbolic layer stays light)

        from phdesign.symbolic.evaluation import enclose, evaluate

        a, b = float(self.a), float(self.b)
        kernel: sympy.MatrixBase | None = None
        if not self.strict:
            kernel, S = _without_constant_kernel(S, a, b, self.name)
            if S.rows == 0:
                return "identically zero on [a, b]"
        n = S.rows
        entries = [(i, j) for i in range(n) for j in range(i, n)]

        def values(z: np.ndarray) -> np.ndarray:
            out = np.empty((z.size, n, n))
            for i, j in entries:
                out[:, i, j] = out[:, j, i] = _evaluate(evaluate, S[i, j], z, self.name)
            return out

        def smallest(z: np.ndarray) -> np.ndarray:
            V = values(z)
            if not np.all(np.isfinite(V)):
                bad = z[~np.all(np.isfinite(V), axis=(1, 2))][0]
                raise ModelError(
                    f"{self.name} must be bounded on {self.where}; found a non-finite entry "
                    f"at z = {bad:g}"
                )
            return np.linalg.eigvalsh(V)[:, 0]

        grid = np.linspace(a, b, POSITIVITY_GRID_POINTS)
        lam = smallest(grid)
        scale = max(1.0, float(np.max(np.abs(values(grid)))))
        tolerance = 0.0 if self.strict else _SEMIDEFINITE_TOLERANCE * scale

        def violated(value: float) -> bool:
            return value <= 0 if self.strict else value < -tolerance

        worst = int(np.argmin(lam))
        if violated(lam[worst]):
            self.fail_point(lam[worst], grid[worst])
        lo, hi = grid[:-1], grid[1:]
        examined, lowest = 0, (float(lam[worst]), float(grid[worst]))
        for _ in range(_MAX_HALVINGS):
            mid = 0.5 * (lo + hi)
            lam_mid = smallest(mid)
            k = int(np.argmin(lam_mid))
            if lam_mid[k] < lowest[0]:
                lowest = (float(lam_mid[k]), float(mid[k]))
            if violated(lam_mid[k]):
                self.fail_point(lam_mid[k], mid[k])
            radius = np.zeros((lo.size, n, n))
            reach = np.zeros((lo.size, n, n))  # |S_ij| <= reach_ij off the diagonal
            floor = np.zeros((lo.size, n))  # S_ii >= floor_i
            centre = values(mid)
            for i, j in entries:
                low, high = enclose(S[i, j], lo, hi)
                r = np.maximum(high - centre[:, i, j], centre[:, i, j] - low)
                radius[:, i, j] = radius[:, j, i] = r
                if i == j:
                    floor[:, i] = low
                else:
                    reach[:, i, j] = reach[:, j, i] = np.maximum(np.abs(low), np.abs(high))
            # two lower bounds of the smallest eigenvalue on the cell, the better one kept:
            # Weyl about the midpoint, and Gershgorin's discs of the interval matrix (sharp
            # where an entry touches 0 while the others stay away: diag(sin(2 pi z)^2, e^z))
            # each less round-off in its own magnitudes (the cell's, the row's): one from the
            # largest entry left diag(exp(30 z), 1) unproved (1e-13 e³⁰ > 1 = λ_min)
            cell = np.max(np.abs(centre) + radius, axis=(1, 2))
            weyl = lam_mid - np.sqrt(np.sum(radius**2, axis=(1, 2))) - _allowance(cell, n)
            row = np.abs(floor) + np.sum(reach, axis=2)
            gershgorin = np.min(floor - np.sum(reach, axis=2) - _allowance(row, n), axis=1)
            bound = np.maximum(weyl, gershgorin)
            open_cells = ~(bound > 0) if self.strict else ~(bound >= -tolerance)
            examined += lo.size
            if not np.any(open_cells):
                return self.proved(lowest, tolerance, kernel)
            lo, hi, mid = lo[open_cells], hi[open_cells], mid[open_cells]
            if examined + 2 * lo.size > _MAX_CELLS:
                break
            lo, hi = np.concatenate([lo, mid]), np.concatenate([mid, hi])
        which, shown = self.extreme(lowest[0])
        if self.strict:
            raise ModelError(
                f"{self.name} must be {self.kind} on {self.where}; it could not be proved "
                f"near z = {lo[0]:g} ({which} eigenvalue found {shown:.6g} at z = "
                f"{lowest[1]:g}; interval bounds of the entries do not separate it from 0) "
                "(parameter defaults)"
            )
        raise ModelError(
            f"{self.name} must be {self.kind} on {self.where}; it could not be decided near "
            f"z = {lo[0]:g} within the budget of {_MAX_CELLS} cells: an eigenvalue stays "
            f"within {tolerance:.3g} of 0 there ({which} eigenvalue sampled {shown:.6g} at "
            f"z = {lowest[1]:g}) and interval bounds of the entries do not bound it away "
            "from the wrong side; write the entries as rational functions of z (decided "
            "exactly) (parameter defaults)"
        )

    def extreme(self, value: float) -> tuple[str, float]:
        """Name and value of the eigenvalue of M that ``value`` (of S = ±M) stands for."""
        return ("smallest", value + 0.0) if self.sign == 1 else ("largest", 0.0 - value)

    def proved(
        self, lowest: tuple[float, float], tolerance: float, kernel: sympy.MatrixBase | None
    ) -> str:
        """Return the line that says what the interval proof established."""
        which, shown = self.extreme(lowest[0])
        how = (
            f"on a grid of {POSITIVITY_GRID_POINTS} points at the parameter defaults, proved "
            "between the points by interval bounds"
        )
        if self.strict:
            return f"{how} ({which} eigenvalue {shown:.6g} at z = {lowest[1]:g})"
        aside = ""
        if kernel is not None:
            vectors = ", ".join(
                "(" + ", ".join(str(x) for x in kernel[:, j]) + ")" for j in range(kernel.cols)
            )
            aside = f"; its constant kernel {vectors} set aside"
        return (
            f"{how} to {tolerance:.3g} (eigenvalues within {tolerance:.3g} of 0 count as 0; "
            f"{which} eigenvalue {shown:.6g} at z = {lowest[1]:g}{aside})"
        )

    def fail_point(self, value: float, z: float) -> None:
        which, shown = self.extreme(value)
        raise ModelError(
            f"{self.name} must be {self.kind} on {self.where}; found "
            f"{which} eigenvalue {shown:.6g} at z = {z:g} (parameter defaults)"
        )


# ---------------------------------------------------------------------- helpers
def _allowance(magnitude: Any, n: int) -> Any:
    """Round-off of a bound from outward-rounded entries of this magnitude (relative)."""
    import numpy as np

    return 1e-13 * n * np.maximum(magnitude, 1e-300)  # the floor: entries that underflow


def _without_constant_kernel(
    S: sympy.MatrixBase, a: float, b: float, name: str
) -> tuple[sympy.MatrixBase | None, sympy.MatrixBase]:
    r"""Return ``(N, B^T S B)``: the constant kernel of S set aside, exactly; or ``(None, S)``.

    If :math:`S(z) N = 0` for every z with a constant N of full column rank, then in the
    basis :math:`(B\ N)`, B a basis of :math:`N^\perp`, :math:`S` is
    :math:`\mathrm{diag}(B^\top S B, 0)` (congruence keeps the inertia), so
    :math:`S \succeq 0` iff :math:`B^\top S B \succeq 0`.  Without this, a kernel that
    persists (a damping on some components only, or on a combination of them) keeps the
    smallest eigenvalue at 0 on every cell while the entries vary, and no interval bound
    could close a cell.  The candidate N is read from samples (their common null space),
    rounded to rationals and then *verified exactly*, :math:`S N = 0` symbolically; a
    candidate that fails the verification is not used.
    """
    import numpy as np

    from phdesign.symbolic.evaluation import evaluate

    n = S.rows
    points = a + (b - a) * np.array([0.0, 0.1234, 0.3571, 0.5, 0.7071, 0.9123, 1.0])
    samples = np.empty((points.size, n, n))
    for i in range(n):
        for j in range(n):
            samples[:, i, j] = _evaluate(evaluate, S[i, j], points, name)
    if not np.all(np.isfinite(samples)):
        return None, S  # the grid reports the unbounded entry with its point
    stacked = samples.reshape(-1, n)
    _, sigma, vt = np.linalg.svd(stacked)
    rank = int(np.sum(sigma > 1e-9 * max(1.0, float(sigma[0]) if sigma.size else 1.0)))
    if rank == n:
        return None, S
    # a rational basis of the numeric null space: reduce it to echelon form first, so that
    # a kernel such as (1, -1) comes out with small integer entries
    null = sympy.Matrix(vt[rank:]).applyfunc(lambda x: sympy.nsimplify(x, tolerance=1e-12))
    try:
        echelon = null.rref(pivots=False)
        rows = echelon.applyfunc(lambda x: sympy.nsimplify(x, rational=True, tolerance=1e-9))
    except (TypeError, ValueError, ZeroDivisionError):  # pragma: no cover - defensive
        return None, S
    N = rows.T
    # distributing products only: expanding exp(-c (z - m)**2) would overflow its factors
    if N.rank() != n - rank or any(sympy.expand_mul(x) != 0 for x in S * N):
        return None, S
    complement = N.T.nullspace()
    if not complement:
        return N, sympy.zeros(0, 0)
    B = sympy.Matrix.hstack(*complement)
    return N, B.T * S * B


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


def _eigenvalues(M: sympy.MatrixBase) -> str:
    import numpy as np

    values = np.linalg.eigvalsh(np.array(M.evalf(17).tolist(), dtype=float))
    return "[" + ", ".join(f"{v:.6g}" for v in values) + "]"


def _evaluate(evaluate: Any, entry: sympy.Expr, z: Any, name: str) -> Any:
    try:
        return evaluate(entry, z)
    except ExpressionError as error:
        raise ModelError(f"{name}: {error}") from None


def _brief(value: object) -> str:
    return brief(value, 80)
