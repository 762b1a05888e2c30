r"""Spurious modes of the weakly imposed boundary inputs, and the Galerkin space without them.

The Legendre-Galerkin method of :mod:`phdesign.numeric.discretization.galerkin` builds

.. math::

    E \dot{\hat e} = (J - R)\hat e + B u, \qquad y = B^\top \hat e,

with the state's own input traces :math:`U T \hat e` replaced by the imposed input u.
When a component of e has all its boundary traces among the inputs (a string with
velocity inputs at both ends, a clamped-clamped beam), the weak form never sees that
component's top Legendre modes except through those forgotten traces: they form a
subspace :math:`\mathcal O` that produces no output and that the dynamics maps into
itself.  Such an *unobservable* subspace is invariant under every output feedback
:math:`u = -K y`, so its eigenvalues (0 for the string, :math:`-d` for a beam with
viscous damping d, :math:`\pm i` for a Timoshenko beam whose two Dirichlet components are
coupled by :math:`P_0`) appear in the spectrum of every closed loop, at every degree,
well conditioned: the drift test of the spectrum calls them resolved.

They are artefacts.  A continuum eigenmode with u = 0 and y = 0 has all its traces zero
(the stacked ports (U; Y) are invertible), and :math:`\lambda \mathcal H^{-1} e = \sum_k
P_k \partial^k e` with zero Cauchy data and :math:`P_N` invertible forces e = 0: the
continuum has no unobservable mode at any :math:`\lambda`.

**Where they are.**  Let :math:`A_D = \sum_{k \ge 1} \int \Psi^\top P_k \partial^k \Psi`
(the differential part, no ports) in the orthonormal Legendre coordinates, and
:math:`G` the Gram matrix (the identity there).  From the energy identity
:math:`A + A^\top = T^\top (U^\top Y + Y^\top U) T + 2 \int \Psi^\top \operatorname{sym}
(P_0)\Psi` one gets, for :math:`Y T z = 0`,

.. math::

    (J - R - \lambda E) z = 0 \iff z^\top \big(A_D - P_0^\top \otimes G + \lambda E\big) = 0 .

For constant :math:`\mathcal H` the matrix in brackets is block upper triangular in the
polynomial degree, with diagonal blocks :math:`\lambda \mathcal H^{-1} - P_0^\top`, so an
unobservable eigenvalue must make that block singular: :math:`\lambda \in
\operatorname{eig}(\mathcal H P_0^\top)`, n candidates.  Each candidate is then decided on
a well-scaled matrix: the left null space of :math:`[M_\lambda X \,|\, (YT)^\top]` is
invariant under any invertible :math:`X`, and with X the trial functions whose N-th
derivative is the orthonormal :math:`\psi_{l-N}` (N-fold integrals, exact by
:func:`numpy.polynomial.legendre.legint`) every entry is O(1) instead of
:math:`O(p^{2N})`.  Columns are normalized (which does not change a left null space), so
the decision is independent of the scales of H, of the interval and of the outputs.  Its
singular values are :math:`\sim 10^{-16}` on the artefacts and :math:`\ge 10^{-3}`
elsewhere (measured up to degree 110 for N = 1, 2, 3); the threshold is
:data:`RANK_TOL` = 1e-9.  :math:`\lambda = 0` does not involve E and is exact for any
:math:`\mathcal H(z)`; for a varying :math:`\mathcal H` the other candidates are computed
with :math:`\mathcal H` frozen at the midpoint (the subspace is structural: e.g. the top
modes of two Dirichlet components coupled by :math:`P_0`; with :math:`\mathcal H(z)`
itself the discretization keeps an exactly unobservable pair nearby, which the frozen
subspace removes).

**The fix.**  With W a basis of the E-orthogonal complement of :math:`\mathcal O`, the
Galerkin method on the trial space :math:`\Psi W` has :math:`W^\top E W`,
:math:`W^\top J W`, :math:`W^\top R W`, :math:`W^\top B`: still port-Hamiltonian with
the same exact energy balance.  Because :math:`\mathcal O` is invariant under every
closed loop :math:`E^{-1}(J - R - B K B^\top)` and lies in :math:`\ker B^\top`, the
closed-loop matrix is block triangular in :math:`(\mathcal O, W)` and the spectrum splits
exactly: eig(full) = eig(restricted) ∪ eig(:math:`\mathcal O`) for every K, and the
input-output map is unchanged.  W is the identity minus the removed coordinates whenever
:math:`\mathcal O` is spanned by coordinate vectors E-orthogonal to the others (constant
diagonal H; diagonal E of the trace-scaled basis kept diagonal), otherwise those columns
get a rank-r correction.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import scipy.linalg as sl
from numpy.polynomial import legendre as leg

from phdesign.core.text import html_table
from phdesign.numeric.bridge import NumericModel

__all__ = ["RANK_TOL", "SpuriousModes", "e_orthogonal_complement", "spurious_modes"]

#: Relative pivot below which a direction of the normalized test matrix is a null vector.
RANK_TOL = 1e-9


@dataclass(frozen=True, repr=False)
class SpuriousModes:
    """The unobservable subspace of a Galerkin discretization (module docstring).

    Attributes
    ----------
    basis : ndarray (dim, r)
        Orthonormal basis in orthonormal-Legendre coordinates (component-major).
    eigenvalues : tuple of complex
        One eigenvalue per removed dimension (conjugate pairs both listed).
    frozen : bool
        Some eigenvalues were computed with H frozen at the midpoint (varying H).
    """

    basis: np.ndarray = field(repr=False)
    eigenvalues: tuple[complex, ...] = ()
    frozen: bool = False

    @property
    def count(self) -> int:
        """Number of removed dimensions."""
        return int(self.basis.shape[1])

    def to_dict(self) -> dict[str, object]:
        """JSON-ready summary: count, distinct eigenvalues as ``[re, im]``, frozen."""
        return {
            "count": self.count,
            "eigenvalues": [[z.real, z.imag] for z in _distinct(self.eigenvalues)],
            "frozen": self.frozen,
        }

    def __repr__(self) -> str:
        values = ", ".join(_format_eigenvalue(z) for z in _distinct(self.eigenvalues)[:4])
        return f"SpuriousModes(count={self.count}, eigenvalues=[{values}])"

    def __str__(self) -> str:
        return self.describe()

    def _repr_html_(self) -> str:
        return html_table((), [("spurious modes", self.describe())])

    def describe(self) -> str:
        """One sentence for reports: how many modes were removed and why."""
        if not self.count:
            return "no spurious modes"
        values = ", ".join(_format_eigenvalue(z) for z in _distinct(self.eigenvalues))
        frozen = " (H frozen at the midpoint)" if self.frozen else ""
        return (
            f"{self.count} spurious Galerkin mode{'s' if self.count > 1 else ''} removed: "
            f"unobservable (zero output for every input and gain) at eigenvalue "
            f"{values}{frozen}, an artefact of the weakly imposed inputs that no "
            "continuum mode matches"
        )


def _format_eigenvalue(z: complex) -> str:
    if abs(z.imag) <= 1e-12 * max(1.0, abs(z)):
        return f"{z.real:.6g}"
    return f"{z.real:.6g}{z.imag:+.6g}i"


def _distinct(values: tuple[complex, ...]) -> list[complex]:
    out: list[complex] = []
    for z in values:
        if not any(abs(z - w) <= 1e-9 * max(1.0, abs(z)) for w in out):
            out.append(z)
    return out


@lru_cache(maxsize=32)
def integrated_trial_derivatives(p: int, order: int, length: float) -> tuple[np.ndarray, ...]:
    r"""Coefficients of :math:`\partial_z^k \chi_l` in the orthonormal Legendre basis.

    :math:`\chi_l = \psi_l` for l < N and the N-fold integral from a of
    :math:`\psi_{l-N}` for l >= N, so that :math:`\chi_l^{(N)} = \psi_{l-N}`.  Returns
    ``(X_0, ..., X_N)``, each ``(p + 1, p + 1)``; column l holds :math:`\chi_l^{(k)}`.
    Integration of a Legendre series is exact and well conditioned (``legint``), so
    every entry is O(1) whatever the degree.
    """
    nb = p + 1
    norm = np.sqrt((2.0 * np.arange(nb + order) + 1.0) / length)
    out = []
    for k in range(order + 1):
        X = np.zeros((nb, nb))
        for col in range(nb):
            c: np.ndarray
            if col < order:
                c = np.zeros(col + 1)
                c[col] = norm[col]
                c = leg.legder(c, k) * (2.0 / length) ** k if k else c
            else:
                m = col - order
                c = np.zeros(m + 1)
                c[m] = norm[m]
                if order > k:
                    c = leg.legint(c, order - k, lbnd=-1) * (length / 2.0) ** (order - k)
            X[: min(c.size, nb), col] = c[:nb]
        X /= norm[:nb, None]
        X.setflags(write=False)
        out.append(X)
    return tuple(out)


def _candidates(H: np.ndarray, P0: np.ndarray) -> list[complex]:
    """Distinct eigenvalues of H P0^T in the closed upper half-plane (0 when P0 is singular)."""
    mu = np.linalg.eigvals(H @ P0.T)
    scale = float(np.max(np.abs(mu)))
    out: list[complex] = []
    for value in mu:
        z = complex(value)
        if abs(z) <= 1e-12 * scale:
            z = 0j
        elif abs(z.imag) <= 1e-12 * scale:
            z = complex(z.real, 0.0)
        if z.imag < 0 or any(abs(z - w) <= 1e-9 * max(scale, abs(z)) for w in out):
            continue
        out.append(z)
    return out


def _left_null(M: np.ndarray) -> np.ndarray:
    """Orthonormal left null space of ``M`` after normalizing its columns."""
    norms = np.linalg.norm(M, axis=0)
    keep = norms > 1e-14 * float(np.max(norms))
    Mn = M[:, keep] / norms[keep]
    Q, R, _ = sl.qr(Mn, mode="full", pivoting=True)
    pivots = np.abs(np.diag(R))
    rank = int(np.sum(pivots > RANK_TOL * pivots[0])) if pivots.size else 0
    Z = Q[:, rank:]
    # Round-off entries of an exact structural null vector are set to zero, so that a
    # coordinate vector stays one and its complement is a plain selection.
    Z = np.where(np.abs(Z) > 1e-13 * np.max(np.abs(Z), axis=0, initial=0.0), Z, 0.0)
    return Z


def spurious_modes(
    nm: NumericModel,
    degree: int,
    T_legendre: np.ndarray,
    zeroth_order: np.ndarray | None = None,
    frozen: tuple[np.ndarray, np.ndarray] | None = None,
) -> SpuriousModes:
    """Return the unobservable subspace of the degree-``degree`` Galerkin discretization.

    Parameters
    ----------
    nm : NumericModel
    degree : int
        Polynomial degree p.
    T_legendre : ndarray (2 N n, n (p + 1))
        Trace map in orthonormal-Legendre coordinates.
    zeroth_order : ndarray (n (p + 1), n (p + 1)), optional
        Galerkin matrix of the zeroth-order term, ∫ Ψᵀ P_0 Ψ in the same coordinates;
        default ``P_0 ⊗ I`` (constant P_0).  A z-dependent P_0 passes its quadrature.
    frozen : (H, P0), optional
        The constant H and P_0 that give the candidate eigenvalues; default both at the
        midpoint of the interval (exact when they are constant).

    Returns
    -------
    SpuriousModes
    """
    N, n, p = nm.order, nm.size, int(degree)
    a, b = nm.interval
    X = integrated_trial_derivatives(p, N, float(b - a))
    AD = sum(np.kron(nm.P[k], X[k]) for k in range(1, N + 1) if np.any(nm.P[k]))
    if zeroth_order is None:
        base = np.asarray(AD) - np.kron(nm.P[0].T, X[0])
    else:
        base = np.asarray(AD) - zeroth_order.T @ np.kron(np.eye(n), X[0])
    YT = nm.Y @ T_legendre
    H, P0 = frozen if frozen is not None else (nm.H_at(np.array([0.5 * (a + b)]))[0], nm.P[0])
    exact = nm.H_constant and zeroth_order is None
    columns: list[np.ndarray] = []
    eigenvalues: list[complex] = []
    was_frozen = False
    for lam in _candidates(H, P0):
        M = base if lam == 0 else base + lam * np.kron(np.linalg.inv(H), X[0])
        Z = _left_null(np.hstack([M, YT.T.astype(M.dtype)]))
        if not Z.shape[1]:
            continue
        was_frozen = was_frozen or (lam != 0 and not exact)
        if lam.imag:
            columns += [Z.real, Z.imag]
            eigenvalues += [lam, lam.conjugate()] * Z.shape[1]
        else:
            columns.append(Z.real)
            eigenvalues += [complex(lam.real, 0.0)] * Z.shape[1]
    if not columns:
        return SpuriousModes(np.zeros((n * (p + 1), 0)))
    V = np.hstack(columns)
    U, s, _ = np.linalg.svd(V, full_matrices=False)
    rank = int(np.sum(s > 1e-8 * s[0]))
    basis = V if rank == V.shape[1] and _is_orthonormal(V) else U[:, :rank]
    return SpuriousModes(basis, tuple(eigenvalues[:rank]), was_frozen)


def _is_orthonormal(V: np.ndarray) -> bool:
    return bool(np.max(np.abs(V.T @ V - np.eye(V.shape[1]))) < 1e-12)


def e_orthogonal_complement(V: np.ndarray, E: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool]:
    r"""Basis W of :math:`\{w : V^\top E w = 0\}`, built from coordinate vectors.

    The r coordinates where V is best conditioned in the energy norm (column-pivoted QR
    of :math:`(E^{1/2}_{diag} V)^\top`) are dropped; each remaining coordinate vector
    :math:`e_j` becomes :math:`e_j - V (V^\top E V)^{-1} V^\top E e_j`.

    Returns
    -------
    W : ndarray (dim, dim - r)
    keep : ndarray of int
        The coordinate j behind each column of W.
    selection : bool
        True when no correction was needed: W is exactly ``I[:, keep]``, so that
        restricted matrices are exact sub-blocks.
    """
    dim, r = V.shape
    weighted = V * np.sqrt(np.diag(E))[:, None]
    _, _, piv = sl.qr(weighted.T, pivoting=True)
    keep = np.setdiff1d(np.arange(dim), piv[:r])
    EV = E @ V
    coupling = EV[keep]  # (dim - r, r): V^T E e_j for the kept j
    W = np.zeros((dim, keep.size))
    W[keep, np.arange(keep.size)] = 1.0
    if not np.any(coupling):
        return W, keep, True
    W -= V @ np.linalg.solve(V.T @ EV, coupling.T)
    return W, keep, False
