r"""Enclosures of :math:`\Delta` over a box of :math:`\lambda`, in mpmath's interval arithmetic.

With the exact data of :mod:`.system` (companion :math:`A(\lambda) = A_0 + \lambda A_1`,
length :math:`\ell`, weights :math:`W_k`), :math:`\Delta = \sum_k \sum_{I,J} W_k[I,J]\,
\Lambda^k(e^{A\ell})[I,J]` (Cauchy-Binet).  Over a box :math:`\lambda \in \Lambda`:

1. scale the traces, :math:`\tilde A = D A D^{-1}`, :math:`D = \operatorname{diag}
   (\sigma^{-b(i)})` with :math:`\sigma = 2^j \approx |\lambda|^{1/N}` (then
   :math:`\Lambda^k(e^{A\ell})[I,J] = \sigma^{b(I) - b(J)} \Lambda^k(e^{\tilde A\ell})[I,J]`);
2. :math:`Y = \tilde A\ell/p`, :math:`p = 2^s` with :math:`\|Y\|_\infty \le 1/4`, and
   :math:`e^Y = \sum_{j \le m} Y^j/j! + R`, :math:`|R_{ik}| \le \|R\|_\infty \le
   \|Y\|^{m+1}/(m+1)! \cdot (1 - \|Y\|/(m+2))^{-1}`, the remainder added as an interval
   to every entry;
3. square to :math:`F = e^{\tilde A\ell/q}` with :math:`\|\tilde A\ell\|/q \le 2`, so that
   the minors of F (the compound :math:`\Lambda^k(F)`) do not cancel much;
4. square :math:`\Lambda^k(F)` up to :math:`\Lambda^k(e^{\tilde A\ell})` (compounds are
   multiplicative) and sum against the weights.

Every operation is an interval operation of ``mpmath.libmp.libmpi`` (what ``mpmath.iv``
calls), rounded outward, so the result contains :math:`\Delta(\lambda)` for every
:math:`\lambda` of the box.
"""

from __future__ import annotations

import math
from fractions import Fraction
from itertools import permutations

from mpmath.libmp import from_int, mpf_div
from mpmath.libmp import libmpi as L

__all__ = ["PRECISION", "box", "delta", "interval", "parity"]

PRECISION = 64
TAYLOR_TERMS = 11  # with ||Y|| <= 1/4 the remainder is below 1.3e-16
MINOR_NORM = (
    0.25  # the minors are taken of e^{Ãℓ/q} with ‖Ãℓ‖/q <= this (their wrapping ~ e^{2·this})
)


def interval(x: Fraction, prec: int = PRECISION) -> tuple:
    """Return the outward-rounded interval of the rational x."""
    p, q = from_int(x.numerator), from_int(x.denominator)
    return (mpf_div(p, q, prec, "f"), mpf_div(p, q, prec, "c"))


def box(re: tuple[Fraction, Fraction], im: tuple[Fraction, Fraction], prec: int = PRECISION):
    """Return the complex interval of the box ``re x im`` (each a pair lo <= hi)."""
    return (
        (interval(min(re), prec)[0], interval(max(re), prec)[1]),
        (interval(min(im), prec)[0], interval(max(im), prec)[1]),
    )


def _real(x: Fraction, prec: int) -> tuple:
    return (interval(x, prec), L.mpi_zero)


def _magnitude(z: tuple) -> float:
    """Return an upper bound of |z| (as a float, rounded up generously)."""
    re, im = z
    bound = max(abs(_float(re[0])), abs(_float(re[1]))) + max(
        abs(_float(im[0])), abs(_float(im[1]))
    )
    return bound * (1 + 1e-9) + 1e-300


def _float(x: tuple) -> float:
    from mpmath.libmp import to_float

    return float(to_float(x))


def _matmul(X: list, Y: list, prec: int) -> list:
    size, inner, cols = len(X), len(Y), len(Y[0])
    out = []
    for i in range(size):
        row = []
        for j in range(cols):
            acc = None
            for k in range(inner):
                if X[i][k] is None or Y[k][j] is None:
                    continue
                term = L.mpci_mul(X[i][k], Y[k][j], prec)
                acc = term if acc is None else L.mpci_add(acc, term, prec)
            row.append(acc)
        out.append(row)
    return out


def _zero_filled(X: list) -> list:
    zero = (L.mpi_zero, L.mpi_zero)
    return [[zero if x is None else x for x in row] for row in X]


def parity(order: tuple[int, ...]) -> int:
    """Return the sign of the permutation that sorts ``order`` (by counting inversions)."""
    inversions = sum(1 for i in range(len(order)) for j in range(i) if order[j] > order[i])
    return -1 if inversions % 2 else 1


def _minor(F: list, rows: tuple[int, ...], cols: tuple[int, ...], prec: int) -> tuple:
    """Return the determinant of F[rows, cols] by the Leibniz formula (k <= 4 here)."""
    total = (L.mpi_zero, L.mpi_zero)
    for perm in permutations(range(len(rows))):
        term = None
        for r, c in enumerate(perm):
            entry = F[rows[r]][cols[c]]
            term = entry if term is None else L.mpci_mul(term, entry, prec)
        if term is not None and parity(perm) < 0:
            term = (L.mpi_neg(term[0]), L.mpi_neg(term[1]))
        total = L.mpci_add(total, term, prec)
    return total


def delta(data, lam: tuple, prec: int = PRECISION) -> tuple:
    """Enclose Δ over the complex interval ``lam`` (``data``: :class:`.system.Delta`)."""
    nn, order = data.dimension, data.order
    size = max(_magnitude(lam), 1.0)
    j = max(0, round(math.log2(size) / order)) if order > 1 else 0
    sigma = Fraction(2) ** j
    blocks = data.blocks
    ell = data.length
    Y = []
    for i in range(nn):
        row = []
        for k in range(nn):
            factor = sigma ** (blocks[k] - blocks[i]) * ell
            a0, a1 = data.A0[i][k], data.A1[i][k]
            entry = _real(a0 * factor, prec) if a0 else None
            if a1:
                scaled = L.mpci_mul(lam, _real(a1 * factor, prec), prec)
                entry = scaled if entry is None else L.mpci_add(entry, scaled, prec)
            row.append(entry)
        Y.append(row)
    norm = max(sum(_magnitude(x) for x in row if x is not None) for row in Y)
    s = max(0, math.ceil(math.log2(norm * 4))) if norm > 0 else 0
    t = max(0, math.ceil(math.log2(norm / MINOR_NORM))) if norm > 0 else 0
    t = min(t, s)
    p = _real(Fraction(1, 2**s), prec)
    Y = [[None if x is None else L.mpci_mul(x, p, prec) for x in row] for row in Y]
    F = _exp_small(Y, norm / 2**s, prec)
    for _ in range(s - t):
        F = _matmul(F, F, prec)
    total = (L.mpi_zero, L.mpi_zero)
    for k, subsets, weights in data.terms:
        if k == 0:
            total = L.mpci_add(total, _real(weights[(0, 0)], prec), prec)
            continue
        C = [[_minor(F, rows, cols, prec) for cols in subsets] for rows in subsets]
        for _ in range(t):  # squarings: repeated products would wrap far more
            C = _matmul(C, C, prec)
        for (a, b), w in weights.items():
            scale = sigma ** (data.weight_blocks[k][a] - data.weight_blocks[k][b])
            total = L.mpci_add(total, L.mpci_mul(C[a][b], _real(w * scale, prec), prec), prec)
    return total


def _exp_small(Y: list, norm: float, prec: int) -> list:
    r""":math:`e^Y` for :math:`\|Y\|_\infty \le 1/4` with the Taylor remainder enclosed."""
    size = len(Y)
    m = TAYLOR_TERMS
    one = _real(Fraction(1), prec)
    zero = (L.mpi_zero, L.mpi_zero)
    T = [[one if i == j else zero for j in range(size)] for i in range(size)]
    for j in range(m, 0, -1):  # Horner: T = I + Y T / j
        YT = _zero_filled(_matmul(Y, T, prec))
        inv = _real(Fraction(1, j), prec)
        T = [
            [
                L.mpci_add(one if a == b else zero, L.mpci_mul(YT[a][b], inv, prec), prec)
                for b in range(size)
            ]
            for a in range(size)
        ]
    bound = norm ** (m + 1) / math.factorial(m + 1) / (1 - norm / (m + 2))
    rho = interval(Fraction(bound * 1.001 + 1e-300), prec)[1]
    from mpmath.libmp import mpf_neg

    pad = ((mpf_neg(rho), rho), (mpf_neg(rho), rho))
    return [[L.mpci_add(x, pad, prec) for x in row] for row in T]
