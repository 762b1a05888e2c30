r"""The numeric path of the definiteness check: a grid, then a proof on every cell.

:func:`~phdesign.symbolic.definiteness.check_definite` comes here when the exact path
(minors and real roots) does not apply: transcendental entries, algebraic coefficients,
or a matrix over the exact budgets.  With :math:`S = \pm M`, for :math:`S \succ 0` the
smallest eigenvalue is sampled on a grid of :data:`POSITIVITY_GRID_POINTS` points, then
every cell :math:`[z_i, z_{i+1}]` is proved:

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
aside first, exactly (:func:`_without_constant_kernel`): it adds the eigenvalue 0 and
nothing else, and would otherwise keep every bound below 0.  A cell the budget cannot
close is refused with its location, never accepted on the strength of samples; so is
any sample below :math:`-\tau`, which is how a narrow violation between grid points (a
bump of width :math:`10^{-5}`) is found.

numpy and :mod:`phdesign.symbolic.evaluation` (which imports it) are imported when this
path runs, so that building a model whose conditions are decided exactly does not load
numpy.

Examples
--------
>>> import sympy
>>> from phdesign.symbolic.expressions import Z
>>> question = Question("H", "positive definite", 1, True, sympy.Integer(0), sympy.Integer(1))
>>> on_grid(question, sympy.Matrix([[sympy.exp(Z)]]))
'on a grid of 2001 points at the parameter defaults, proved between the points by interval
bounds (smallest eigenvalue 1 at z = 0)'
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NoReturn

import sympy

from phdesign.core.errors import ExpressionError, ModelError

if TYPE_CHECKING:  # pragma: no cover - typing only
    import numpy as np

__all__ = ["POSITIVITY_GRID_POINTS", "Question", "on_grid"]

#: Points of the first grid of the numeric check (cells between them are then proved).
POSITIVITY_GRID_POINTS = 2001
#: Halvings of a cell the numeric proof may make, and cells it may examine in all.
_MAX_HALVINGS = 40
_MAX_CELLS = 400_000
#: Relative size under which an eigenvalue counts as zero in the semidefinite check.
_SEMIDEFINITE_TOLERANCE = 1e-12


@dataclass(frozen=True)
class Question:
    """One definiteness question: the matrix's name, the relation and the interval.

    ``sign * M`` is to be positive definite (``strict``) or semidefinite on ``[a, b]``;
    ``kind`` names the relation of ``M`` itself in messages.
    """

    name: str
    kind: str
    sign: int
    strict: bool
    a: sympy.Expr
    b: sympy.Expr

    @property
    def where(self) -> str:
        """The interval as messages print it."""
        return f"[{self.a}, {self.b}]"

    def extreme(self, value: float) -> tuple[str, float]:
        """Name and value of the eigenvalue of M that ``value`` (of S = ±M) stands for."""
        return ("smallest", value + 0.0) if self.sign == 1 else ("largest", 0.0 - value)

    def fail_point(self, value: float, z: float) -> NoReturn:
        """Refuse the matrix, giving the eigenvalue that violates the relation at ``z``."""
        which, shown = self.extreme(value)
        raise ModelError(
            f"{self.name} must be {self.kind} on {self.where}; found "
            f"{which} eigenvalue {shown:.6g} at z = {z:g} (parameter defaults)"
        )

    def violated(self, value: float, tolerance: float) -> bool:
        """Whether a smallest eigenvalue of S violates the relation (module docstring)."""
        return value <= 0 if self.strict else value < -tolerance


class _Samples:
    """The entries of S (upper triangle) evaluated at points, and its smallest eigenvalue."""

    def __init__(self, S: sympy.MatrixBase, name: str, where: str) -> None:
        from phdesign.symbolic.evaluation import evaluate  # numpy: the numeric path only

        self.S, self.name, self.where, self._evaluate = S, name, where, evaluate
        self.n = S.rows
        self.entries = [(i, j) for i in range(self.n) for j in range(i, self.n)]

    def values(self, z: np.ndarray) -> np.ndarray:
        import numpy as np

        out = np.empty((z.size, self.n, self.n))
        for i, j in self.entries:
            out[:, i, j] = out[:, j, i] = _evaluate(self._evaluate, self.S[i, j], z, self.name)
        return out

    def smallest(self, z: np.ndarray) -> np.ndarray:
        import numpy as np

        V = self.values(z)
        if not np.all(np.isfinite(V)):
            bad = z[~np.all(np.isfinite(V), axis=(1, 2))][0]
            raise ModelError(
                f"{self.name} must be bounded on {self.where}; found a non-finite entry "
                f"at z = {bad:g}"
            )
        return np.linalg.eigvalsh(V)[:, 0]


def on_grid(question: Question, S: sympy.MatrixBase) -> str:
    """Decide on a grid, then prove every cell between its points by interval bounds.

    Strict: every cell must have a bound > 0.  Semidefinite: a constant kernel of ``S`` is
    set aside first, and every cell of the rest must have a bound of at least
    ``-tolerance`` (:data:`_SEMIDEFINITE_TOLERANCE` times the matrix's scale), the
    eigenvalue that "counts as 0": where an eigenvalue touches 0 the cells shrink until
    the bound meets it.  A cell that cannot be closed within the budget is refused, never
    accepted on the strength of its samples.

    Returns
    -------
    str
        How the relation was verified (the tail of a line of ``BCPHS.checks``).

    Raises
    ------
    ModelError
        At a sample that violates the relation, or at a cell that cannot be closed.
    """
    import numpy as np

    a, b = float(question.a), float(question.b)
    kernel: sympy.MatrixBase | None = None
    if not question.strict:
        kernel, S = _without_constant_kernel(S, a, b, question.name)
        if S.rows == 0:
            return "identically zero on [a, b]"
    samples = _Samples(S, question.name, question.where)
    grid = np.linspace(a, b, POSITIVITY_GRID_POINTS)
    lam = samples.smallest(grid)
    scale = max(1.0, float(np.max(np.abs(samples.values(grid)))))
    tolerance = 0.0 if question.strict else _SEMIDEFINITE_TOLERANCE * scale
    worst = int(np.argmin(lam))
    if question.violated(lam[worst], tolerance):
        question.fail_point(lam[worst], grid[worst])
    lowest = (float(lam[worst]), float(grid[worst]))
    lowest, unclosed = _prove_cells(question, samples, grid, lowest, tolerance)
    if unclosed is None:
        return _proved(question, lowest, tolerance, kernel)
    _undecided(question, unclosed, lowest, tolerance)


def _prove_cells(
    question: Question,
    samples: _Samples,
    grid: np.ndarray,
    lowest: tuple[float, float],
    tolerance: float,
) -> tuple[tuple[float, float], float | None]:
    """Halve the cells no bound closes; return the lowest sample and an unclosed point.

    The point is ``None`` when every cell is proved.
    """
    import numpy as np

    lo, hi = grid[:-1], grid[1:]
    examined = 0
    for _ in range(_MAX_HALVINGS):
        mid = 0.5 * (lo + hi)
        lam_mid = samples.smallest(mid)
        k = int(np.argmin(lam_mid))
        if lam_mid[k] < lowest[0]:
            lowest = (float(lam_mid[k]), float(mid[k]))
        if question.violated(lam_mid[k], tolerance):
            question.fail_point(lam_mid[k], mid[k])
        bound = _cell_bound(samples, lo, hi, mid, lam_mid)
        open_cells = ~(bound > 0) if question.strict else ~(bound >= -tolerance)
        examined += lo.size
        if not np.any(open_cells):
            return lowest, None
        lo, hi, mid = lo[open_cells], hi[open_cells], mid[open_cells]
        if examined + 2 * lo.size > _MAX_CELLS:
            break
        lo, hi = np.concatenate([lo, mid]), np.concatenate([mid, hi])
    return lowest, float(lo[0])


def _cell_bound(
    samples: _Samples, lo: np.ndarray, hi: np.ndarray, mid: np.ndarray, lam_mid: np.ndarray
) -> np.ndarray:
    """Return a lower bound of the smallest eigenvalue of S on each cell ``[lo, hi]``."""
    import numpy as np

    from phdesign.symbolic.evaluation import enclose  # numpy: the numeric path only

    n, S = samples.n, samples.S
    radius = np.zeros((lo.size, n, n))
    reach = np.zeros((lo.size, n, n))  # |S_ij| <= reach_ij off the diagonal
    floor = np.zeros((lo.size, n))  # S_ii >= floor_i
    centre = samples.values(mid)
    for i, j in samples.entries:
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
    return np.asarray(np.maximum(weyl, gershgorin))


def _proved(
    question: Question,
    lowest: tuple[float, float],
    tolerance: float,
    kernel: sympy.MatrixBase | None,
) -> str:
    """Return the line that says what the interval proof established."""
    which, shown = question.extreme(lowest[0])
    how = (
        f"on a grid of {POSITIVITY_GRID_POINTS} points at the parameter defaults, proved "
        "between the points by interval bounds"
    )
    if question.strict:
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


def _undecided(
    question: Question, near: float, lowest: tuple[float, float], tolerance: float
) -> NoReturn:
    """Refuse the matrix at a cell the budget could not close."""
    which, shown = question.extreme(lowest[0])
    name, kind, where = question.name, question.kind, question.where
    if question.strict:
        raise ModelError(
            f"{name} must be {kind} on {where}; it could not be proved "
            f"near z = {near:g} ({which} eigenvalue found {shown:.6g} at z = "
            f"{lowest[1]:g}; interval bounds of the entries do not separate it from 0) "
            "(parameter defaults)"
        )
    raise ModelError(
        f"{name} must be {kind} on {where}; it could not be decided near "
        f"z = {near:g} within the budget of {_MAX_CELLS} cells: an eigenvalue stays "
        f"within {tolerance:.3g} of 0 there ({which} eigenvalue sampled {shown:.6g} at "
        f"z = {lowest[1]:g}) and interval bounds of the entries do not bound it away "
        "from the wrong side; write the entries as rational functions of z (decided "
        "exactly) (parameter defaults)"
    )


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

    from phdesign.symbolic.evaluation import evaluate  # numpy: the numeric path only

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


def _evaluate(
    evaluate: Callable[[sympy.Expr, Any], Any], entry: sympy.Expr, z: Any, name: str
) -> Any:
    try:
        return evaluate(entry, z)
    except ExpressionError as error:
        raise ModelError(f"{name}: {error}") from None
