r"""The Legendre basis of the Galerkin method, its Gauss rules and the trace scaling.

:math:`\psi_j(z) = \sqrt{(2j+1)/(b-a)}\, P_j(t)`, :math:`t = (2z - a - b)/(b - a)`: the
Legendre polynomials orthonormal on [a, b] (:func:`legendre_basis`, with derivatives),
the Gauss-Legendre rules that integrate their products exactly (:func:`gauss_rule`) and
the scale factors of the trace-scaled basis (:func:`trace_scaling`).

Conditioning and the choice of basis.  The eigenvalues of the pencil (closed matrix, E)
do not depend on the basis; how accurately they are computed depends on how.  The
spectrum (and with it the tuning, the loop's spectrum and the modal reduction) computes
them by shift and invert (:mod:`phdesign.numeric.spectrum.eigen`), accurate in either
basis: on airy (N = 3, L = I) the rightmost eigenvalue of the error system agrees with
the root of its characteristic determinant (mpmath, 40 digits) to 14.5 to 16 digits at
p = 16, 20, ..., 60 in both bases with every sensor (-1.99392753718), its real part to 11
to 13 digits in both with sensor 1 (-2.99987214184 + 837.3i), and the plain Legendre
basis keeps its 15 digits up to p = 140.  What factors the whole pencil sees its norm:
the QZ algorithm (:func:`scipy.linalg.eigvals`, and the triangularization of the noise
figures' Lyapunov solver, :mod:`phdesign.numeric.noise.lyapunov`) has a backward error
of order :math:`\epsilon \|A\|` and :math:`\epsilon \|E\|`.  In the orthonormal Legendre
basis E = I (for H = I) but the trace rows of T grow like
:math:`\psi_j^{(k)}(b) \sim j^{2k + 1/2}`, so an output feedback on the (N−1)-th
derivative traces puts entries of order :math:`p^{4N-3}` into the closed matrix (airy,
all sensors, L = I, p = 40: :math:`\|A\|_2 = 7.5 \cdot 10^{14}`, cond(A) = 3.8e14,
cond(E) = 1; QZ's abscissa is then wrong by 5e-3 at p = 40 and already by 8.5e-10 at
p = 12).

``basis="scaled"`` divides each :math:`\psi_j` by its largest boundary trace,
:math:`s_j = 1 / \max_{k<N} |\psi_j^{(k)}(b)|` (:func:`trace_scaling`): every column of
T has max-norm 1 and the same airy case has :math:`\|A\|_2 = 40.5`, cond(A) = 5.2e9,
and cond(E) = 1.5e14 for a *diagonal* E = diag(s²) (constant H; E = S M S, graded,
otherwise); QZ's error of the abscissa drops to 3e-15 … 1e-14 at every p from 8 to 140.
The change is the congruence ê = S ĉ, S = diag(s): E, J, R, B become S E S, S J S,
S R S, S B, so E ≻ 0, J = −Jᵀ, R ⪰ 0 and the exact energy balance are untouched, and
the matrices are assembled directly in the scaled basis (no product with S).  A
diagonal E costs nothing in the solves :math:`E^{-1} f`, which stay componentwise
accurate however large cond(E) is (the energy balance is checked to 1e-12).

Why the table of defaults (:mod:`phdesign.core.defaults`) still takes the scaled basis
for N >= 3, now that the spectrum no longer needs it (airy, L = I, measured again):

* the noise figures: with every sensor and unit intensities the variance of
  :math:`\int x_1 dz` is 0.5 to 15 digits at p = 16, 24, ..., 60 in the scaled basis; in
  the Legendre basis QZ puts it 1.5e-6 off at p = 16, 4e-4 at p = 32, 3e-3 at p = 40 and
  at 0.149 at p = 60;
* the spectrum's refinement with sensor 1 (the golden case ``spectrum airy --sensors 1``):
  the scaled basis converges at the pair (62, 93) to 10.5 digits; in the Legendre basis
  the agreement degrades beyond (27, 41) and the refinement stops unconverged (its
  abscissa within the scaled one's uncertainty 9e-11);
* not the time stepping: the error system's energy balance drifts alike in both bases
  (8e-10, 2e-9, 2e-8, 1e-7, 9e-6, 5e-5 of its energy at p = 12, 16, 20, 24, 32, 40),
  since the stiffness of :math:`E^{-1}A` does not depend on the basis: it is what sets
  the degree 16 for N >= 3.

For N <= 2 both bases agree to round-off and the Legendre basis keeps E well
conditioned for any H(z).

Rejected alternatives (QZ's error on the same airy case): an orthonormalization in the
E-inner product, or any orthogonal change of basis, leaves :math:`\|A\|_2` and the error
unchanged (a split into E-orthonormal bubbles and their 6-dimensional complement: error
2.6e-4 at p = 40); the boundary-adapted Babuška–Shen basis (2N low Legendre polynomials
plus bubbles :math:`(1-t^2)^N P_j^{(N,N)}` with vanishing traces) brings the error to
1e-12…1.5e-11 but its non-diagonal E has cond ~ p^(4N−3) (1e12 at p = 40) and a solve
with it loses the energy balance to 1e-7 at p = 24; imposing the boundary conditions
strongly creates spurious real eigenvalues drifting to 0.  Powers
:math:`s_j = (1+j)^{-\alpha}` confirm the exponent: α = 1, 2, 3, 4, 4.5 give errors
1.8e-7, 5.8e-12, 1.3e-12, 1e-14, 6e-15 at p = 40; :func:`trace_scaling` is α = 2N − 3/2
with the exact constants.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.polynomial import legendre as leg

__all__ = ["basis_at_gauss", "gauss_rule", "legendre_basis", "trace_scaling"]


@lru_cache(maxsize=64)
def _derivative_coefficients(p: int, k: int) -> np.ndarray:
    """Legendre coefficients (rows) of the k-th t-derivative of P_0..P_p (columns)."""
    C = np.eye(p + 1)
    if k == 0:
        return C
    Dk = leg.legder(C, k, axis=0)
    out = np.zeros((p + 1, p + 1))
    out[: Dk.shape[0], :] = Dk
    out.setflags(write=False)
    return out


def legendre_basis(z: np.ndarray, p: int, k: int, interval: tuple[float, float]) -> np.ndarray:
    r"""Values of the k-th z-derivative of the orthonormal Legendre basis on ``interval``.

    Returns an array of shape ``(len(z), p + 1)``; column j is
    :math:`\psi_j^{(k)}(z)`, :math:`\psi_j(z) = \sqrt{(2j+1)/(b-a)}\, P_j(t)`,
    :math:`t = (2z - a - b)/(b - a)`.

    Examples
    --------
    >>> import numpy as np
    >>> V = legendre_basis(np.array([0.0, 1.0]), 2, 0, (0.0, 1.0))
    >>> np.allclose(V[:, 0], 1.0)
    True
    """
    a, b = interval
    t = (2.0 * np.asarray(z, dtype=float) - a - b) / (b - a)
    V = leg.legvander(t, p) @ _derivative_coefficients(p, k)
    scale = (2.0 / (b - a)) ** k * np.sqrt((2.0 * np.arange(p + 1) + 1.0) / (b - a))
    return np.asarray(V * scale)


def trace_scaling(p: int, order: int, interval: tuple[float, float]) -> np.ndarray:
    r"""Scale factors :math:`s_j = 1 / \max_{k<N} |\psi_j^{(k)}(b)|` of the scaled basis.

    Every basis function :math:`s_j \psi_j` then has its largest boundary trace (of order
    < N, at either end: the magnitudes agree by parity) equal to 1, so the columns of the
    trace map T are equilibrated.  For large j, :math:`s_j \sim j^{-(2N - 3/2)}`.

    Examples
    --------
    >>> trace_scaling(3, 1, (0.0, 1.0)) ** -2  # psi_j(1)^2 = 2j + 1 on [0, 1]
    array([1., 3., 5., 7.])
    """
    b = np.array([float(interval[1])])
    peak = np.max([np.abs(legendre_basis(b, p, k, interval)[0]) for k in range(order)], axis=0)
    return np.asarray(1.0 / peak)


@lru_cache(maxsize=64)
def gauss_rule(points: int, interval: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on ``interval`` (cached, read-only arrays).

    Examples
    --------
    >>> z, w = gauss_rule(2, (0.0, 1.0))
    >>> float(w.sum()), bool(np.allclose(z, [0.5 - 0.5 / 3**0.5, 0.5 + 0.5 / 3**0.5]))
    (1.0, True)
    """
    a, b = interval
    t, w = leg.leggauss(points)
    nodes, weights = 0.5 * (a + b) + 0.5 * (b - a) * t, 0.5 * (b - a) * w
    nodes.setflags(write=False)
    weights.setflags(write=False)
    return nodes, weights


@lru_cache(maxsize=64)
def basis_at_gauss(p: int, k: int, points: int, interval: tuple[float, float]) -> np.ndarray:
    """``legendre_basis`` at the nodes of ``gauss_rule(points, interval)`` (cached)."""
    values = legendre_basis(gauss_rule(points, interval)[0], p, k, interval)
    values.setflags(write=False)
    return values
