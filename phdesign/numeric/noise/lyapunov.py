r"""Stationary covariance and frequency response of a stable descriptor system.

For :math:`E \dot x = A x + G n`, :math:`E = E^\top \succ 0`, driven by unit white noise
(:math:`\mathbb E[n(t) n(s)^\top] = I \delta(t - s)`), the stationary covariance
:math:`P = \mathbb E[x x^\top]` solves the generalized Lyapunov equation

.. math::

    A P E^\top + E P A^\top + G G^\top = 0,

and the frequency response in the energy norm :math:`\|x\|_E^2 = x^\top E x` is
:math:`\sigma_{\max}\big(E^{1/2} (i\omega E - A)^{-1} G\big)`.

Both are computed on one triangular form of the pencil.  When E is well conditioned
(:math:`\kappa(E) \le 10^6`, the Legendre-Galerkin mass matrices of order 1 and 2) the
system is whitened, :math:`\xi = C^\top x` with :math:`E = C C^\top` (Cholesky), and
:math:`F = C^{-1} A C^{-\top}` is reduced to the complex Schur form
:math:`F = Z T Z^*`; the Lyapunov equation :math:`T X + X T^* = -Z^* C^{-1} G G^\top
C^{-\top} Z` is then LAPACK's triangular Sylvester solve (``ztrsyl``) and the energy norm
is the Euclidean norm of :math:`\xi`.  Otherwise (the trace-scaled basis of order
N >= 3 has a diagonal E with :math:`\kappa(E) \sim 10^{14}`, where whitening would undo
the scaling that keeps the pencil accurate) the pencil itself is reduced by the complex
QZ algorithm, :math:`A = Q T Z^*`, :math:`E = Q S Z^*`, and the generalized equation
:math:`T X S^* + S X T^* = -Q^* G G^\top Q`, :math:`P = Z X Z^*`, is solved column by
column from the last (a generalized Bartels-Stewart recursion): column j needs the
triangular solve

.. math::

    (\bar S_{jj} T + \bar T_{jj} S) X_{:j}
    = -\tilde C_{:j} - T \sum_{k>j} \bar S_{jk} X_{:k} - S \sum_{k>j} \bar T_{jk} X_{:k}.

Either way the solve is backward stable on the pencil; the forward error of a variance is
about :math:`\epsilon \|F\| / \mathrm{sep}`, with sep twice the distance of the spectrum to
the imaginary axis (beam, degree 100: a relative 1e-9 against scipy's
``solve_continuous_lyapunov`` on :math:`E^{-1}A`).

:func:`hamiltonian_hinf_norm` is the independent check of the frequency sweep: the
bisection of Boyd, Balakrishnan and Kabamba on the imaginary eigenvalues of the
Hamiltonian matrix of the standard form.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sl

from phdesign.core.errors import NumericError

__all__ = ["TriangularPencil", "hamiltonian_hinf_norm", "triangularize"]

#: Largest condition number of E for which the system is whitened (Schur path).
WHITEN_MAX_CONDITION = 1e6


@dataclass(frozen=True)
class TriangularPencil:
    r"""A stable descriptor system :math:`E x' = A x + G n` in triangular coordinates.

    ``x = V @ Z @ y`` maps triangular coordinates y to the original state x, where
    ``V`` is :math:`C^{-\top}` on the whitened path and the identity on the QZ path;
    ``T y' = S y + H n`` up to the unitary left factor, with ``S`` the identity on the
    whitened path.

    Attributes
    ----------
    T, S : ndarray (complex, upper triangular)
        The triangular pencil (``S`` is the identity after whitening).
    H : ndarray
        The noise input in triangular coordinates (``Q^* G`` or ``Z^* C^{-1} G``).
    Z : ndarray
        Right unitary factor.
    V : ndarray or None
        :math:`C^{-\top}` (whitened path) or None (identity).
    energy_map : ndarray or None
        ``R`` with :math:`\|x\|_E = \|R y\|`; None when the norm is Euclidean in y.
    whitened : bool
    """

    T: np.ndarray
    S: np.ndarray
    H: np.ndarray
    Z: np.ndarray
    V: np.ndarray | None
    energy_map: np.ndarray | None
    whitened: bool

    @property
    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of the pencil (A, E)."""
        return np.diag(self.T) / np.diag(self.S)

    def to_state(self, Y: np.ndarray) -> np.ndarray:
        """Map triangular coordinates (columns of ``Y``) to the original state."""
        X = self.Z @ Y
        return np.asarray(X if self.V is None else self.V @ X)

    def covariance(self) -> np.ndarray:
        r"""Return the stationary covariance: :math:`A P E^\top + E P A^\top + GG^\top = 0`."""
        C = self.H @ self.H.conj().T
        if self.whitened:
            X, scale, info = sl.lapack.ztrsyl(self.T, self.T, -C, tranb="C")
            if info < 0 or scale != 1.0:  # pragma: no cover - LAPACK guard
                raise NumericError(f"the triangular Lyapunov solve failed (info {info})")
        else:
            X = _generalized_triangular_lyapunov(self.T, self.S, C)
        P = self.to_state(self.to_state(X).conj().T).conj().T
        P = P.real
        return np.asarray(0.5 * (P + P.T))

    def channel_energies(self) -> np.ndarray | None:
        r"""Return :math:`\|R (sS - T)^{-1} h_k\|_2^2` for each input channel :math:`h_k`.

        The H₂ norms squared of the single channels, from the observability Gramian
        :math:`T^* Y + Y T + R^* R = 0` (one triangular Sylvester solve):
        :math:`h_k^* Y h_k`.  On the whitened path only (``None`` on the QZ path, and
        without an output map).
        """
        if not self.whitened or self.energy_map is None:
            return None
        RR = self.energy_map.conj().T @ self.energy_map
        Y, scale, info = sl.lapack.ztrsyl(self.T, self.T, -RR, trana="C")
        if info < 0 or scale != 1.0:  # pragma: no cover - LAPACK guard
            raise NumericError(f"the triangular Lyapunov solve failed (info {info})")
        return np.asarray(np.maximum(np.einsum("ik,ij,jk->k", self.H.conj(), Y, self.H).real, 0))

    def response(self, omega: np.ndarray) -> np.ndarray:
        r"""Largest singular value of the energy-norm frequency response at each ``omega``.

        :math:`\sigma_{\max}(R (i\omega S - T)^{-1} H)`, vectorized over the frequencies by
        one back substitution on the triangular pencil (:func:`_shifted_back_substitution`).
        """
        w = np.atleast_1d(np.asarray(omega, dtype=float))
        n, m = self.H.shape
        if n == 0 or m == 0:
            return np.zeros(w.size)
        # columns of Y: (input channel, frequency) pairs, frequency fastest
        Y = _shifted_back_substitution(self.T, None if self.whitened else self.S, self.H, w)
        if self.energy_map is not None:
            Y = self.energy_map @ Y
        top = _largest_gram_eigenvalues(Y.reshape(Y.shape[0], m, w.size))
        return np.asarray(np.sqrt(np.maximum(top, 0.0)))

    def response_at(self, omega: float, work: np.ndarray | None = None) -> float:
        r""":meth:`response` at one frequency, by one LAPACK triangular solve.

        ``work``, an array shaped and typed like ``T``, holds the shifted matrix
        :math:`i\omega S - T` (a caller that evaluates many frequencies, a peak search,
        passes one and saves an allocation per frequency); it is overwritten.
        """
        if self.H.size == 0:
            return 0.0
        shifted = np.empty_like(self.T) if work is None else work
        if self.whitened:  # S is the identity: i omega on the diagonal only
            np.negative(self.T, out=shifted)
            shifted.flat[:: shifted.shape[0] + 1] += 1j * omega
        else:
            np.multiply(1j * omega, self.S, out=shifted)
            shifted -= self.T
        # LAPACK's trtrs as solve_triangular calls it (on the transpose of a C-ordered matrix)
        trtrs = sl.get_lapack_funcs("trtrs", (shifted, self.H))
        if shifted.flags.f_contiguous:
            Y, info = trtrs(shifted, self.H, lower=0, trans=0)
        else:
            Y, info = trtrs(shifted.T, self.H, lower=1, trans=1)
        if info != 0:  # pragma: no cover - a pole on the imaginary axis (stable pencils only)
            raise NumericError(f"the frequency response is singular at omega = {omega}")
        if self.energy_map is not None:
            Y = self.energy_map @ Y
        # sigma_max from the small Gram matrix (one column per noise channel)
        return float(np.sqrt(max(np.linalg.eigvalsh(Y.conj().T @ Y)[-1], 0.0)))


def _largest_gram_eigenvalues(Y: np.ndarray) -> np.ndarray:
    r"""Largest eigenvalue of :math:`Y_w^* Y_w` for each frequency w (``Y``: (n, m, w)).

    One or two channels in closed form, :math:`\tfrac12(a + b) + \sqrt{\tfrac14(a - b)^2
    + |c|^2}` for the Gram matrix [[a, c], [c̄, b]]; more by a batched eigensolve.
    """
    m = Y.shape[1]
    if m <= 2:
        a = np.sum(Y[:, 0].real ** 2 + Y[:, 0].imag ** 2, axis=0)
        if m == 1:
            return np.asarray(a)
        b = np.sum(Y[:, 1].real ** 2 + Y[:, 1].imag ** 2, axis=0)
        c = np.sum(Y[:, 0].conj() * Y[:, 1], axis=0)
        return np.asarray(0.5 * (a + b) + np.sqrt(0.25 * (a - b) ** 2 + np.abs(c) ** 2))
    gram = np.einsum("kaw,kbw->wab", Y.conj(), Y)
    return np.asarray(np.linalg.eigvalsh(gram)[:, -1])


#: Rows per block of :func:`_shifted_back_substitution` (its updates are matrix products).
_BLOCK = 16


def _shifted_back_substitution(
    T: np.ndarray, S: np.ndarray | None, H: np.ndarray, omega: np.ndarray
) -> np.ndarray:
    r"""Solve :math:`(i\omega_k S - T) Y_{jk} = H_j` for every channel j and frequency k.

    T and S upper triangular (``S=None``: the identity, the whitened path); the columns
    of the result are (channel, frequency) pairs, frequency fastest.  Every column has its
    own shift, so the diagonal blocks are solved row by row; the off-diagonal blocks of
    T and S are the same for every column, and their updates are matrix products over
    all columns at once (BLAS 3).
    """
    n, m = H.shape
    s = np.tile(1j * omega, m)
    Y = np.repeat(H.astype(complex), omega.size, axis=1)  # right-hand sides, then Y
    diagonal = np.diag(T)
    scale = np.ones(n, dtype=complex) if S is None else np.diag(S)
    for stop in range(n, 0, -_BLOCK):
        start = max(stop - _BLOCK, 0)
        if stop < n:
            Y[start:stop] += T[start:stop, stop:] @ Y[stop:]
            if S is not None:
                Y[start:stop] -= s * (S[start:stop, stop:] @ Y[stop:])
        for i in range(stop - 1, start - 1, -1):
            if i + 1 < stop:
                Y[i] += T[i, i + 1 : stop] @ Y[i + 1 : stop]
                if S is not None:
                    Y[i] -= s * (S[i, i + 1 : stop] @ Y[i + 1 : stop])
            Y[i] /= s * scale[i] - diagonal[i]
    return Y


def triangularize(
    A: np.ndarray, E: np.ndarray, G: np.ndarray, method: str = "auto"
) -> TriangularPencil:
    """Reduce :math:`E x' = A x + G n` to a :class:`TriangularPencil`.

    Parameters
    ----------
    A, E, G : ndarray
        ``E`` symmetric positive definite.
    method : {"auto", "schur", "qz"}
        ``"schur"`` whitens with the Cholesky factor of E, ``"qz"`` keeps the pencil;
        ``"auto"`` whitens when the condition number of E is at most
        :data:`WHITEN_MAX_CONDITION`.

    Examples
    --------
    >>> import numpy as np
    >>> tp = triangularize(np.array([[-1.0]]), np.array([[2.0]]), np.array([[1.0]]))
    >>> [round(float(v), 12) for v in (tp.eigenvalues[0].real, tp.covariance()[0, 0])]
    [-0.5, 0.25]
    """
    if method not in ("auto", "schur", "qz"):
        raise NumericError(f"unknown triangularization {method!r}; expected auto, schur or qz")
    if method == "auto":
        ev = np.linalg.eigvalsh(E)
        method = "schur" if ev[0] > 0 and ev[-1] <= WHITEN_MAX_CONDITION * ev[0] else "qz"
    if method == "schur":
        C = np.linalg.cholesky(E)
        F = sl.solve_triangular(C, A, lower=True)
        F = sl.solve_triangular(C, F.T, lower=True).T
        T, Z = sl.schur(F, output="complex")
        H = Z.conj().T @ sl.solve_triangular(C, G, lower=True)
        V = sl.solve_triangular(C, np.eye(C.shape[0]), lower=True).T
        S = np.eye(T.shape[0], dtype=complex)
        return TriangularPencil(T, S, H, Z, V, None, True)
    T, S, Q, Z = sl.qz(A, E, output="complex")
    energy = np.linalg.cholesky(E).T @ Z
    return TriangularPencil(T, S, Q.conj().T @ G, Z, None, energy, False)


def _generalized_triangular_lyapunov(T: np.ndarray, S: np.ndarray, C: np.ndarray) -> np.ndarray:
    """Solve ``T X S^* + S X T^* = -C`` for upper triangular T, S (module docstring)."""
    n = T.shape[0]
    X = np.zeros((n, n), dtype=complex)
    for j in range(n - 1, -1, -1):
        rhs = -C[:, j].astype(complex)
        if j + 1 < n:
            rhs -= T @ (X[:, j + 1 :] @ S[j, j + 1 :].conj())
            rhs -= S @ (X[:, j + 1 :] @ T[j, j + 1 :].conj())
        X[:, j] = sl.solve_triangular(S[j, j].conj() * T + T[j, j].conj() * S, rhs)
    return X


def hamiltonian_hinf_norm(
    F: np.ndarray, G: np.ndarray, rtol: float = 1e-10, imaginary_tol: float = 1e-8
) -> float:
    r"""H-infinity norm of :math:`\xi' = F \xi + G n`, output :math:`\xi`, by bisection.

    :math:`\gamma > \|(sI - F)^{-1} G\|_\infty` exactly when the Hamiltonian matrix

    .. math::

        \mathcal H_\gamma = \begin{bmatrix} F & \gamma^{-2} G G^\top \\ -I & -F^\top
        \end{bmatrix}

    has no eigenvalue on the imaginary axis (Boyd, Balakrishnan and Kabamba, 1989).  The
    supremum is over all frequencies: it serves as a check of a frequency sweep of a
    small, fully resolved system.  F must be Hurwitz.

    Examples
    --------
    >>> import numpy as np
    >>> round(hamiltonian_hinf_norm(np.array([[-2.0]]), np.array([[1.0]])), 8)  # 1/|iw + 2| at 0
    0.5
    """
    n = F.shape[0]
    GG = G @ G.T

    def has_imaginary(gamma: float) -> bool:
        ham = np.block([[F, GG / gamma**2], [-np.eye(n), -F.T]])
        ev = np.linalg.eigvals(ham)
        return bool(np.any(np.abs(ev.real) <= imaginary_tol * max(1.0, np.max(np.abs(ev)))))

    lo = float(np.linalg.norm(np.linalg.solve(-F, G), 2))  # the gain at omega = 0
    hi = max(2.0 * lo, 1e-300)
    while has_imaginary(hi):
        hi *= 2.0
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        if has_imaginary(mid):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
