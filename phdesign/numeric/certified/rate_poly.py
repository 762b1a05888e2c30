r"""The decay-rate proof for z-dependent coefficients: a polynomial weight, decided exactly.

For :math:`\partial_t x = P_1 \partial_z(\mathcal H x) + P_0 \mathcal H x` with
:math:`\mathcal H(z)`, :math:`P_0(z)` rational functions of :math:`z`
(:mod:`.rate_problem`), take

.. math::

    V(x) = \int_a^b x^\top \Pi(z)\, x\, dz, \qquad
    \Pi(z) = \sum_{j=0}^{d} \sum_k c_{jk}\, T_j(\zeta)\, B_k(z), \qquad
    \zeta = \frac{2(z - a)}{b - a} - 1 ,

with constant rational unknowns :math:`c_{jk}`, the Chebyshev polynomials :math:`T_j`
(a well-conditioned basis of the polynomials of degree :math:`\le d` on
:math:`[a, b]`) and :math:`B_k(z)` a polynomial basis of the symmetric matrices with
:math:`B_k P_1 \mathcal H` symmetric (:func:`.rate_exact.lyapunov_basis`: the nullspace of
:math:`\Pi \mapsto \Pi P_1\mathcal H - (\Pi P_1\mathcal H)^\top` over the field of
rational functions of :math:`z`, denominators cleared).  For the string,
:math:`\mathcal H = \operatorname{diag}(1/\rho, T)` and
:math:`P_1 = \begin{psmallmatrix}0&1\\1&0\end{psmallmatrix}`,
:math:`\Pi = \begin{psmallmatrix}p&q\\q&r\end{psmallmatrix}` gives
:math:`\Pi P_1 \mathcal H = \begin{psmallmatrix}q/\rho & pT\\ r/\rho & qT\end{psmallmatrix}`,
symmetric iff :math:`r = \rho T p`: :math:`B_1 = \operatorname{diag}(1, \rho T)`,
:math:`B_2 = P_1`.  A polynomial weight replaces the exponentials
:math:`e^{\mp\mu z}` of the constant case (polynomials approximate them, and the
travel-time weights a varying speed asks for, to any accuracy) and keeps every
inequality a polynomial one, decided exactly on all of :math:`[a, b]`.

With :math:`S = \Pi P_1 \mathcal H` symmetric,
:math:`2x^\top \Pi P_1 (\mathcal H x)_z = (x^\top S x)_z - x^\top S' x
+ 2x^\top \Pi P_1 \mathcal H' x` and :math:`S' = \Pi' P_1\mathcal H + \Pi P_1 \mathcal H'`, so
along classical solutions

.. math::

    \dot V + 2\sigma V = \Big[e^\top \mathcal H^{-1}\Pi P_1 e\Big]_a^b
    + \int_a^b x^\top G(z)\, x\, dz, \qquad
    G = -\operatorname{sym}(\Pi' P_1 \mathcal H) + \operatorname{sym}(\Pi P_1 \mathcal H')
    + 2\operatorname{sym}(\Pi P_0 \mathcal H) + 2\sigma \Pi ,

(:math:`\operatorname{sym} X = (X + X^\top)/2`; for a constant :math:`\mathcal H` this is
the :math:`G` of :mod:`.rate`).  The estimate
:math:`\|\tilde x(t)\| \le M e^{-\sigma t}\|\tilde x(0)\|` in the energy norm
:math:`\|x\|^2 = \int_a^b x^\top \mathcal H x\,dz` then rests on (:func:`inequalities`)

* :math:`\mathcal H(z) \succ 0`, :math:`\Pi(z) - c_1 \mathcal H(z) \succ 0`,
  :math:`c_2 \mathcal H(z) - \Pi(z) \succ 0` and :math:`G(z) \prec 0` for **every**
  :math:`z \in [a, b]`: matrices of rational functions, decided by
  :func:`.rate_exact.positive_on` (Sylvester's criterion with polynomial minors, each
  shown zero-free on :math:`[a, b]` by Sturm's theorem, and positive at :math:`a`);
* the boundary form :math:`K_b^\top \operatorname{diag}(\mathcal H(b)^{-1}\Pi(b)P_1,
  -\mathcal H(a)^{-1}\Pi(a)P_1) K_b \prec 0`, a rational matrix;
* :math:`\Pi` and :math:`\Pi P_1 \mathcal H` symmetric, identically in :math:`z`.

The numeric search (:mod:`.rate_poly_sdp`) imposes the pointwise inequalities on a grid
and adds the points where a fine check finds them violated; nothing it returns is
trusted before :func:`failures` is empty.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import sympy

from phdesign.numeric.certified.rate_exact import Inequality, boundary_form, lyapunov_basis
from phdesign.numeric.certified.rate_problem import RateProblem

__all__ = [
    "DEGREE",
    "PolynomialLyapunov",
    "failures",
    "inequalities",
    "interior_form",
    "polynomial_basis",
]

#: Degree d of the polynomial coordinates of Π (99.9 % of the true rate on the test strings).
DEGREE = 6


@dataclass(frozen=True)
class PolynomialLyapunov:
    r"""The rational unknowns of the z-dependent proof: :math:`\Pi(z)`, σ, c₁, c₂."""

    Pi: sympy.ImmutableMatrix
    sigma: sympy.Rational
    c1: sympy.Rational
    c2: sympy.Rational


def polynomial_basis(
    problem: RateProblem, degree: int = DEGREE
) -> tuple[sympy.ImmutableMatrix, ...]:
    r"""Return the basis :math:`T_j(\zeta) B_k(z)`, :math:`j \le` ``degree`` (module docstring)."""
    a, b = problem.interval
    zeta = 2 * (problem.z - a) / (b - a) - 1
    return tuple(
        sympy.ImmutableMatrix(sympy.expand(sympy.chebyshevt(j, zeta) * B))
        for j in range(degree + 1)
        for B in lyapunov_basis(problem)
    )


def _sym(X: sympy.MatrixBase) -> sympy.Matrix:
    return (X + X.T) / 2


def interior_form(problem: RateProblem, Pi: sympy.MatrixBase) -> sympy.ImmutableMatrix:
    r"""Return :math:`G - 2\sigma\Pi`, the σ-free part of the pointwise form (linear in Π)."""
    z, H, P1 = problem.z, problem.H, problem.P1
    parts = -_sym(Pi.diff(z) * P1 * H) + _sym(Pi * P1 * H.diff(z)) + 2 * _sym(Pi * problem.P0 * H)
    return sympy.ImmutableMatrix(parts)  # not cancelled: its readers cancel once


@functools.lru_cache(maxsize=4)  # the exact check and the proof ask for the same data
def inequalities(problem: RateProblem, data: PolynomialLyapunov) -> tuple[Inequality, ...]:
    """Return every matrix inequality of the estimate (the module docstring's list)."""
    z, H, Pi = problem.z, problem.H, data.Pi
    a, b = problem.interval
    on = (a, b)
    pointwise = interior_form(problem, Pi) + 2 * data.sigma * Pi

    def cancelled(M: sympy.MatrixBase) -> sympy.ImmutableMatrix:
        return sympy.ImmutableMatrix(sympy.Matrix(M).applyfunc(sympy.cancel))

    return (
        Inequality("energy", "positive", H, "H(z) ≻ 0 on [a, b]: the energy norm", on),
        Inequality(
            "lower bound",
            "positive",
            cancelled(Pi - data.c1 * H),
            "Π(z) − c₁H(z) ≻ 0 on [a, b], so V ≥ c₁‖x‖²",
            on,
        ),
        Inequality(
            "upper bound",
            "positive",
            cancelled(data.c2 * H - Pi),
            "c₂H(z) − Π(z) ≻ 0 on [a, b], so V ≤ c₂‖x‖²",
            on,
        ),
        Inequality(
            "boundary",
            "negative",
            boundary_form(problem, Pi.subs(z, b), Pi.subs(z, a)),
            "K_bᵀ diag(H(b)⁻¹Π(b)P₁, −H(a)⁻¹Π(a)P₁) K_b ≺ 0: the boundary term of dV/dt",
        ),
        Inequality(
            "pointwise",
            "negative",
            cancelled(pointwise),
            "G(z) = −sym(Π′P₁H) + sym(ΠP₁H′) + 2 sym(ΠP₀H) + 2σΠ ≺ 0 on [a, b]: "
            "dV/dt + 2σV inside",
            on,
        ),
    )


def failures(problem: RateProblem, data: PolynomialLyapunov) -> list[str]:
    """Return what fails of the exact proof (empty: every inequality and identity holds)."""
    found = [f"{q.name}: {q.meaning} fails" for q in inequalities(problem, data) if not q.holds]
    S = data.Pi * problem.P1 * problem.H
    if data.Pi != data.Pi.T or not (S - S.T).applyfunc(sympy.cancel).is_zero_matrix:
        found.append("Pi: Π(z) and Π(z) P₁ H(z) must be symmetric for every z")
    if not (data.sigma > 0 and data.c1 > 0):
        found.append("σ > 0 and c₁ > 0 are required")
    return found
