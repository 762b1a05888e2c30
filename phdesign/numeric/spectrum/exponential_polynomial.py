r"""Root chains of an exponential polynomial, and the limits of their real parts.

A determinant :math:`\Delta_\infty(\lambda) = \det(A + B\,\operatorname{diag}(e^{\lambda
\tau_1}, \dots, e^{\lambda \tau_n}))` (the high-frequency characteristic determinant of a
hyperbolic boundary problem, :mod:`phdesign.numeric.spectrum.branches`) is, by multilinearity in
the columns, the exponential polynomial

.. math::

    \Delta_\infty(\lambda) = \sum_{S \subseteq \{1..n\}} \det M_S \; e^{\lambda \sum_{j \in S}
    \tau_j}, \qquad M_S = A \text{ with the columns } j \in S \text{ taken from } B .

Write the travel times over a *rational basis*, :math:`\tau_j = \sum_k n_{jk} r_k` with
integers :math:`n_{jk}` (:func:`rational_basis`: pairwise ratios p/q with |p|, q <= 12
are found; what is left is taken as rationally independent, see below).  Then
:math:`\Delta_\infty = F(e^{\lambda r_1}, \dots, e^{\lambda r_m})` for a Laurent polynomial
F, and the classical results on the zeros of exponential polynomials (Pólya; Bellman and
Cooke, *Differential-Difference Equations*, ch. 12; Avellar and Hale, J. Math. Anal.
Appl. 73, 1980) give the real parts of its zeros:

* **one basis element** (commensurate times, m = 1): :math:`F(\zeta)` is a polynomial
  in :math:`\zeta = e^{\lambda r}` and every root :math:`\zeta_l` gives the chain
  :math:`\lambda = (\ln \zeta_l + 2\pi i j)/r`, :math:`j \in \mathbb Z`, of real part
  exactly :math:`\ln|\zeta_l| / r`;
* **several** (rationally independent times): the closure of the set of real parts of
  the zeros is the set of :math:`\sigma` for which
  :math:`F(e^{\sigma r_1 + i\theta_1}, \dots, e^{\sigma r_m + i\theta_m}) = 0` for some
  phases :math:`\theta \in [0, 2\pi)^m` (Kronecker: the phases :math:`\omega r_k` fill the
  torus).  Its supremum is computed by :func:`torus_supremum`.  When F factors into
  polynomials in disjoint sets of variables (families that the boundary does not couple),
  each factor is treated on its own, exactly when it has one variable.

A pairwise rational relation with small integers is found; a relation among three or more
times (τ₃ = τ₁ + τ₂ with τ₁/τ₂ irrational), or with larger integers (speeds 1 and 100),
is not: then the phases are taken as independent, a set of phases larger than the true
one, so the supremum is an upper bound, never too small (and exact for factors the
boundary leaves apart, which are treated one by one).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from itertools import product

import numpy as np
from scipy.optimize import minimize_scalar

__all__ = [
    "ChainLimit",
    "ExponentialPolynomial",
    "chain_limits",
    "exponential_polynomial",
    "rational_basis",
    "torus_supremum",
]

MAX_DENOMINATOR = 12  # largest q of a rational ratio p/q between two travel times
MAX_EXPONENT = 64  # largest integer coefficient of a travel time over the basis
RATIO_RTOL = 1e-9  # relative agreement of a ratio with p/q
MAX_COLUMNS = 16  # 2^16 minors: beyond that the expansion is not attempted
_EPS = float(np.finfo(float).eps)


def rational_basis(tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return (r, n): positive basis times r_k and integers n (len(tau), m), τ = n r.

    Pairwise ratios that are rationals p/q with q <= :data:`MAX_DENOMINATOR` (to
    :data:`RATIO_RTOL`) share a basis element; the others get their own.

    Examples
    --------
    >>> r, n = rational_basis(np.array([1.0, -1.0, 0.5, np.sqrt(2)]))
    >>> r.round(6).tolist(), n.tolist()
    ([0.5, 1.414214], [[2, 0], [-2, 0], [1, 0], [0, 1]])
    """
    basis: list[float] = []
    rows: list[dict[int, int]] = []
    for t in np.asarray(tau, dtype=float):
        for k, r in enumerate(basis):
            ratio = Fraction(t / r).limit_denominator(MAX_DENOMINATOR)
            if abs(float(ratio) - t / r) > RATIO_RTOL * abs(t / r):
                continue
            if abs(ratio.numerator) > MAX_DENOMINATOR:  # p/q with both small, else apart
                continue
            q = ratio.denominator
            if q > 1:  # refine the basis element so that every multiple stays an integer
                basis[k] = r / q
                for row in rows:
                    if k in row:
                        row[k] *= q
            rows.append({k: ratio.numerator})
            break
        else:
            basis.append(abs(float(t)))
            rows.append({len(basis) - 1: 1 if t > 0 else -1})
    n = np.zeros((len(rows), len(basis)), dtype=int)
    for j, row in enumerate(rows):
        for k, v in row.items():
            n[j, k] = v
    return np.array(basis), n


@dataclass(frozen=True)
class ExponentialPolynomial:
    r"""A Laurent polynomial :math:`F(\zeta_1..\zeta_m) = \sum_e c_e \prod_k \zeta_k^{e_k}`.

    With :math:`\zeta_k = e^{\lambda r_k}` it is the exponential polynomial of the module
    docstring.

    Attributes
    ----------
    basis : ndarray (m,)
        The basis times :math:`r_k > 0`.
    exponents : ndarray of int (terms, m)
    coefficients : ndarray of complex (terms,)
        Only the terms that are not zero within round-off.
    scale : float
        The size of the terms before cancellation (Hadamard bounds): the round-off
        reference of the coefficients.
    """

    basis: np.ndarray
    exponents: np.ndarray
    coefficients: np.ndarray
    scale: float

    def __call__(self, lam: complex) -> complex:
        """Evaluate at λ."""
        zeta = np.exp(lam * self.basis)
        return complex(np.sum(self.coefficients * np.prod(zeta**self.exponents, axis=1)))

    def factors(self) -> list[ExponentialPolynomial]:
        """Split into factors in disjoint sets of variables (families the boundary leaves apart).

        A bipartition of the variables splits F when the coefficient matrix unfolded along
        it has rank one (relative 1e-10).
        """
        m = self.basis.size
        if m <= 1:
            return [self]
        for size in range(1, m // 2 + 1):
            for first in _subsets(m, size):
                split = self._split(list(first))
                if split is not None:
                    return split[0].factors() + split[1].factors()
        return [self]

    def _split(
        self, first: list[int]
    ) -> tuple[ExponentialPolynomial, ExponentialPolynomial] | None:
        second = [k for k in range(self.basis.size) if k not in first]
        rows = sorted({tuple(e[first]) for e in self.exponents})
        cols = sorted({tuple(e[second]) for e in self.exponents})
        C = np.zeros((len(rows), len(cols)), dtype=complex)
        for e, c in zip(self.exponents, self.coefficients, strict=True):
            C[rows.index(tuple(e[first])), cols.index(tuple(e[second]))] += c
        U, s, Vh = np.linalg.svd(C)
        if s.size > 1 and s[1] > 1e-10 * s[0]:
            return None
        g, h = U[:, 0] * s[0], Vh[0]
        return (
            _polynomial(self.basis[first], np.array(rows), g, self.scale),
            _polynomial(self.basis[second], np.array(cols), h, 1.0),
        )


def _subsets(m: int, size: int) -> list[tuple[int, ...]]:
    return [c for c in product(range(m), repeat=size) if list(c) == sorted(set(c))]


def _polynomial(
    basis: np.ndarray, exponents: np.ndarray, coefficients: np.ndarray, scale: float
) -> ExponentialPolynomial:
    keep = np.abs(coefficients) > 1e3 * _EPS * max(scale, float(np.max(np.abs(coefficients))))
    return ExponentialPolynomial(
        basis=basis,
        exponents=exponents[keep].reshape(-1, basis.size),
        coefficients=coefficients[keep],
        scale=float(scale),
    )


def exponential_polynomial(A: np.ndarray, B: np.ndarray, tau: np.ndarray) -> ExponentialPolynomial:
    r"""Return :math:`\det(A + B \operatorname{diag}(e^{\lambda\tau}))` as a Laurent polynomial.

    Raises
    ------
    ValueError
        With more than :data:`MAX_COLUMNS` columns (2^n minors).

    Examples
    --------
    The unit string fixed at 0 (e₁(0) = 0) with a damper at 1 (e₂(1) = -k e₁(1)): in the
    characteristic variables of speeds -1 and 1, e = (w₋ + w₊, -w₋ + w₊)/√2, so
    Δ∞ = ((1 + k) e^λ - (k - 1) e^{-λ}) / 2 and the chain's real part is
    ln|(1 - k)/(1 + k)| / 2.

    >>> k = 0.5
    >>> A = np.array([[1.0, 1.0], [0.0, 0.0]]) / np.sqrt(2)
    >>> B = np.array([[0.0, 0.0], [k - 1, k + 1]]) / np.sqrt(2)
    >>> F = exponential_polynomial(A, B, np.array([-1.0, 1.0]))
    >>> [round(c.limit, 10) for c in chain_limits(F)], round(0.5 * math.log(1 / 3), 10)
    ([-0.5493061443], -0.5493061443)
    """
    n = A.shape[1]
    if n > MAX_COLUMNS:
        raise ValueError(f"exponential polynomial of {n} columns: at most {MAX_COLUMNS}")
    basis, n_int = rational_basis(tau)
    picks = np.array(list(product((False, True), repeat=n)), dtype=bool)  # (2^n, n)
    minors = np.where(picks[:, None, :], B[None], A[None])  # every mixed matrix M_S at once
    dets = np.linalg.det(minors)
    scale = float(np.max(np.prod(np.linalg.norm(minors, axis=1), axis=1)))  # Hadamard
    keys = picks.astype(int) @ n_int  # the exponent of each subset over the basis
    exponents, where = np.unique(keys, axis=0, return_inverse=True)
    coefficients = np.zeros(exponents.shape[0], dtype=complex)
    np.add.at(coefficients, where.ravel(), dets)
    return _polynomial(basis, exponents.reshape(-1, basis.size), coefficients, scale)


@dataclass(frozen=True)
class ChainLimit:
    r"""The limit of the real parts of the root chains of one factor.

    Attributes
    ----------
    limit : float
        :math:`\sup \operatorname{Re}` of the factor's chains at high frequency
        (``-inf``: the factor has no zeros, e.g. a reflection-free boundary).
    uncertainty : float
        Accuracy of ``limit`` (round-off of the roots, or of the torus search).
    exact : bool
        One basis element: the chains' real parts are exactly the limit.
    variables : tuple of int
        The basis elements (of the polynomial factored) the factor depends on.
    chains : int
        Number of root chains (the degree in ζ; 0 for several variables).
    """

    limit: float
    uncertainty: float
    exact: bool
    variables: tuple[int, ...]
    chains: int


def chain_limits(F: ExponentialPolynomial, floor: float = -math.inf) -> list[ChainLimit]:
    """Return the limit of every factor of ``F`` (module docstring).

    ``floor`` bounds the search of a factor in several variables from below: a limit
    under it is reported as ``floor`` (an upper bound).
    """
    out: list[ChainLimit] = []
    for factor in F.factors():
        variables = tuple(int(np.flatnonzero(F.basis == r)[0]) for r in factor.basis)
        if factor.basis.size == 1:
            out.append(_polynomial_limit(factor, variables))
        else:
            value, uncertainty = torus_supremum(factor, floor)
            out.append(ChainLimit(value, uncertainty, False, variables, 0))
    return out


def _polynomial_limit(F: ExponentialPolynomial, variables: tuple[int, ...]) -> ChainLimit:
    r = float(F.basis[0])
    e = F.exponents[:, 0]
    if F.coefficients.size <= 1 or np.ptp(e) == 0:
        return ChainLimit(-math.inf, 0.0, True, variables, 0)
    coeffs = np.zeros(int(np.ptp(e)) + 1, dtype=complex)
    np.add.at(coeffs, e - e.min(), F.coefficients)
    roots = np.roots(coeffs[::-1])
    roots = roots[np.abs(roots) > 0]
    if roots.size == 0:
        return ChainLimit(-math.inf, 0.0, True, variables, 0)
    sigma = np.log(np.abs(roots)) / r
    lead = int(np.argmax(sigma))
    return ChainLimit(
        float(sigma[lead]),
        _root_uncertainty(coeffs, roots, lead) / r,
        True,
        variables,
        int(roots.size),
    )


def _root_uncertainty(coeffs: np.ndarray, roots: np.ndarray, lead: int) -> float:
    """Accuracy of ln|ζ| for the root ``lead`` (first order, or ε^(1/m) in a cluster)."""
    z = roots[lead]
    powers = np.abs(z) ** np.arange(coeffs.size)
    size = float(np.sum(np.abs(coeffs) * powers))
    derivative = np.polyval(np.polyder(coeffs[::-1]), z)
    multiplicity = int(np.count_nonzero(np.abs(roots - z) <= 1e-5 * abs(z)))
    relative = 16 * _EPS * coeffs.size * size / max(abs(z * derivative), 1e-300)
    if multiplicity > 1:
        relative = max(relative, (16 * _EPS * coeffs.size) ** (1.0 / multiplicity))
    return float(min(relative, 1.0))


def _counts(F: ExponentialPolynomial, thetas: np.ndarray, sigmas: np.ndarray) -> np.ndarray:
    """Roots ζ₁ inside |ζ₁| = e^{σ r₁} for each phase row of ``thetas`` and each σ.

    ``thetas`` has shape (P, m - 1), ``sigmas`` shape (P, S); the result (P, S).  The
    polynomials in ζ₁ of all (phase, σ) are solved at once (companion matrices).
    """
    r, e = F.basis, F.exponents
    exponent = sigmas[:, :, None] * (e[:, 1:] @ r[1:])[None, None, :]
    phase = (thetas @ e[:, 1:].T)[:, None, :]
    terms = F.coefficients[None, None, :] * np.exp(exponent + 1j * phase)
    low, degree = int(e[:, 0].min()), int(np.ptp(e[:, 0]))
    if degree == 0:  # F does not depend on ζ₁: no root to count
        return np.zeros(sigmas.shape, dtype=int)
    coeffs = np.zeros((*sigmas.shape, degree + 1), dtype=complex)
    for power in range(degree + 1):
        coeffs[..., power] = terms[..., e[:, 0] - low == power].sum(axis=-1)
    size = np.max(np.abs(coeffs), axis=-1, keepdims=True)
    lead = coeffs[..., -1:]
    tiny = np.abs(lead) <= 1e-14 * size  # a degree that drops: its roots lie at infinity
    lead = np.where(tiny, 1e-14 * size, lead)
    companion = np.zeros((*sigmas.shape, degree, degree), dtype=complex)
    companion[..., 0, :] = -coeffs[..., -2::-1] / lead
    companion[..., np.arange(1, degree), np.arange(degree - 1)] = 1.0
    roots = np.linalg.eigvals(companion)
    inside = np.log(np.maximum(np.abs(roots), 1e-300)) < (sigmas * r[0])[..., None]
    return np.asarray(np.count_nonzero(inside, axis=-1))


def _largest_crossings(
    F: ExponentialPolynomial, thetas: np.ndarray, top: float, floor: float
) -> np.ndarray:
    """Return the largest σ in [floor, top] where a root crosses its circle, per phase row.

    A grid finer near ``top`` (where a supremum of real parts lies) brackets the first
    change of the count from the top; 52 bisections close each bracket.  ``-inf`` where
    no root crosses.
    """
    P = thetas.shape[0]
    grid = top - np.concatenate([[0.0], np.geomspace(1e-9, top - floor, 120)])
    counts = _counts(F, thetas, np.broadcast_to(grid, (P, grid.size)))
    changed = counts[:, 1:] != counts[:, :1]
    found = changed.any(axis=1)
    first = np.argmax(changed, axis=1)
    hi, lo = grid[first], grid[first + 1]
    reference = counts[:, 0]
    for _ in range(52):
        mid = 0.5 * (hi + lo)
        same = _counts(F, thetas, mid[:, None])[:, 0] == reference
        hi, lo = np.where(same, mid, hi), np.where(same, lo, mid)
    return np.where(found, 0.5 * (hi + lo), -np.inf)


def torus_supremum(
    F: ExponentialPolynomial, floor: float = -math.inf, top: float = 0.0
) -> tuple[float, float]:
    r"""Supremum over the phases of the real parts where F has a zero (m = 2 or 3).

    For phases :math:`\theta_2..\theta_m` on a grid (64 or 16 × 16 points) the largest
    :math:`\sigma` at which a root :math:`\zeta_1` of F crosses the circle
    :math:`|\zeta_1| = e^{\sigma r_1}` is found by counting the roots inside it and
    bisecting; the best phase is then polished by a bounded scalar search (m = 2).  The
    search runs over :math:`[\text{floor}, \text{top}]` (top = 0 for a dissipative
    problem, whose chains have :math:`\operatorname{Re} \le 0`); the floor is raised to
    a bound below which one term dominates and nothing crosses.  Returns (value,
    uncertainty); the value is ``floor`` (an upper bound) when nothing crosses above it.

    Raises
    ------
    ValueError
        For more than three basis elements.
    """
    m = F.basis.size
    if m not in (2, 3):
        raise ValueError(f"torus search over {m} phases: only 2 or 3 are supported")
    # below the single-term bound nothing crosses; above ~700 / |n r| exp overflows
    floor = max(floor, _floor_bound(F), -600.0 / float(np.max(np.abs(F.exponents @ F.basis))))
    axis = np.linspace(0.0, 2 * np.pi, 64 if m == 2 else 16, endpoint=False)
    points = np.array(list(product(axis, repeat=m - 1)))
    values = _largest_crossings(F, points, top, floor)
    best = int(np.argmax(values))
    value = float(values[best])
    if not math.isfinite(value):
        return floor, 0.0
    step = axis[1] - axis[0]
    if m == 2:
        center = float(points[best, 0])
        res = minimize_scalar(
            lambda t: -float(_largest_crossings(F, np.array([[t]]), top, floor)[0]),
            bounds=(center - step, center + step),
            method="bounded",
            options={"xatol": 1e-10},
        )
        value = max(value, -float(res.fun))
        spread = 1e-12 * max(1.0, abs(value))
    else:
        # a grid over two phases may miss a narrow peak between points: its size is bounded
        # by the change of the crossing over one grid step, estimated from the neighbours
        finite = values[np.isfinite(values)]
        spread = float(np.ptp(finite)) / 16 + 1e-12 * max(1.0, abs(value))
    return value, spread


def _floor_bound(F: ExponentialPolynomial) -> float:
    """Return a σ below every crossing: where one term dominates all others on the torus."""
    r = F.basis
    weights = F.exponents @ r
    low = int(np.argmin(weights))
    for sigma in -np.logspace(-2, 8, 200):
        size = np.abs(F.coefficients) * np.exp(sigma * weights)
        if size[low] > 2 * (np.sum(size) - size[low]):
            return float(sigma)
    return -1e8
