r"""The characteristic determinant :math:`\Delta(\lambda)` of a constant-coefficient system.

For constant :math:`P_k` and :math:`H`, an eigenfunction of
:math:`\lambda x = \sum_k P_k \partial_z^k (Hx)` is, in the efforts :math:`e = Hx`, a
solution of :math:`\lambda H^{-1} e = \sum_k P_k e^{(k)}`: with
:math:`w = (e, e', \dots, e^{(N-1)})` it is :math:`w' = A(\lambda) w`, the companion matrix

.. math::

    A(\lambda) = A_0 + \lambda A_1, \qquad
    A_{k,k+1} = I, \qquad
    A_{N-1,0} = P_N^{-1}(\lambda H^{-1} - P_0), \qquad
    A_{N-1,k} = -P_N^{-1} P_k \ (k \ge 1)

(blocks of size n).  So :math:`w(z) = e^{A(\lambda)(z-a)} w(a)`, the trace vector is
:math:`v = (w(b); w(a)) = (\Phi; I)\, w(a)` with :math:`\Phi = e^{A(\lambda)\ell}`,
:math:`\ell = b - a`, and the closed boundary rows :math:`B = (B_b\ B_a)` admit a nonzero
:math:`w(a)` iff

.. math::

    \Delta(\lambda) = \det\bigl(B_a + B_b\, e^{A(\lambda)\ell}\bigr) = 0 .

:math:`\Delta` is entire, and its zeros are exactly the eigenvalues.

**Scaling.**  The eigenvalues of :math:`A(\lambda)` grow like :math:`|\lambda|^{1/N}` while
its entries grow like :math:`|\lambda|`; with :math:`D_\sigma = \operatorname{diag}(I,
\sigma^{-1} I, \dots, \sigma^{1-N} I)` (:math:`\sigma` a power of two near
:math:`|\lambda|^{1/N}`) the scaled companion :math:`\tilde A = D_\sigma A D_\sigma^{-1}`
has entries of the size of its eigenvalues, and

.. math::

    \Delta(\lambda) = \det D_\sigma \cdot
    \det\bigl(B_a D_\sigma^{-1} + B_b D_\sigma^{-1} e^{\tilde A \ell}\bigr),
    \qquad \det D_\sigma > 0,

so the scaled determinant has the argument of :math:`\Delta`, whatever :math:`\sigma`
(what the argument principle reads).  Each boundary row is divided by its first nonzero
entry (the same kernel, a nonzero constant factor): rows such as
:math:`(e_1'(0) + e_1'(1))/\sqrt 2` become rational.

The exact data (:class:`Characteristic`) is rational; :meth:`Characteristic.evaluate`
encloses :math:`\Delta` over a box of :math:`\lambda` in ball arithmetic (python-flint's
``acb_mat.exp`` and ``det``, imported when called).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from typing import Any

import sympy

from phdesign.core.errors import CertificateError
from phdesign.numeric.certified.compound import additive_compound, binet_weights, subsets
from phdesign.numeric.certified.exact_system import ExactClosedSystem

__all__ = ["Characteristic", "characteristic", "fraction", "fraction_text"]

Rows = tuple[tuple[Fraction, ...], ...]


def fraction(x: Any, what: str) -> Fraction:
    """Return the rational sympy number ``x`` as a :class:`~fractions.Fraction`."""
    if isinstance(x, int | Fraction):
        return Fraction(x)
    if not isinstance(x, sympy.Rational):
        raise CertificateError(f"{what} must be rational for a certificate; found {x}")
    return Fraction(int(x.p), int(x.q))


def fraction_text(x: Fraction) -> str:
    """Write ``x`` as ``"p/q"`` (``"p"`` for an integer): how a proof file spells numbers."""
    return str(x.numerator) if x.denominator == 1 else f"{x.numerator}/{x.denominator}"


def _rows(M: sympy.MatrixBase, what: str) -> Rows:
    return tuple(
        tuple(fraction(M[i, j], f"{what}[{i + 1},{j + 1}]") for j in range(M.cols))
        for i in range(M.rows)
    )


@dataclass(frozen=True)
class Characteristic:
    r"""The exact data of :math:`\Delta(\lambda)` (module docstring).

    Attributes
    ----------
    order, size : int
        :math:`N`, :math:`n`.
    length : Fraction
        :math:`\ell = b - a`.
    A0, A1 : tuple of tuple of Fraction
        :math:`A(\lambda) = A_0 + \lambda A_1` (``Nn x Nn``).
    Bb, Ba : tuple of tuple of Fraction
        The closed boundary rows over :math:`\phi(b)` and :math:`\phi(a)`, each row divided
        by its first nonzero entry.
    """

    order: int
    size: int
    length: Fraction
    A0: Rows
    A1: Rows
    Bb: Rows
    Ba: Rows

    @property
    def dimension(self) -> int:
        """:math:`Nn`."""
        return self.order * self.size

    def scale(self, magnitude: float) -> int:
        r"""Return :math:`\log_2 \sigma` for :math:`|\lambda| \approx` ``magnitude``."""
        import math

        if self.order == 1 or magnitude <= 1:
            return 0
        return max(0, round(math.log2(magnitude) / self.order))

    def to_dict(self) -> dict[str, Any]:
        """Return the data as exact ``"p/q"`` text (the proof file's ``characteristic``)."""

        def text(rows: Rows) -> list[list[str]]:
            return [[fraction_text(x) for x in row] for row in rows]

        return {
            "definition": "Delta(lam) = det(Ba + Bb expm((A0 + lam*A1)*length))",
            "order": self.order,
            "size": self.size,
            "length": fraction_text(self.length),
            "A0": text(self.A0),
            "A1": text(self.A1),
            "Bb": text(self.Bb),
            "Ba": text(self.Ba),
        }

    @cached_property
    def _compounds(self) -> tuple[tuple[int, Any, Any, dict[tuple[int, int], Fraction]], ...]:
        """Per k with nonzero weights: (k, A0^[k], A1^[k], W_k) (:mod:`.compound`)."""
        weights = binet_weights(self.Ba, self.Bb)
        return tuple(
            (k, additive_compound(self.A0, k), additive_compound(self.A1, k), W)
            for k, W in sorted(weights.items())
        )

    def evaluate(self, lam: Any, log2_sigma: int) -> Any:
        r"""Enclose :math:`\Delta` over the ``acb`` ball ``lam`` (flint).

        :math:`\Delta = \sum_k \sum_{I,J} W_k[I,J]\, \sigma^{b(I) - b(J)}
        (e^{\tilde A^{[k]}\ell})_{IJ}` (:mod:`.compound`), :math:`b(I)` the sum of the block
        indices of I, :math:`\tilde A^{[k]}_{IJ} = \sigma^{b(J) - b(I)} A^{[k]}_{IJ}`,
        :math:`\sigma = 2^{\text{log2\_sigma}}` (module docstring): equal to
        :math:`\Delta` for every :math:`\sigma`.  The working precision is flint's current
        one (``flint.ctx.workprec``).
        """
        return self._expand(lam, log2_sigma, slope=False)[0]

    def evaluate_with_slope(self, lam: Any, log2_sigma: int) -> tuple[Any, Any]:
        r"""Enclose :math:`\Delta` and :math:`\Delta'` over the ``acb`` ball ``lam``.

        With :math:`X = (\tilde A^{[k]}_0 + \lambda \tilde A^{[k]}_1)\ell`, the derivative
        :math:`\frac{d}{d\lambda} e^{X}` is the upper right block of
        :math:`\exp\begin{pmatrix} X & \tilde A^{[k]}_1\ell \\ 0 & X \end{pmatrix}`
        (Van Loan, 1978); :math:`\Delta'` is the same weighted sum of its entries.
        """
        return self._expand(lam, log2_sigma, slope=True)

    def _expand(self, lam: Any, log2_sigma: int, *, slope: bool) -> tuple[Any, Any]:
        from flint import acb, acb_mat, fmpq

        n = self.size
        ell = fmpq(self.length.numerator, self.length.denominator)
        total, derivative = acb(0), acb(0)
        for k, A0k, A1k, W in self._compounds:
            if k == 0:
                total += acb(_q(W[(0, 0)]))
                continue
            blocks = [sum(i // n for i in subset) for subset in subsets(self.dimension, k)]
            scale = [fmpq(2) ** (b * log2_sigma) for b in blocks]
            m = len(blocks)
            X = [[acb(0)] * m for _ in range(m)]
            X1 = [[acb(0)] * m for _ in range(m)]
            for i in range(m):
                for j in range(m):
                    factor = scale[j] / scale[i] * ell
                    a0, a1 = A0k[i][j], A1k[i][j]
                    if a1:
                        X1[i][j] = acb(_q(a1) * factor)
                    X[i][j] = (acb(_q(a0) * factor) if a0 else acb(0)) + lam * X1[i][j]
            if slope:
                zero = [acb(0)] * m
                E = _exp(
                    acb_mat([x + x1 for x, x1 in zip(X, X1, strict=True)] + [zero + x for x in X])
                )
            else:
                E = _exp(acb_mat(X))
            for (i, j), w in W.items():
                weight = acb(_q(w) * scale[i] / scale[j])
                total += weight * E[i, j]
                if slope:
                    derivative += weight * E[i, m + j]
        return total, derivative

    def box(self, a: tuple[Fraction, Fraction], b: tuple[Fraction, Fraction]) -> Any:
        r"""Enclose :math:`\Delta` over the rectangle of :math:`\lambda` with corners a, b."""
        return self.evaluate(_ball(a, b), self.scale(_size(a, b)))

    def centered(self, a: tuple[Fraction, Fraction], b: tuple[Fraction, Fraction]) -> Any:
        r"""Enclose :math:`\Delta` over the rectangle with corners a, b by the mean-value form.

        :math:`\Delta(\lambda) \in \Delta(c) + \Delta'(\text{box})(\text{box} - c)` (c the
        centre; the integral of :math:`\Delta'` along the segment from c lies in the convex
        ball enclosing it over the box): its radius is :math:`|\Delta'|` times the box where
        :meth:`box`'s carries every term's size, which near a multiple zero (where
        :math:`\Delta'` is small too) never separates :math:`\Delta` from 0.
        """
        from flint import acb

        centre = acb(_q((a[0] + b[0]) / 2), _q((a[1] + b[1]) / 2))
        ball, log2_sigma = _ball(a, b), self.scale(_size(a, b))
        _, slope = self.evaluate_with_slope(ball, log2_sigma)
        return self.evaluate(centre, log2_sigma) + slope * (ball - centre)

    def point(self, lam: Any) -> Any:
        r"""Enclose :math:`\Delta` at the ``acb`` point ``lam``."""
        return self.evaluate(lam, self.scale(float(abs(lam).mid())))


def _ball(a: tuple[Fraction, Fraction], b: tuple[Fraction, Fraction]) -> Any:
    """Return the ``acb`` ball that holds the rectangle with corners a, b."""
    from flint import acb, arb

    return acb(arb(_q(a[0])).union(arb(_q(b[0]))), arb(_q(a[1])).union(arb(_q(b[1]))))


def _size(a: tuple[Fraction, Fraction], b: tuple[Fraction, Fraction]) -> float:
    return float(max(abs(a[0]), abs(a[1]), abs(b[0]), abs(b[1])))


def _exp(X: Any) -> Any:
    r"""Return :math:`e^X` for a ball matrix: flint's exponential of :math:`X/2^s`, squared.

    flint bounds the effect of the input radii through the norm of the whole matrix,
    :math:`\|e^{X+E} - e^X\| \le \|E\| e^{\|X\| + \|E\|}`, which for an oscillatory
    :math:`X` (imaginary eigenvalues, :math:`\|e^X\| \approx 1 \ll e^{\|X\|}`) overstates
    the radius by :math:`e^{\|X\|}`; with :math:`\|X/2^s\| \le 1/2` that factor is at most
    :math:`e^{1/2}`, and the squarings propagate the radii as the entries themselves grow.
    """
    norm = max(sum(abs(X[i, j]).upper() for j in range(X.ncols())) for i in range(X.nrows()))
    s = max(0, math.ceil(math.log2(max(float(norm), 1e-300) * 2)))
    from flint import acb

    E = (X * acb(2) ** -s).exp()
    for _ in range(s):
        E = E * E
    return E


def _q(x: Fraction) -> Any:
    from flint import fmpq

    return fmpq(x.numerator, x.denominator)


def characteristic(system: ExactClosedSystem) -> Characteristic:
    r"""Return the exact :class:`Characteristic` of ``system``.

    Raises
    ------
    CertificateError
        If :math:`H` or a :math:`P_k` depends on z (no rigorous fundamental matrix is
        built here), if :math:`P_N` is singular, or if an entry is not rational after the
        rows are normalized.
    """
    if not system.constant:
        raise CertificateError(
            f"model {system.name!r} has z-dependent coefficients (H or P_k depend on z); the "
            "certified spectrum needs constant P_k and H (Δ is then det(B_a + B_b e^{A(λ)ℓ}))"
        )
    N, n = system.order, system.size
    PN = system.P[N]
    if PN.det() == 0:
        raise CertificateError(
            f"P{N} of model {system.name!r} is singular; Δ needs P_N invertible"
        )
    PN_inv = PN.inv()
    nn = N * n
    A0 = sympy.zeros(nn, nn)
    A1 = sympy.zeros(nn, nn)
    for k in range(N - 1):
        A0[k * n : (k + 1) * n, (k + 1) * n : (k + 2) * n] = sympy.eye(n)
    last = slice((N - 1) * n, N * n)
    for k in range(N):
        A0[last, k * n : (k + 1) * n] = -PN_inv * system.P[k]
    A1[last, 0:n] = PN_inv * system.H.inv()
    B = sympy.Matrix(system.boundary)
    for i in range(B.rows):
        lead = next((x for x in B.row(i) if x != 0), None)
        if lead is None:
            raise CertificateError(f"boundary row {i + 1} of model {system.name!r} is zero")
        B[i, :] = (B.row(i) / lead).applyfunc(sympy.radsimp)
    return Characteristic(
        order=N,
        size=n,
        length=fraction(system.length, "the interval's length"),
        A0=_rows(A0, "A0"),
        A1=_rows(A1, "A1"),
        Bb=_rows(B[:, :nn], "boundary row"),
        Ba=_rows(B[:, nn:], "boundary row"),
    )
