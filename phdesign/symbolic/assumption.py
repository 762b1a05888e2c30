r"""Assumption 3.1 of the paper (partitioned structure), with a permutation search.

For :math:`N = 2`, Assumption 3.1 asks for :math:`n` even and a split of the state
:math:`x = (x_1, x_2)` into two halves such that

.. math::

    P_1 = \begin{pmatrix} 0 & Q_1 \\ Q_1 & 0 \end{pmatrix}, \quad
    P_2 = \begin{pmatrix} 0 & -Q_2 \\ Q_2 & 0 \end{pmatrix}, \quad
    \mathcal H = \begin{pmatrix} \mathcal H_1 & 0 \\ 0 & \mathcal H_2 \end{pmatrix},

with :math:`Q_1, Q_2` symmetric and :math:`Q_2` invertible (:math:`\mathcal H_1,
\mathcal H_2 > 0` follow from :math:`\mathcal H > 0`).  A model rarely lists its
components in that order, so :func:`check_assumption` searches the permutations:
it picks the set of components of :math:`x_1` (the order-free conditions are tested
first: zero diagonal blocks of :math:`P_1, P_2`, zero off-diagonal block of
:math:`\mathcal H`), then pairs the components of :math:`x_1` with those of
:math:`x_2` by backtracking until :math:`Q_1` and :math:`Q_2` are symmetric.

The assumption is symmetric under swapping the blocks (:math:`Q_2 \to -Q_2`), and
Proposition 3.4 refers to the blocks asymmetrically, so every admissible choice of
:math:`x_1` is returned; the classifier tries each.

Examples
--------
>>> import sympy
>>> P1 = sympy.zeros(2, 2)
>>> P2 = sympy.Matrix([[0, -1], [1, 0]])
>>> H = sympy.diag(1, 1)
>>> check = check_assumption(P1, P2, H)
>>> check.holds, [p.label() for p in check.partitions]
(True, ['x1 = (x1), x2 = (x2)', 'x1 = (x2), x2 = (x1)'])
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from itertools import combinations
from typing import TYPE_CHECKING

import sympy

from phdesign.symbolic.expressions import vanishes

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.symbolic.model import BCPHS

__all__ = ["AssumptionCheck", "Partition", "check_assumption", "model_assumption"]

#: Beyond this size the subset search (C(n, n/2) subsets) is not attempted.
MAX_SIZE = 16


@dataclass(frozen=True)
class Partition:
    """A split of the state satisfying Assumption 3.1.

    Parameters
    ----------
    x1, x2 : tuple of int
        1-based state components of each block, paired in order: ``x1[j]`` and
        ``x2[j]`` carry row/column ``j`` of :math:`Q_1` and :math:`Q_2`.
    Q1, Q2 : sympy.ImmutableMatrix
        The blocks, :math:`Q_1 = P_1[x_1, x_2]` and :math:`Q_2 = P_2[x_2, x_1]`.
    """

    x1: tuple[int, ...]
    x2: tuple[int, ...]
    Q1: sympy.ImmutableMatrix
    Q2: sympy.ImmutableMatrix

    @property
    def permutation(self) -> tuple[int, ...]:
        """The new order of the components, ``x1 + x2`` (1-based)."""
        return self.x1 + self.x2

    def label(self, names: tuple[str, ...] | None = None) -> str:
        """Describe the split, e.g. ``x1 = (x1), x2 = (x2)``."""

        def name(i: int) -> str:
            return names[i - 1] if names else f"x{i}"

        first = ", ".join(name(i) for i in self.x1)
        second = ", ".join(name(i) for i in self.x2)
        return f"x1 = ({first}), x2 = ({second})"

    def to_dict(self) -> dict[str, object]:
        """JSON form: 1-based components and the blocks as strings."""
        return {
            "x1": list(self.x1),
            "x2": list(self.x2),
            "Q1": [[str(e) for e in row] for row in self.Q1.tolist()],
            "Q2": [[str(e) for e in row] for row in self.Q2.tolist()],
        }


@dataclass(frozen=True)
class AssumptionCheck:
    """Outcome of :func:`check_assumption`.

    Parameters
    ----------
    holds : bool
        Whether some partition satisfies Assumption 3.1.
    partitions : tuple of Partition
        Every admissible set of :math:`x_1` components (one pairing each), sorted.
    reason : str
        Why it fails, or a short confirmation.
    """

    holds: bool
    partitions: tuple[Partition, ...]
    reason: str


def model_assumption(model: BCPHS) -> AssumptionCheck | None:
    """Check Assumption 3.1 on a model of order 2; ``None`` for other orders."""
    if model.order != 2:
        return None
    return check_assumption(model.P[1], model.P[2], model.H, model.parameter_defaults)


def _is_zero(expr: sympy.Expr) -> bool:
    # An entry must vanish identically (in z and in the parameters), not only at the defaults.
    return vanishes(expr)


def check_assumption(
    P1: sympy.MatrixBase,
    P2: sympy.MatrixBase,
    H: sympy.MatrixBase,
    parameter_values: Mapping[sympy.Symbol, sympy.Expr] | None = None,
) -> AssumptionCheck:
    r"""Check Assumption 3.1 and find every admissible partition :math:`x = (x_1, x_2)`.

    Parameters
    ----------
    P1, P2 : sympy matrix
        :math:`P_1` and :math:`P_2` of an order-2 model, :math:`n \times n`.
    H : sympy matrix
        :math:`\mathcal H(z)`; its off-diagonal block must vanish identically in z.
    parameter_values : mapping, optional
        Values of the model's parameters, used only to decide whether
        :math:`\det Q_2 \ne 0` when it depends on them.

    Returns
    -------
    AssumptionCheck
    """
    values = dict(parameter_values or {})
    n = P1.shape[0]
    if n % 2:
        return AssumptionCheck(False, (), f"n must be even; found n = {n}")
    if n > MAX_SIZE:
        return AssumptionCheck(
            False, (), f"partition search not attempted for n = {n} > {MAX_SIZE}"
        )
    blocks = _Blocks(P1, P2, H, values)
    found: list[Partition] = []
    reasons: list[str] = []
    for first in combinations(range(n), n // 2):
        second = tuple(i for i in range(n) if i not in first)
        partition = blocks.partition(first, second)
        if isinstance(partition, str):
            reasons.append(partition)
        else:
            found.append(partition)
    if found:
        found.sort(key=lambda p: sorted(p.x1))
        return AssumptionCheck(True, tuple(found), f"{len(found)} admissible partition(s)")
    # Report the condition that failed for the most promising split.
    order = [
        "Q2 singular",
        "Q1/Q2 not symmetric for any pairing",
        "H not block diagonal",
        "diagonal blocks of P1/P2",
    ]
    worst = next((r for r in order if r in reasons), "no split")
    return AssumptionCheck(False, (), f"no split of the state satisfies it ({worst})")


class _Blocks:
    r"""The entries of :math:`P_1`, :math:`P_2`, :math:`\mathcal H`, with a cached zero test."""

    def __init__(
        self,
        P1: sympy.MatrixBase,
        P2: sympy.MatrixBase,
        H: sympy.MatrixBase,
        values: dict[sympy.Symbol, sympy.Expr],
    ) -> None:
        n = P1.shape[0]
        self.p1 = [[sympy.sympify(P1[i, j], strict=True) for j in range(n)] for i in range(n)]
        self.p2 = [[sympy.sympify(P2[i, j], strict=True) for j in range(n)] for i in range(n)]
        self.hh = [[sympy.sympify(H[i, j], strict=True) for j in range(n)] for i in range(n)]
        self.values = values
        self._zero: dict[sympy.Expr, bool] = {}

    def zero(self, expr: sympy.Expr) -> bool:
        if expr not in self._zero:
            self._zero[expr] = _is_zero(expr)
        return self._zero[expr]

    def equal(self, x: sympy.Expr, y: sympy.Expr) -> bool:
        return self.zero(x - y)

    def partition(self, first: tuple[int, ...], second: tuple[int, ...]) -> Partition | str:
        """Return the partition of the split ``(first, second)``, or the condition it fails."""
        p1, p2, zero, equal = self.p1, self.p2, self.zero, self.equal
        diagonal_zero = all(
            zero(m[i][j])
            for m in (p1, p2)
            for block in (first, second)
            for i in block
            for j in block
        )
        if not diagonal_zero:
            return "diagonal blocks of P1/P2"
        if not all(zero(self.hh[i][j]) for i in first for j in second):
            return "H not block diagonal"
        pairing = _pair(first, second, p1, p2, equal)
        if pairing is None:
            return "Q1/Q2 not symmetric for any pairing"
        h = len(first)
        Q1 = sympy.ImmutableMatrix([[p1[r][c] for c in second] for r in pairing])
        Q2 = sympy.ImmutableMatrix([[p2[r][c] for c in pairing] for r in second])
        # The lower-left block of P1 must be Q1 and the upper-right block of P2 must be
        # -Q2 exactly (automatic for a validated model, checked for direct callers).
        lower_ok = all(
            equal(p1[second[r]][pairing[c]], Q1[r, c])
            and equal(p2[pairing[r]][second[c]], -Q2[r, c])
            for r in range(h)
            for c in range(h)
        )
        if not lower_ok:
            return "Q1/Q2 not symmetric for any pairing"
        det = Q2.det()
        if _is_zero(det) or (det.free_symbols and _is_zero(det.subs(self.values))):
            return "Q2 singular"
        return Partition(tuple(i + 1 for i in pairing), tuple(i + 1 for i in second), Q1, Q2)


def _pair(
    first: tuple[int, ...],
    second: tuple[int, ...],
    p1: list[list[sympy.Expr]],
    p2: list[list[sympy.Expr]],
    equal: object,
) -> tuple[int, ...] | None:
    """Order ``first`` so that Q1 = P1[first, second] and Q2 = P2[second, first] are symmetric.

    Backtracking over positions: placing component ``c`` at position ``r`` requires
    ``Q[r, s] == Q[s, r]`` against every already placed position ``s``, and the order
    of the off-diagonal block conditions (lower block = Q1, lower block = Q2) follows
    from P1 symmetric and P2 skew-symmetric, checked at model construction.
    """
    h = len(first)
    placed: list[int] = []
    same = equal  # callable(x, y) -> bool

    def fits(c: int, r: int) -> bool:
        for s, d in enumerate(placed):
            # Q1[r, s] = P1[c, second[s]], Q1[s, r] = P1[d, second[r]]
            if not same(p1[c][second[s]], p1[d][second[r]]):  # type: ignore[operator]
                return False
            # Q2[r, s] = P2[second[r], d], Q2[s, r] = P2[second[s], c]
            if not same(p2[second[r]][d], p2[second[s]][c]):  # type: ignore[operator]
                return False
        # diagonal entries of Q1, Q2 are trivially symmetric
        return True

    def search() -> bool:
        r = len(placed)
        if r == h:
            return True
        for c in first:
            if c in placed or not fits(c, r):
                continue
            placed.append(c)
            if search():
                return True
            placed.pop()
        return False

    return tuple(placed) if search() else None
