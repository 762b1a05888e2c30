r"""Locate a coalescence of eigenvalues exactly: the polish of an abscissa optimum.

With q gains the abscissa is typically minimized where m = q + 1 eigenvalues coalesce
(the paper's beam, q = 2: three real eigenvalues at -5.8334).  There the eigenvalues are
ill-conditioned, each computed only to :math:`(\epsilon \|A\|)^{1/m}`, and a direct
search on the abscissa stalls far from the point.  Their *symmetric functions* are
well-conditioned: the computed eigenvalues are exact for a matrix within
:math:`\epsilon \|A\|` of the true one, and the central moments of the cluster

.. math::

    M_k(L) = \frac1m \sum_{i=1}^m (\lambda_i - \mu)^k, \quad
    \mu = \frac1m \sum_{i=1}^m \lambda_i, \qquad k = 2, \dots, m,

are smooth in L as long as the cluster stays apart from the rest of the spectrum; they
all vanish exactly at an m-fold eigenvalue (for m = 3, :math:`M_2 = M_3 = 0` makes the
cluster's characteristic polynomial :math:`(x - \mu)^3`).  For m - 1 = q these are q
equations in the q log-gains, solved by Newton's method with a finite-difference
Jacobian; the abscissa there is :math:`\operatorname{Re}\mu`, accurate to
:math:`\epsilon \|A\|` where the individual eigenvalues are not.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = ["Coalescence", "cluster_of", "polish_coalescence"]

_CLUSTER = 5e-2  # relative radius within which eigenvalues belong to the rightmost cluster


@dataclass(frozen=True)
class Coalescence:
    """An m-fold eigenvalue located by :func:`polish_coalescence`.

    Attributes
    ----------
    size : int
        m, the number of coalescing eigenvalues.
    eigenvalue : complex
        μ, the mean of the cluster: the coalesced eigenvalue.
    residual : float
        max |M_k| at the returned parameters.
    parameters : ndarray
        Where it is attained.
    iterations : int
    """

    size: int
    eigenvalue: complex
    residual: float
    parameters: np.ndarray
    iterations: int


def cluster_of(lam: np.ndarray, lead: complex, scale: float) -> np.ndarray:
    """Return the indices of the eigenvalues within 5 % of ``lead``, grown transitively.

    Examples
    --------
    >>> cluster_of(np.array([-1.0, -1.01, -1.03, -3.0]), -1.0, 1.0).tolist()
    [0, 1, 2]
    """
    lam = np.asarray(lam)
    finite = np.isfinite(lam)
    radius = _CLUSTER * max(scale, abs(lead))
    members = np.zeros(lam.shape, dtype=bool)
    members[finite] = np.abs(lam[finite] - lead) <= radius
    while True:
        near = finite & ~members
        if not near.any():
            break
        dist = np.min(np.abs(lam[near][:, None] - lam[members][None, :]), axis=1)
        grow = np.flatnonzero(near)[dist <= radius]
        if grow.size == 0:
            break
        members[grow] = True
    return np.flatnonzero(members)


def _moments(cluster: np.ndarray) -> tuple[complex, np.ndarray]:
    mu = complex(np.mean(cluster))
    m = cluster.size
    return mu, np.array([np.mean((cluster - mu) ** k).real for k in range(2, m + 1)])


def polish_coalescence(
    eigenvalues: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    lead: complex,
    *,
    scale: float,
    max_iterations: int = 30,
    step: float = 1e-6,
) -> Coalescence | None:
    """Newton's method on the central moments of the rightmost cluster (module docstring).

    Parameters
    ----------
    eigenvalues : callable
        ``eigenvalues(x)``: every eigenvalue of the closed loop at parameters x (log-gains).
    x0 : ndarray (q,)
        Start, near the coalescence.
    lead : complex
        The rightmost resolved eigenvalue at ``x0`` (the cluster is grown around it; the
        unresolved high frequencies of a discretization may lie further right).
    scale : float
        The problem's rate: the cluster radius and the residual are relative to it.

    Returns
    -------
    Coalescence or None
        None when the q + 1 eigenvalues nearest ``lead`` are not closed under conjugation
        or not apart from the rest (the next one at least twice as far), or when Newton's
        method does not converge.
    """
    x = np.asarray(x0, dtype=float).copy()
    q = x.size

    m = q + 1
    lam = eigenvalues(x)
    lam = lam[np.isfinite(lam)]
    order = np.argsort(np.abs(lam - lead))
    if lam.size <= m:
        return None
    cluster, nxt = lam[order[:m]], lam[order[m]]
    spread = float(np.max(np.abs(cluster - lead)))
    # the cluster must be closed under conjugation (real moments) and apart from the rest
    if (
        abs(float(np.sum(cluster.imag))) > 1e-8 * max(scale, abs(lead))
        or abs(nxt - lead) < 2 * spread
    ):
        return None
    centre = complex(np.mean(cluster))

    def residual(x: np.ndarray) -> tuple[complex, np.ndarray]:
        lam = eigenvalues(x)
        lam = lam[np.isfinite(lam)]
        # follow the same m eigenvalues: the m nearest the current centre
        near = lam[np.argsort(np.abs(lam - centre))[:m]]
        return _moments(near)

    mu, F = residual(x)
    norm = float(np.max(np.abs(F)))
    iterations = 0
    while iterations < max_iterations:
        iterations += 1
        J = np.empty((q, q))
        for j in range(q):
            h = np.zeros(q)
            h[j] = step
            J[:, j] = (residual(x + h)[1] - residual(x - h)[1]) / (2 * step)
        try:
            dx = np.linalg.solve(J, -F)
        except np.linalg.LinAlgError:
            return None
        t = 1.0
        while True:
            mu_new, F_new = residual(x + t * dx)
            norm_new = float(np.max(np.abs(F_new)))
            if norm_new < norm or t < 1e-4:
                break
            t *= 0.5
        if not norm_new < norm:
            break
        x, mu, F, norm = x + t * dx, mu_new, F_new, norm_new
        centre = mu
        if np.max(np.abs(t * dx)) < 1e-14 * max(1.0, float(np.max(np.abs(x)))):
            break
    if norm > 1e-6 * max(scale, abs(mu)) ** 2:
        return None
    return Coalescence(size=m, eigenvalue=mu, residual=norm, parameters=x, iterations=iterations)
