r"""The sign conditions that make a model and its discretizations dissipative, checked once.

Every spectrum phdesign reports rests on one inequality: for an eigenpair
:math:`A x = \lambda E x` of a closed loop ũ = −Kỹ of a discretization
:math:`E\dot{\hat e} = (J - R)\hat e + B u`, :math:`y = B^\top \hat e + D u`,

.. math::

    \operatorname{Re}\lambda \; x^* E x = -x^* R x - \tilde y^* \operatorname{sym}(G)\,
    \tilde y \le 0, \qquad G = (I + K D)^{-1} K,

which needs :math:`E \succ 0`, :math:`J = -J^\top`, :math:`R \succeq 0`,
:math:`D = -D^\top` and :math:`\operatorname{sym}(K) \succeq 0`; for the PDE,
:math:`P_0 + P_0^\top \preceq 0` on the interval and the plant's own dampers with
:math:`K + K^\top \succeq 0`.  With it the shift and invert of
:mod:`phdesign.numeric.spectrum.eigen` is safe (no eigenvalue at a positive shift) and a positive
real part of a computed eigenvalue can only be round-off (:mod:`phdesign.numeric.spectrum.drift`).
The checks here are cheap (a Cholesky factorization, or eigenvalues of n x n matrices on a
grid of :data:`GRID_POINTS` points) and run where a
:class:`~phdesign.numeric.bridge.NumericModel` or a
:class:`~phdesign.numeric.discretization.phs.DiscretePHS` is built.

"Within round-off" means relative to the size :math:`r` of what the matrix was computed
from (``reference``: its own size by default): a symmetric :math:`M` is accepted as
:math:`\succeq 0` when :math:`\lambda_{\min}(M) \ge -\tau r`, :math:`r = \max|M_{ij}|`
unless stated, :math:`\tau` = :data:`RELATIVE_ROUNDOFF`, far above the :math:`n \epsilon`
that quadrature sums leave and far below any physical violation.  The reference matters
when M is itself round-off: :math:`P_0 + P_0^\top` of a skew :math:`P_0` evaluated in
floating point is measured against :math:`\max|P_0|`, the dissipation R of a lossless
discretization against :math:`\max(|J|, |R|)`, the size of :math:`J - R`.
"""

from __future__ import annotations

import numpy as np

from phdesign.core.errors import NumericError, PhdesignError

__all__ = [
    "GRID_POINTS",
    "RELATIVE_ROUNDOFF",
    "require_definite",
    "require_semidefinite",
    "require_skew",
]

#: Relative round-off accepted in a sign or symmetry condition (module docstring).
RELATIVE_ROUNDOFF = 1e-10
#: Points at which a z-dependent matrix is sampled on the interval.
GRID_POINTS = 33


def _size(M: np.ndarray) -> float:
    return float(np.max(np.abs(M))) if M.size else 0.0


def _finite(name: str, M: np.ndarray, error: type[PhdesignError]) -> np.ndarray:
    M = np.asarray(M, dtype=float)
    if not np.all(np.isfinite(M)):
        raise error(f"{name} must be finite; found a non-finite entry")
    return M


def _require_symmetric(
    name: str, M: np.ndarray, tolerance: float, error: type[PhdesignError]
) -> None:
    defect = _size(M - np.swapaxes(M, -1, -2))
    if defect > tolerance:
        raise error(
            f"{name} must be symmetric; found max |{name} - {name}^T| = {defect:.3g} against "
            f"max |{name}| = {_size(M):.3g}"
        )


def require_skew(name: str, M: np.ndarray, error: type[PhdesignError] = NumericError) -> None:
    r"""Raise ``error`` unless :math:`M = -M^\top` within round-off."""
    M = _finite(name, M, error)
    defect = _size(M + M.T)
    if defect > RELATIVE_ROUNDOFF * _size(M):
        raise error(
            f"{name} must be skew-symmetric ({name}^T = -{name}); found "
            f"max |{name} + {name}^T| = {defect:.3g} against max |{name}| = {_size(M):.3g}"
        )


def require_definite(
    name: str,
    M: np.ndarray,
    error: type[PhdesignError] = NumericError,
    *,
    points: np.ndarray | None = None,
) -> None:
    """Raise ``error`` unless the symmetric M is positive definite (Cholesky succeeds).

    ``M`` is one matrix, or a stack ``(m, n, n)`` sampled at ``points`` (then the message
    says where the condition fails).

    Examples
    --------
    >>> require_definite("E", np.eye(2))
    >>> require_definite("H(z)", np.array([np.eye(2), -np.eye(2)]), points=np.array([0.0, 1.0]))
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    phdesign.core.errors.NumericError: H(z) must be ... definite; found smallest eigenvalue -1 at z
    = 1
    """
    M = _finite(name, M, error)
    _require_symmetric(name, M, RELATIVE_ROUNDOFF * _size(M), error)
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        stack = np.linalg.eigvalsh(M.reshape((-1, *M.shape[-2:])))[:, 0]
        worst = int(np.argmin(stack))
        where = "" if points is None else f" at z = {float(np.ravel(points)[worst]):.6g}"
        raise error(
            f"{name} must be symmetric positive definite; found smallest eigenvalue "
            f"{float(stack[worst]):.3g}{where}"
        ) from None


def require_semidefinite(
    name: str,
    M: np.ndarray,
    *,
    negative: bool = False,
    points: np.ndarray | None = None,
    reference: float | None = None,
    error: type[PhdesignError] = NumericError,
) -> None:
    r"""Raise ``error`` unless :math:`M \succeq 0` (``negative``: :math:`\preceq 0`) to round-off.

    ``M`` is one symmetric matrix, or a stack ``(m, n, n)`` sampled at ``points`` (then
    the message says where the condition fails).  The test is :math:`\lambda \ge -\tau r`
    for the eigenvalues of :math:`\pm M`, with :math:`r` the larger of ``reference`` and
    :math:`\max|M|` (module docstring); one matrix larger than 16 x 16 is first tried by a
    Cholesky factorization of :math:`M + \tau r I`, which succeeds exactly when no
    eigenvalue lies below the tolerance (to round-off), without computing eigenvalues.

    Examples
    --------
    >>> require_semidefinite("R", np.diag([1.0, 0.0]))
    >>> require_semidefinite("R", np.diag([1.0, -0.5]))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    phdesign.core.errors.NumericError: R must be positive semidefinite ...; found smallest ... -0.5
    """
    M = _finite(name, M, error)
    if not M.size or not np.any(M):
        return
    signed = -M if negative else M
    stack = signed.reshape((-1, *signed.shape[-2:]))
    size = max(_size(M), 0.0 if reference is None else float(reference))
    tolerance = RELATIVE_ROUNDOFF * size
    _require_symmetric(name, stack, tolerance, error)
    if stack.shape[0] == 1 and stack.shape[-1] > 16:
        try:
            np.linalg.cholesky(stack[0] + tolerance * np.eye(stack.shape[-1]))
            return
        except np.linalg.LinAlgError:
            pass
    extreme = np.linalg.eigvalsh(0.5 * (stack + stack.transpose(0, 2, 1)))[:, 0]
    worst = int(np.argmin(extreme))
    if extreme[worst] >= -tolerance:
        return
    relation = "negative" if negative else "positive"
    value = -extreme[worst] if negative else extreme[worst]
    which = "largest" if negative else "smallest"
    where = "" if points is None else f" at z = {float(np.ravel(points)[worst]):.6g}"
    raise error(
        f"{name} must be {relation} semidefinite (to round-off, {RELATIVE_ROUNDOFF:g} of "
        f"{size:.3g}); found {which} eigenvalue {value:.6g}{where}"
    )
