r"""Eigenvalues of closed discrete port-Hamiltonian systems, and their condition numbers.

Every closed loop of a :class:`~phdesign.numeric.phs.DiscretePHS` is a pencil
:math:`(A_K, E)` with :math:`A_K` = ``closed_matrix(K)`` and :math:`E = E^\top \succ 0`.
When E is well conditioned it is cheaper, and as accurate, to whiten it once per
discretization: with the Cholesky factor :math:`E = W W^\top` and :math:`\hat c = W^\top
\hat e`,

.. math::

    \dot{\hat c} = W^{-1} (J - R) W^{-\top} \hat c + W^{-1} B u, \qquad
    y = (W^{-1} B)^\top \hat c + D u,

a port-Hamiltonian system again (:math:`W^{-1} J W^{-\top}` skew, :math:`W^{-1} R
W^{-\top} \succeq 0`, unit mass), whose closed loops are standard eigenproblems (Hessenberg
QR instead of QZ, about half the time at 40 to 60 states).  The price is accuracy on the
graded matrices of a Galerkin discretization: QZ, even with E = I, keeps the slow modes
to round-off where Hessenberg QR loses three to four digits (beam plant at degree 30,
every mode at Re λ = −0.1: QZ to 3e-16, QR to 1.1e-12; the cluster of condition 390 of the
beam's error system at L = diag(0.17548, 1.02567): QZ 3.9e-10, QR 2.0e-9 from the mpmath
root).  So searches (tuning, gain maps) whiten and reports
(:func:`phdesign.numeric.spectrum.spectrum`) keep QZ.  Whitening does not pay when E
is badly conditioned: the trace-scaled Legendre basis of order N >= 3 has a diagonal E of
condition 1e14 on purpose (:mod:`phdesign.numeric.galerkin`), and whitening it would undo
the scaling; such systems keep the QZ algorithm.  The threshold
:data:`WHITEN_MAX_CONDITION` is where the whitened problem's backward error
:math:`\epsilon\, \mathrm{cond}(E)^{1/2} \|A\|` stays below what the QZ algorithm gets.

The condition number reported with an eigenvalue is the one of the energy norm,

.. math::

    \kappa = \frac{\|x\|_E \, \|y\|_E}{|y^* E x|}, \qquad A x = \lambda E x, \quad
    y^* A = \lambda y^* E,

1 for an operator :math:`E^{-1} A` normal in the energy inner product, large near a
coalescence of eigenvalues.  For a whitened system :math:`\|\cdot\|_E` is the Euclidean
norm and the left eigenvectors are the rows of :math:`X^{-1}`, so that
:math:`\kappa_i = \|x_i\| \, \|(X^{-1})_{i,:}\|` costs one eigendecomposition and one
inverse.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sl

from phdesign.numeric.phs import DiscretePHS

__all__ = [
    "WHITEN_MAX_CONDITION",
    "PreparedSystem",
    "eigen_condition",
    "prepare",
    "rescaled",
    "whiten",
]

#: Largest condition number of E for which :func:`prepare` whitens the mass matrix.
WHITEN_MAX_CONDITION = 1e6


def rescaled(lam: np.ndarray, factor: float) -> np.ndarray:
    """``factor * lam`` for the finite eigenvalues; infinite or undefined ones become ``inf``.

    Examples
    --------
    >>> rescaled(np.array([1 + 1j, complex(np.inf, np.nan)]), 2.0).tolist()
    [(2+2j), (inf+0j)]
    """
    lam = np.asarray(lam, dtype=complex)
    finite = np.isfinite(lam)
    out = np.full(lam.shape, complex(np.inf, 0.0))
    out[finite] = lam[finite] * factor
    return out


def eigen_condition(A: np.ndarray, E: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    r"""Eigenvalues of the pencil (A, E) and their energy-norm condition numbers.

    ``E=None`` means the identity (a whitened system).  Eigenvalues at infinity (a
    singular E) get condition number ``inf``.

    Examples
    --------
    >>> lam, kappa = eigen_condition(np.array([[0.0, 1.0], [-1.0, 0.0]]))
    >>> np.round(kappa, 12).tolist()  # a skew matrix is normal
    [1.0, 1.0]
    >>> lam, kappa = eigen_condition(np.array([[1.0, 1e4], [0.0, 1.0 + 1e-6]]))
    >>> bool(kappa.min() > 1e9)  # nearly defective
    True
    """
    if E is None:
        lam, X = np.linalg.eig(A)
        try:
            Xinv = np.linalg.inv(X)
        except np.linalg.LinAlgError:
            return lam, np.full(lam.shape, np.inf)
        with np.errstate(over="ignore", invalid="ignore"):
            kappa = np.linalg.norm(X, axis=0) * np.linalg.norm(Xinv, axis=1)
        return lam, np.where(np.isfinite(kappa), kappa, np.inf)
    lam, Vl, Vr = sl.eig(A, E, left=True, right=True)
    EVr = E @ Vr
    num = np.sqrt(np.abs(np.einsum("ij,ij->j", Vr.conj(), EVr)))
    num *= np.sqrt(np.abs(np.einsum("ij,ij->j", Vl.conj(), E @ Vl)))
    den = np.abs(np.einsum("ij,ij->j", Vl.conj(), EVr))
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = np.where((den > 0) & np.isfinite(lam), num / den, np.inf)
    return lam, kappa


def whiten(d: DiscretePHS) -> DiscretePHS:
    r"""Return the congruent system with unit mass, :math:`\hat c = W^\top \hat e`.

    With the Cholesky factor :math:`E = W W^\top` (module docstring).

    Every field is transformed (E, J, R, B and the effort, projection and displacement
    maps), so the result is a complete :class:`DiscretePHS` of the same model.

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> from phdesign.numeric.discretize import discretize
    >>> d = discretize(to_numeric(load_builtin("wave"), {"rho": 4}), "galerkin", 6)
    >>> w = whiten(d)
    >>> bool(np.allclose(w.E, np.eye(w.dim))), bool(np.allclose(w.J, -w.J.T))
    (True, True)
    """
    W = np.linalg.cholesky(d.E)

    def left(M: np.ndarray) -> np.ndarray:  # W^-1 M
        return np.asarray(sl.solve_triangular(W, M, lower=True))

    def congruence(M: np.ndarray) -> np.ndarray:  # W^-1 M W^-T
        return left(left(M).T).T

    Winv_T = left(np.eye(d.dim)).T

    def effort_basis(z: np.ndarray) -> np.ndarray:
        return np.asarray(d.effort_basis(z) @ Winv_T)

    def project(x0: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        return np.asarray(W.T @ d.project(x0))

    displacement = None
    if d.displacement_basis is not None:
        base = d.displacement_basis

        def displacement(z: np.ndarray) -> np.ndarray:
            return np.asarray(base(z) @ Winv_T)

    J = congruence(d.J)
    R = congruence(d.R)
    return dataclasses.replace(
        d,
        E=np.eye(d.dim),
        J=0.5 * (J - J.T),
        R=0.5 * (R + R.T),
        B=left(d.B),
        effort_basis=effort_basis,
        project=project,
        displacement_basis=displacement,
        info={**d.info, "whitened": True},
    )


@dataclass(frozen=True)
class PreparedSystem:
    """A discretization prepared once for many closed-loop eigenproblems.

    Attributes
    ----------
    system : DiscretePHS
        The system whose pencils are solved: :func:`whiten`-ed (unit mass) when that
        pays, the original otherwise.
    whitened : bool
        Whether ``system.E`` is the identity (standard eigenproblems).
    """

    system: DiscretePHS
    whitened: bool

    @property
    def dim(self) -> int:
        """Number of discrete states."""
        return self.system.dim

    def eigvals(self, K: np.ndarray | None = None) -> np.ndarray:
        """Eigenvalues of the closed loop ũ = −K ỹ (``K=None``: u = 0)."""
        A = self.system.closed_matrix(K)
        if self.whitened:
            return np.asarray(sl.eigvals(A, overwrite_a=True, check_finite=False))
        return np.asarray(sl.eigvals(A, self.system.E, check_finite=False))

    def eigen_condition(self, K: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Eigenvalues and energy-norm condition numbers of the closed loop."""
        A = self.system.closed_matrix(K)
        return eigen_condition(A, None if self.whitened else self.system.E)


def prepare(d: DiscretePHS, whitened: bool = True) -> PreparedSystem:
    """Whiten ``d`` when its mass matrix is well conditioned (module docstring).

    ``whitened=False`` keeps the QZ algorithm whatever E is: it is the accurate choice
    for a report (module docstring), the whitened one the fast choice for a search.
    """
    E = d.E
    if not whitened:
        return PreparedSystem(d, False)
    if np.array_equal(E, np.eye(d.dim)):
        return PreparedSystem(d, True)
    if np.linalg.cond(E) <= WHITEN_MAX_CONDITION:
        return PreparedSystem(whiten(d), True)
    return PreparedSystem(d, False)
