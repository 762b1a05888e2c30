r"""Compound matrices: :math:`\Delta` as a sum of entries of :math:`e^{A^{[k]}\ell}`.

Evaluated directly, :math:`\det(B_a + B_b e^{A\ell})` cancels: the entries of
:math:`e^{A\ell}` grow like :math:`e^{\nu_1 \ell}` (the fastest solution) while a
:math:`k \times k` minor grows only like :math:`e^{(\nu_1 + \dots + \nu_k)\ell}`, so a
ball of :math:`\lambda` of width :math:`h` gives an enclosure wider than :math:`|\Delta|`
by :math:`e^{(k-1)\nu_1\ell}`-fold (the beam at :math:`|\lambda| = 1000`: :math:`10^{13}`).
Two classical identities remove the cancellation:

* **Cauchy-Binet** on :math:`\Delta = \det\bigl((B_a\ B_b) \binom{I}{E}\bigr)`: with
  :math:`S = S_a \cup S_b` the column sets (:math:`|S_a| = Nn - k`, :math:`|S_b| = k`),

  .. math::

      \Delta = \sum_{k=0}^{Nn} \sum_{I, J} W_k[I, J]\, \Lambda^k(E)[I, J], \qquad
      W_k[S_b, C] \mathrel{+}= (-1)^{\sum_m (m + i_m)} \det (B_a\ B_b)_{:, S},

  where :math:`C` is the complement of :math:`S_a = \{i_1 < \dots\}` (1-based) and
  :math:`\Lambda^k(E)` the :math:`k`-th compound (the matrix of :math:`k \times k` minors,
  subsets in lexicographic order);
* the compound of an exponential is the exponential of the **additive compound**,
  :math:`\Lambda^k(e^{A\ell}) = e^{A^{[k]}\ell}`, with
  :math:`A^{[k]}(v_1 \wedge \dots \wedge v_k) = \sum_i v_1 \wedge \dots \wedge A v_i
  \wedge \dots \wedge v_k`, linear in :math:`A` (so :math:`A^{[k]}(\lambda) = A_0^{[k]} +
  \lambda A_1^{[k]}`) and of the growth :math:`e^{(\nu_1 + \dots + \nu_k)\ell}` of the
  minors themselves.
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction
from itertools import combinations

__all__ = ["additive_compound", "binet_weights", "subsets"]

Matrix = list[list[Fraction]]


def subsets(size: int, k: int) -> list[tuple[int, ...]]:
    """Return the k-subsets of ``range(size)`` in lexicographic order (the compounds' basis)."""
    return list(combinations(range(size), k))


def additive_compound(A: Sequence[Sequence[Fraction]], k: int) -> Matrix:
    r"""Return :math:`A^{[k]}` exactly (module docstring).

    :math:`A^{[k]} e_J = \sum_{m} e_{j_1} \wedge \dots \wedge A e_{j_m} \wedge \dots`; the
    term :math:`a_{i j_m} e_i` at position m of J sorts into position p of
    :math:`I = J \setminus \{j_m\} \cup \{i\}` with the sign :math:`(-1)^{m-p}`.

    Examples
    --------
    >>> A = [[Fraction(1), Fraction(2)], [Fraction(3), Fraction(4)]]
    >>> additive_compound(A, 2)   # the trace
    [[Fraction(5, 1)]]
    """
    basis = subsets(len(A), k)
    where = {s: i for i, s in enumerate(basis)}
    out = [[Fraction(0)] * len(basis) for _ in basis]
    for col, J in enumerate(basis):
        for m, j in enumerate(J):
            rest = J[:m] + J[m + 1 :]
            for i, row in enumerate(A):
                if row[j] == 0 or i in rest:
                    continue
                target = tuple(sorted((*rest, i)))
                sign = 1 if (m - target.index(i)) % 2 == 0 else -1
                out[where[target]][col] += sign * row[j]
    return out


def _det(M: Matrix) -> Fraction:
    """Exact determinant (sympy's, over the rationals)."""
    import sympy

    value = sympy.Matrix(
        [[sympy.Rational(x.numerator, x.denominator) for x in row] for row in M]
    ).det()
    return Fraction(int(value.p), int(value.q))


def binet_weights(
    Ba: Sequence[Sequence[Fraction]], Bb: Sequence[Sequence[Fraction]]
) -> dict[int, dict[tuple[int, int], Fraction]]:
    r"""Return the nonzero :math:`W_k[I, J]` of the Cauchy-Binet expansion, by k.

    Examples
    --------
    The scalar case :math:`\Delta = b_a + b_b e^{a\ell}`:

    >>> binet_weights([[Fraction(2)]], [[Fraction(3)]])
    {0: {(0, 0): Fraction(2, 1)}, 1: {(0, 0): Fraction(3, 1)}}
    """
    nn = len(Ba)
    B = [list(Ba[r]) + list(Bb[r]) for r in range(nn)]
    weights: dict[int, dict[tuple[int, int], Fraction]] = {}
    for k in range(nn + 1):
        where = {s: i for i, s in enumerate(subsets(nn, k))}
        Wk: dict[tuple[int, int], Fraction] = {}
        for Sa in combinations(range(nn), nn - k):
            C = tuple(j for j in range(nn) if j not in Sa)
            sign = -1 if sum(m + i for m, i in enumerate(Sa)) % 2 else 1  # (m+1)+(i+1)
            for Sb, row in where.items():
                cols = [*Sa, *(nn + j for j in Sb)]
                d = _det([[B[r][c] for c in cols] for r in range(nn)])
                if d:
                    key = (row, where[C])
                    Wk[key] = Wk.get(key, Fraction(0)) + sign * d
        nonzero = {key: w for key, w in Wk.items() if w}
        if nonzero:
            weights[k] = nonzero
    return weights
