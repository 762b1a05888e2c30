r"""The eigen stage: eigenvalues of dissipative pencils by shift and invert, with conditioning.

Every spectrum phdesign reports is that of a pencil :math:`(A, E)` with
:math:`E = E^\top \succ 0` whose eigenvalues all satisfy :math:`\operatorname{Re}\lambda
\le 0`: a closed loop ũ = −Kỹ of a :class:`~phdesign.numeric.discretization.phs.DiscretePHS` (``A``
=
``closed_matrix(K)``; with :math:`J = -J^\top`, :math:`R \succeq 0` and
:math:`\operatorname{sym}(K) \succeq 0`, an eigenpair gives
:math:`\operatorname{Re}\lambda\, x^* E x = -x^* R x - \tilde y^* \operatorname{sym}(K)
\tilde y \le 0`, the invariants the constructors check), or the assembled observer-based
loop, block-triangular with two such blocks (:mod:`phdesign.numeric.control.assembly`).  For a real
shift :math:`\sigma > 0` the matrix :math:`A - \sigma E` is therefore invertible, and

.. math::

    S = (A - \sigma E)^{-1} E, \qquad S x = \theta x \iff A x = \lambda E x, \quad
    \lambda = \sigma + \frac{1}{\theta}, \qquad |\theta| \le \frac{1}{\sigma} .

**Why.**  The Galerkin matrices are graded: the entries of :math:`A` grow like
:math:`p^{2N}` with the degree p (a damper on a derivative trace, the beam's tip torque,
adds :math:`p^4`), while the modes that decide the abscissa live in the low degrees.
The QZ algorithm has a *normwise* backward error :math:`\epsilon \|A\|` and gives every
eigenvalue an absolute error :math:`\sim \epsilon \|A\| \kappa`; the LU factorization of
:math:`A - \sigma E` errs row by row (:math:`|\Delta| \le \gamma_n |L||U|`), which the
geometrically decaying eigenvectors of the slow modes barely see, and the Hessenberg QR
of S errs by :math:`\epsilon \|S\|` in :math:`\theta`, i.e.

.. math::

    |\delta\lambda| \approx \epsilon\, \kappa\, \|S\|\, |\lambda - \sigma|^2 ,

small for the slow modes whatever :math:`\|A\|` is.  Measured against the mpmath root of
the characteristic determinant (beam, d = 0.2, tip torque damper u3 = −y3/2, the
controlled plant of ``tests/numeric/spectrum/test_eigen_accuracy.py``): QZ 4.6e-12, 1.1e-10,
1.6e-9,
5.8e-7 at degrees 30, 45, 68, 102 (:math:`\|A\|` from 1.5e8 to 2e11), shift and invert
6e-15, 1.4e-14, 1.4e-14, 2e-15.  The high, unresolved eigenvalues lose *relative*
accuracy instead (:math:`|\lambda| \gg \sigma`: about :math:`\epsilon |\lambda|^2 /
\sigma`); they are the ones the drift test (:mod:`phdesign.numeric.spectrum.drift`) discards.

**The shift.**  With :math:`\|S\| \approx 1/\min_j |\lambda_j - \sigma| \le 1/\sigma` the
error of a slow mode is about :math:`\epsilon \kappa |\lambda - \sigma|^2 / \sigma`,
smallest for :math:`\sigma = |\lambda|`.  The modes that decide the abscissa have
:math:`|\lambda|` of the order of the problem's rate s (:mod:`phdesign.numeric.scales`:
the first mode of a dimensionless problem lies at :math:`|\lambda| \sim \pi/2 \dots
2\pi`, the beam's rightmost ones between 1.5 and 6), so :math:`\sigma = s`
(:data:`SHIFT` = 1 in units of the rate): within a factor of about 2 of the best shift for
each of them, and safely away from the spectrum (:math:`|\lambda_j - \sigma| \ge \sigma`
for :math:`\operatorname{Re}\lambda_j \le 0`).  The measured errors above do not change
beyond round-off for :math:`\sigma/s` between 1/4 and 8.

**Speed.**  One LU factorization, one solve with n right-hand sides and one Hessenberg QR
(:math:`\approx 13 n^3` flops) against QZ's :math:`\approx 30 n^3`.  Measured on the
beam's error system at 22 to 92 states (one BLAS thread, CPU time): 1.3 to 1.5 times
faster than QZ for eigenvalues alone, 1.5 to 1.8 times with left and right eigenvectors
(condition numbers), and as fast as the Hessenberg QR of a Cholesky-whitened pencil that
searches used before (``benchmarks/spectrum.py`` prints the evaluator's throughput).

**Condition numbers.**  A shift changes no eigenvector: the right eigenvectors of S are
those of the pencil, and the left ones follow from :math:`w^* S = \theta w^*` as
:math:`y = (A - \sigma E)^{-*} w` (:math:`y^* A = \lambda y^* E`).  The condition number
reported with an eigenvalue is the one of the energy norm,

.. math::

    \kappa = \frac{\|x\|_E \, \|y\|_E}{|y^* E x|},

1 for an operator :math:`E^{-1} A` normal in the energy inner product, large near a
coalescence of eigenvalues; it does not depend on the shift.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sl
from scipy.linalg import lapack

from phdesign.core.errors import NumericError
from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.scales import problem_scales

__all__ = [
    "SHIFT",
    "PreparedSystem",
    "condition_numbers",
    "prepare",
    "rescaled",
    "roundoff_bound",
    "shift_invert",
    "system_shift",
]

#: The real shift of :func:`shift_invert`, in units of the problem's rate s (module docstring).
SHIFT = 1.0


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


def roundoff_bound(lam: np.ndarray, kappa: np.ndarray, rate: float, dim: int) -> np.ndarray:
    r"""Return the round-off bound of shift and invert's eigenvalues.

    :math:`n \epsilon \kappa \max(|\lambda|, |\lambda - \sigma|^2 / \sigma)`: a real part of
    either sign below it is round-off.

    The error model of the module docstring, :math:`|\delta\lambda| \approx \epsilon \kappa
    \|S\| |\lambda - \sigma|^2` with :math:`\|S\| \le 1/\sigma` (:math:`\sigma` = :data:`SHIFT`
    times the rate), times the pencil's dimension n: the backward errors of the LU
    factorization and of the Hessenberg QR grow like :math:`n \epsilon`.  A computed real
    part of either sign below it is round-off.  Measured on the airy plant (lossless: every
    exact real part is 0), the largest positive real part is 8.7, 13 and 62 times
    :math:`\epsilon \kappa |\lambda - \sigma|^2/\sigma` at n = 41, 62 and 93 (+1.45e3 at
    :math:`|\lambda|` = 1.29e9 for n = 41).

    Examples
    --------
    >>> float(roundoff_bound(np.array([1e9j]), np.array([1.0]), 1.0, 41)[0]) > 1.45e3
    True
    """
    lam = np.asarray(lam, dtype=complex)
    sigma = SHIFT * float(rate)
    k = np.minimum(np.asarray(kappa, dtype=float), 1e300)
    size = np.maximum(np.abs(lam), np.abs(lam - sigma) ** 2 / sigma)
    return np.asarray(int(dim) * np.finfo(float).eps * k * size)


def condition_numbers(X: np.ndarray, Y: np.ndarray, E: np.ndarray | None) -> np.ndarray:
    r"""Energy-norm condition numbers :math:`\|x\|_E \|y\|_E / |y^* E x|` of eigenpairs.

    ``X`` and ``Y`` hold right and left eigenvectors of the pencil column by column;
    ``E=None`` is the identity.  A vanishing :math:`y^* E x` (a defective eigenvalue) gives
    ``inf``.
    """
    EX = X if E is None else E @ X
    EY = Y if E is None else E @ Y
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        num = np.sqrt(np.abs(np.einsum("ij,ij->j", X.conj(), EX)))
        num *= np.sqrt(np.abs(np.einsum("ij,ij->j", Y.conj(), EY)))
        den = np.abs(np.einsum("ij,ij->j", Y.conj(), EX))
        kappa = num / den
    return np.where((den > 0) & np.isfinite(kappa), kappa, np.inf)


def shift_invert(
    A: np.ndarray, E: np.ndarray | None = None, *, shift: float, condition: bool = False
) -> tuple[np.ndarray, np.ndarray | None]:
    r"""Eigenvalues of the pencil (A, E) by shift and invert, and optionally their conditioning.

    Parameters
    ----------
    A, E : ndarray
        The pencil; ``E=None`` is the identity.  Every eigenvalue must satisfy
        :math:`\operatorname{Re}\lambda \le 0` (module docstring), so that
        :math:`A - \sigma E` is invertible.
    shift : float
        :math:`\sigma > 0`, in the pencil's units (:func:`system_shift`).
    condition : bool
        Also return the energy-norm condition numbers (:func:`condition_numbers`).

    Returns
    -------
    eigenvalues : ndarray of complex
        :math:`\sigma + 1/\theta`; ``inf`` where :math:`\theta = 0` (a singular E).
    kappa : ndarray of float or None

    Raises
    ------
    NumericError
        If the shift is not positive or :math:`A - \sigma E` is singular (an eigenvalue
        at the shift: the pencil is not dissipative).

    Examples
    --------
    >>> lam, kappa = shift_invert(np.array([[0.0, 1.0], [-1.0, 0.0]]), shift=1.0, condition=True)
    >>> np.round(np.sort_complex(lam), 12).tolist(), np.round(kappa, 12).tolist()
    ([-1j, 1j], [1.0, 1.0])
    >>> lam, kappa = shift_invert(np.array([[-1.0, 1e4], [0.0, -1.0 - 1e-6]]), shift=1.0,
    ...                           condition=True)
    >>> bool(kappa.min() > 1e9)  # nearly defective
    True
    """
    if not shift > 0:
        raise NumericError(f"the shift must be positive; found {shift!r}")
    n = A.shape[0]
    B = np.eye(n) if E is None else np.asarray(E)
    # LAPACK directly (getrf + getrs in gesv, geev): a search calls this thousands of times
    # on 20 to 60 states, where the wrappers' checks cost as much as the factorization
    lu, piv, S, info = lapack.dgesv(
        np.asarray(A, dtype=float) - shift * B, np.asarray(B, dtype=float), overwrite_a=1
    )
    if info != 0 or not np.all(np.isfinite(S)):
        raise NumericError(
            f"A - {shift:g} E is singular: the pencil has an eigenvalue at the positive shift, "
            "so it is not dissipative"
        )
    if not condition:
        wr, wi, _, _, info = lapack.dgeev(S, compute_vl=0, compute_vr=0, overwrite_a=1)
        if info != 0:
            raise NumericError(f"the eigenvalue iteration did not converge (LAPACK info {info})")
        return _unshift(wr + 1j * wi, shift), None
    theta, W, X = sl.eig(S, left=True, right=True, overwrite_a=True, check_finite=False)
    # w^* S = theta w^*  <=>  y^* A = lambda y^* E  with  y = (A - sigma E)^{-*} w
    Y = sl.lu_solve((lu, piv), W, trans=2, check_finite=False)
    return _unshift(theta, shift), condition_numbers(X, Y, E)


def _unshift(theta: np.ndarray, shift: float) -> np.ndarray:
    out = np.full(theta.shape, complex(np.inf, 0.0))
    finite = theta != 0
    with np.errstate(over="ignore"):  # a theta below 1e-308 is an eigenvalue at infinity
        out[finite] = shift + 1.0 / theta[finite]
    return np.where(np.isfinite(out), out, complex(np.inf, 0.0))


def system_shift(d: DiscretePHS) -> float:
    """Return the shift :data:`SHIFT` times the rate of ``d``'s model (module docstring)."""
    return SHIFT * problem_scales(d.model).rate


@dataclass(frozen=True)
class PreparedSystem:
    r"""A discretization and its shift, for many closed-loop eigenproblems.

    Attributes
    ----------
    system : DiscretePHS
    shift : float
        :math:`\sigma` in the system's units.
    """

    system: DiscretePHS
    shift: float

    @property
    def dim(self) -> int:
        """Number of discrete states."""
        return self.system.dim

    def eigvals(self, K: np.ndarray | None = None) -> np.ndarray:
        """Eigenvalues of the closed loop ũ = −K ỹ (``K=None``: u = 0)."""
        A = self.system.closed_matrix(K)
        return shift_invert(A, self.system.E, shift=self.shift)[0]

    def eigen_condition(self, K: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Eigenvalues and energy-norm condition numbers of the closed loop."""
        A = self.system.closed_matrix(K)
        lam, kappa = shift_invert(A, self.system.E, shift=self.shift, condition=True)
        assert kappa is not None  # condition=True computes them
        return lam, kappa


def prepare(d: DiscretePHS, shift: float | None = None) -> PreparedSystem:
    """Prepare ``d`` for the eigen stage; the shift defaults to :func:`system_shift`."""
    return PreparedSystem(d, system_shift(d) if shift is None else float(shift))
