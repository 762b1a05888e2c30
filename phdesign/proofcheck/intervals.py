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
   to every entry; :math:`\|Y\|` is bounded exactly (the endpoints of the interval entries
   are dyadic rationals) and the remainder bound is evaluated in exact rationals;
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

from mpmath.libmp import from_int, mpf_div, mpf_neg, to_rational
from mpmath.libmp import libmpi as L

__all__ = [
    "PRECISION",
    "box",
    "centered_delta",
    "delta",
    "delta_and_slope",
    "interval",
    "parity",
    "taylor_terms",
]

PRECISION = 64
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


def _exact(x: tuple) -> Fraction:
    """Return the exact value of the mpf ``x`` (a dyadic rational)."""
    p, q = to_rational(x)
    return Fraction(p, q)


def _magnitude(z: tuple) -> Fraction:
    r"""Return an exact upper bound of :math:`|z|` over the complex interval z.

    :math:`|z| \le |\operatorname{Re} z| + |\operatorname{Im} z|`, each the larger
    modulus of its interval's endpoints: exact, no rounding.
    """
    re, im = z
    return max(abs(_exact(re[0])), abs(_exact(re[1]))) + max(
        abs(_exact(im[0])), abs(_exact(im[1]))
    )


def _row_sum_norm(Y: list) -> Fraction:
    r"""Return an exact upper bound of :math:`\|Y\|_\infty` over the interval matrix Y."""
    return max(sum((_magnitude(x) for x in row if x is not None), Fraction(0)) for row in Y)


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
    value: tuple = _delta(data, lam, prec, slope=False)[0]
    return value


def delta_and_slope(data, lam: tuple, prec: int = PRECISION) -> tuple[tuple, tuple]:
    r"""Enclose :math:`\Delta` and :math:`\Delta'` over the complex interval ``lam``.

    The derivative of :math:`F = e^{X(\lambda)}`, :math:`X = X_0 + \lambda X_1`, is the
    upper right block of :math:`\exp\begin{pmatrix} X & X_1 \\ 0 & X\end{pmatrix}`
    (Van Loan, 1978), so the same scaled Taylor polynomial and squarings enclose both;
    the minors' derivatives replace one row at a time by the derivative's, and the
    compound's squarings follow the product rule :math:`(C^2)' = C'C + CC'`.
    """
    return _delta(data, lam, prec, slope=True)


def centered_delta(data, p: tuple, q: tuple, prec: int = PRECISION) -> tuple:
    r"""Enclose Δ over the box spanned by the rational points p, q by the mean-value form.

    With c the box's centre, :math:`\Delta(\lambda) - \Delta(c) = (\lambda - c)
    \int_0^1 \Delta'(c + s(\lambda - c))\, ds`, and the integral lies in the convex
    enclosure of :math:`\Delta'` over the box, so :math:`\Delta(\text{box}) \subset
    \Delta(c) + \Delta'(\text{box})\,(\text{box} - c)`: its width shrinks with the box
    like :math:`|\Delta'|` times the box, where the direct enclosure's carries every
    term's size (which near a multiple zero, where :math:`\Delta'` is small too, never
    separates Δ from 0).
    """
    centre = ((p[0] + q[0]) / 2, (p[1] + q[1]) / 2)
    at_centre = delta(data, box((centre[0],) * 2, (centre[1],) * 2, prec), prec)
    _, slope = delta_and_slope(data, box((p[0], q[0]), (p[1], q[1]), prec), prec)
    half = box(
        (-abs(q[0] - p[0]) / 2, abs(q[0] - p[0]) / 2),
        (-abs(q[1] - p[1]) / 2, abs(q[1] - p[1]) / 2),
        prec,
    )
    enclosure: tuple = L.mpci_add(at_centre, L.mpci_mul(slope, half, prec), prec)
    return enclosure


def _companion(data, lam: tuple, sigma: Fraction, prec: int) -> tuple[list, list]:
    r""":math:`\tilde A(\lambda)\ell` over ``lam``, and its λ-derivative :math:`\tilde A_1\ell`."""
    nn, blocks = data.dimension, data.blocks
    Y, Y1 = [], []
    for i in range(nn):
        row, row1 = [], []
        for k in range(nn):
            factor = sigma ** (blocks[k] - blocks[i]) * data.length
            a0, a1 = data.A0[i][k], data.A1[i][k]
            entry = _real(a0 * factor, prec) if a0 else None
            if a1:
                scaled = L.mpci_mul(lam, _real(a1 * factor, prec), prec)
                entry = scaled if entry is None else L.mpci_add(entry, scaled, prec)
            row.append(entry)
            row1.append(_real(a1 * factor, prec) if a1 else None)
        Y.append(row)
        Y1.append(row1)
    return Y, Y1


def _delta(data, lam: tuple, prec: int, *, slope: bool) -> tuple[tuple, tuple]:
    order = data.order
    size = max(float(_magnitude(lam)), 1.0)  # chooses a scale only: no bound rests on it
    j = max(0, round(math.log2(size) / order)) if order > 1 else 0
    sigma = Fraction(2) ** j
    Y, Y1 = _companion(data, lam, sigma, prec)
    norm = float(_row_sum_norm(Y))  # chooses the numbers of squarings only
    whole = float(_row_sum_norm(_beside(Y, Y1))) if slope else norm  # the Van Loan block's
    s = max(0, math.ceil(math.log2(whole * 4))) if whole > 0 else 0
    t = max(0, math.ceil(math.log2(norm / MINOR_NORM))) if norm > 0 else 0
    t = min(t, s)
    p = _real(Fraction(1, 2**s), prec)
    Y, Y1 = (
        [[None if x is None else L.mpci_mul(x, p, prec) for x in row] for row in M]
        for M in (Y, Y1)
    )
    F, Fp = _exp_small(Y, Y1 if slope else None, prec)
    for _ in range(s - t):
        F, Fp = _square(F, Fp, prec)
    value = derivative = (L.mpi_zero, L.mpi_zero)
    for k, subsets, weights in data.terms:
        if k == 0:
            value = L.mpci_add(value, _real(weights[(0, 0)], prec), prec)
            continue
        C = [[_minor(F, rows, cols, prec) for cols in subsets] for rows in subsets]
        Cp = None if Fp is None else _minor_slopes(F, Fp, subsets, prec)
        for _ in range(t):  # squarings: repeated products would wrap far more
            C, Cp = _square(C, Cp, prec)
        for (a, b), w in weights.items():
            weight = _real(
                w * sigma ** (data.weight_blocks[k][a] - data.weight_blocks[k][b]), prec
            )
            value = L.mpci_add(value, L.mpci_mul(C[a][b], weight, prec), prec)
            if Cp is not None:
                derivative = L.mpci_add(derivative, L.mpci_mul(Cp[a][b], weight, prec), prec)
    return value, derivative


def _minor_slopes(F: list, Fp: list, subsets: list, prec: int) -> list:
    r""":math:`\frac{d}{d\lambda}\det F[I, J] = \sum_r \det(F[I, J]` with row r from F')."""
    out = []
    for rows in subsets:
        out_row = []
        for cols in subsets:
            total = (L.mpi_zero, L.mpi_zero)
            for r in range(len(rows)):
                mixed = [Fp[i] if at == r else F[i] for at, i in enumerate(rows)]
                total = L.mpci_add(total, _minor(mixed, tuple(range(len(rows))), cols, prec), prec)
            out_row.append(total)
        out.append(out_row)
    return out


def _add(X: list, Y: list, prec: int) -> list:
    zero = (L.mpi_zero, L.mpi_zero)
    return [
        [L.mpci_add(x or zero, y or zero, prec) for x, y in zip(a, b, strict=True)]
        for a, b in zip(X, Y, strict=True)
    ]


def _beside(X: list, Y: list) -> list:
    """Return the rows of X and Y side by side (the top rows of the Van Loan block)."""
    return [a + b for a, b in zip(X, Y, strict=True)]


def _square(F: list, Fp: list | None, prec: int) -> tuple[list, list | None]:
    r"""Return :math:`(F^2, (F^2)')` with :math:`(F^2)' = FF' + F'F` (Fp None: no slope)."""
    if Fp is not None:
        Fp = _add(_matmul(F, Fp, prec), _matmul(Fp, F, prec), prec)
    return _matmul(F, F, prec), Fp


def taylor_terms(prec: int) -> int:
    r"""Return the Taylor degree m whose remainder at :math:`\|Y\| = 1/4` is below 2^(10 - prec).

    The remainder pads every entry, so it must stay below what the precision resolves:
    near a multiple zero :math:`|\Delta|` is tiny (m = 12 at 64 bits, 17 at 96).
    """
    m = 1
    while Fraction(1, 4 ** (m + 1) * math.factorial(m + 1)) > Fraction(1, 2 ** (prec - 10)):
        m += 1
    return m


def _exp_small(Y: list, Y1: list | None, prec: int) -> tuple[list, list | None]:
    r""":math:`e^Y` for :math:`\|Y\|_\infty \le 1/4` with the Taylor remainder enclosed.

    With ``Y1`` (the λ-derivative of Y), also the derivative of :math:`e^Y`: the upper
    right block of the exponential of the Van Loan block :math:`Z = \begin{pmatrix} Y &
    Y_1 \\ 0 & Y\end{pmatrix}`, whose Horner steps are :math:`T \leftarrow I + YT/j`,
    :math:`T' \leftarrow (YT' + Y_1T)/j` (the block's products, never formed).
    The remainder of the degree-m Taylor polynomial obeys
    :math:`\|R\|_\infty \le \frac{\nu^{m+1}}{(m+1)!}\big(1 - \frac{\nu}{m+2}\big)^{-1}`
    for :math:`\nu \ge \|Z\|_\infty` (or :math:`\|Y\|_\infty`); ν is the exact row-sum
    bound of the interval entries and the bound is evaluated in exact rationals, then
    rounded up, so the padding contains the true remainder of every matrix in the box.
    """
    size = len(Y)
    m = taylor_terms(prec)
    norm = _row_sum_norm(Y if Y1 is None else _beside(Y, Y1))
    if norm >= m + 2:  # never with the scaling above; the geometric tail needs it
        raise ValueError(f"Taylor remainder: expected ||Y|| < {m + 2}; found {float(norm):.3g}")
    identity = _identity(size, prec)
    T = identity
    Tp = None if Y1 is None else [[(L.mpi_zero, L.mpi_zero)] * size for _ in range(size)]
    for j in range(m, 0, -1):
        inv = _real(Fraction(1, j), prec)
        if Tp is not None and Y1 is not None:
            Tp = _times(_add(_matmul(Y, Tp, prec), _matmul(Y1, T, prec), prec), inv, prec)
        T = _add(identity, _times(_zero_filled(_matmul(Y, T, prec)), inv, prec), prec)
    bound = norm ** (m + 1) / math.factorial(m + 1) / (1 - norm / (m + 2))
    rho = interval(bound, prec)[1]
    pad = ((mpf_neg(rho), rho), (mpf_neg(rho), rho))
    padding = [[pad] * size] * size  # the remainder, in every entry
    return _add(T, padding, prec), None if Tp is None else _add(Tp, padding, prec)


def _identity(size: int, prec: int) -> list:
    one, zero = _real(Fraction(1), prec), (L.mpi_zero, L.mpi_zero)
    return [[one if i == j else zero for j in range(size)] for i in range(size)]


def _times(X: list, factor: tuple, prec: int) -> list:
    return [[L.mpci_mul(x, factor, prec) for x in row] for row in X]
