r"""The result type of every discretization: a finite-dimensional port-Hamiltonian system.

.. math::

    E \dot{\hat e} = (J - R) \hat e + B u, \qquad y = B^\top \hat e + D u,
    \qquad H_d = \tfrac12 \hat e^\top E \hat e,

with :math:`E = E^\top \succ 0`, :math:`J = -J^\top`, :math:`R = R^\top \succeq 0` and
:math:`D = -D^\top`, so that :math:`\dot H_d = -\hat e^\top R \hat e + u^\top y` exactly.
It lives apart from :mod:`phdesign.numeric.discretize` so that the methods, which build
it, and the dispatcher, which calls them, do not import each other.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.errors import ObserverError, check_shape
from phdesign.numeric.bridge import NumericModel

__all__ = ["DiscretePHS", "feedback_matrix"]


@dataclass(frozen=True)
class DiscretePHS:
    r"""A finite-dimensional port-Hamiltonian system in effort coordinates.

    .. math::

        E \dot{\hat e} = (J - R) \hat e + B u, \quad y = B^\top \hat e + D u,
        \quad H_d = \tfrac12 \hat e^\top E \hat e .

    Parameters
    ----------
    model : NumericModel
        The model it discretizes.
    method : str
        ``"galerkin"`` or ``"fd"``.
    resolution : int
        Polynomial degree (Galerkin) or nodes per group (finite differences).
    E, J, R, B, D : ndarray
        Mass (``E ≻ 0``), structure (skew), dissipation (``⪰ 0``), input, feedthrough
        (skew) matrices.
    effort_basis : callable
        ``effort_basis(z) -> (m, n, dim)``: e(z) = effort_basis(z) @ ê.
    project : callable
        ``project(x0) -> ê`` for a vectorized initial state ``x0(z) -> (m, n)``.
    displacement_basis : callable or None
        ``displacement_basis(z) -> (m, dim)``: w(z) = displacement_basis(z) @ ê.
    """

    model: NumericModel
    method: str
    resolution: int
    E: np.ndarray
    J: np.ndarray
    R: np.ndarray
    B: np.ndarray
    D: np.ndarray
    effort_basis: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    project: Callable[[Callable[[np.ndarray], np.ndarray]], np.ndarray] = field(repr=False)
    displacement_basis: Callable[[np.ndarray], np.ndarray] | None = field(default=None, repr=False)
    info: dict[str, Any] = field(default_factory=dict, compare=False, repr=False)

    @property
    def dim(self) -> int:
        """Number of discrete states."""
        return int(self.E.shape[0])

    @property
    def n_ports(self) -> int:
        """Number of inputs (= outputs)."""
        return int(self.B.shape[1])

    def hamiltonian(self, ehat: np.ndarray) -> np.ndarray:
        """Discrete energy ½ êᵀ E ê; ``ehat`` of shape ``(dim,)`` or ``(nt, dim)``."""
        eh = np.asarray(ehat)
        return 0.5 * np.einsum("...i,ij,...j->...", eh, self.E, eh)

    def output(self, ehat: np.ndarray, u: np.ndarray | None = None) -> np.ndarray:
        """Y = Bᵀ ê + D u (row-wise for stacked ``ehat``)."""
        y = np.asarray(ehat) @ self.B
        if u is not None:
            y = y + np.asarray(u) @ self.D.T
        return y

    def closed_matrix(self, K: np.ndarray | None = None) -> np.ndarray:
        """Right-hand matrix of the closed loop ũ = −K ỹ (``K=None``: u = 0).

        With ỹ = Bᵀ ê + D ũ the loop gives ũ = −(I + K D)⁻¹ K Bᵀ ê, hence
        ``E ê' = (J − R − B (I + K D)⁻¹ K Bᵀ) ê``.
        """
        A = self.J - self.R
        if K is None:
            return A
        check_shape("K = C_m^T L C_m", np.asarray(K), (self.n_ports, self.n_ports))
        M = np.eye(self.n_ports) + K @ self.D
        return A - self.B @ np.linalg.solve(M, K @ self.B.T)

    def standard_form(self, K: np.ndarray | None = None) -> np.ndarray:
        """E⁻¹ times :meth:`closed_matrix` (dense)."""
        return np.linalg.solve(self.E, self.closed_matrix(K))

    def check_structure(self) -> dict[str, float]:
        """Return the structural residuals: skewness of J and D, symmetry and signs."""

        def rel(x: np.ndarray, ref: np.ndarray) -> float:
            return float(np.max(np.abs(x)) / max(np.max(np.abs(ref)), 1e-300))

        return {
            "J_skew": rel(self.J + self.J.T, self.J),
            "R_sym": rel(self.R - self.R.T, self.R) if np.any(self.R) else 0.0,
            "E_sym": rel(self.E - self.E.T, self.E),
            "D_skew": rel(self.D + self.D.T, self.D) if np.any(self.D) else 0.0,
            "R_min_eig": float(np.min(np.linalg.eigvalsh(self.R))) if self.dim else 0.0,
            "E_min_eig": float(np.min(np.linalg.eigvalsh(self.E))),
        }


def feedback_matrix(C_m: np.ndarray, L: np.ndarray, n_outputs: int) -> np.ndarray:
    """Return K = C_mᵀ L C_m, checking shapes and L + Lᵀ ≻ 0.

    Examples
    --------
    >>> feedback_matrix(np.array([[0.0, 1.0]]), np.array([[2.0]]), 2)
    array([[0., 0.],
           [0., 2.]])
    """
    C = np.atleast_2d(np.asarray(C_m, dtype=float))
    q = C.shape[0]
    check_shape("C_m", C, (q, n_outputs))
    Lm = np.atleast_2d(np.asarray(L, dtype=float))
    check_shape("L", Lm, (q, q))
    if not np.all(np.isfinite(Lm)):
        raise ObserverError("L must be finite")
    if q and np.min(np.linalg.eigvalsh(Lm + Lm.T)) <= 0:
        raise ObserverError("L + L^T must be positive definite; found a non-positive eigenvalue")
    return C.T @ Lm @ C
