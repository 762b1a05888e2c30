r"""Reductions of a Galerkin observer: its converged modes, or balanced truncation.

``"modal"`` keeps the observer's invariant subspace of the poles that agree with the
verification plant's error spectrum (:func:`modal_truncation`); ``"balanced"`` truncates
a balanced realization (:func:`balanced_truncation`, square-root method on the gramians
python-control computes through slycot).  Why and when each helps:
:mod:`phdesign.numeric.sampled.order`.
"""

from __future__ import annotations

import importlib.util
from typing import Any

import numpy as np
import scipy.linalg as sl

from phdesign.core.errors import NumericError
from phdesign.numeric.sampled.samplers import ContinuousObserver
from phdesign.numeric.spectrum.drift import match_resolved

__all__ = ["balanced_truncation", "modal_truncation"]


def modal_truncation(
    observer: ContinuousObserver, reference: np.ndarray, tol: float
) -> tuple[ContinuousObserver, np.ndarray]:
    """Keep the observer's modes that agree with ``reference`` (drift test at ``tol``).

    Returns the reduced observer and the dropped poles.
    """
    poles = np.linalg.eigvals(observer.A)
    kept_idx, _ = match_resolved(poles, reference, tol)
    kept = poles[kept_idx]
    if kept.size == 0:
        raise NumericError(
            f"no pole of the degree-{observer.discrete.resolution} observer agrees with the "
            "converged error spectrum: raise the order before a modal reduction"
        )

    def keep(re: float, im: float) -> bool:
        z = complex(re, im)
        return bool(np.min(np.abs(kept - z)) <= 1e-8 * max(1.0, abs(z)))

    T, Q, sdim = sl.schur(observer.A, output="real", sort=keep)
    k = int(sdim)
    if k != kept.size:
        raise NumericError(
            f"the modal reduction could not separate the {kept.size} converged poles "
            f"(the Schur reordering kept {k}); use `reduction='none'`"
        )
    T11, T12, T22 = T[:k, :k], T[:k, k:], T[k:, k:]
    X = sl.solve_sylvester(T11, -T22, -T12)
    Q1, Q2 = Q[:, :k], Q[:, k:]
    reduced = observer.project(Q1, Q1 - Q2 @ X.T, "modal")
    dropped = np.delete(poles, kept_idx)
    return reduced, dropped


def _slycot_available() -> bool:
    return importlib.util.find_spec("slycot") is not None


def balanced_truncation(
    observer: ContinuousObserver, order: int | None = None
) -> tuple[ContinuousObserver | None, np.ndarray, Any]:
    r"""Balanced truncation of ``observer`` (square-root method).

    With the gramians :math:`W_c = S S^\top`, :math:`W_o = R R^\top` (python-control's
    ``gram``, through slycot) and :math:`R^\top S = U \Sigma V^\top`, the reduced observer
    is :math:`x = T x_r`, :math:`T = S V_r \Sigma_r^{-1/2}`,
    :math:`\dot x_r = W^\top(A T x_r + B v)`, :math:`W = R U_r \Sigma_r^{-1/2}`
    (:math:`W^\top T = I`). Returns the reduced observer (None when ``order`` is None),
    the Hankel singular values and a function ``reduce(r)``.

    Raises
    ------
    NumericError
        When slycot is not installed.
    """
    if not _slycot_available():
        raise NumericError(
            "balanced truncation needs slycot (python-control computes its gramians with "
            "it): pip install slycot, or use `reduction='none'` or `reduction='modal'`"
        )
    import control

    system = control.ss(observer.A, observer.B, observer.C, observer.D)
    factors = []
    for kind in ("c", "o"):
        gramian = control.gram(system, kind)
        w, U = np.linalg.eigh(0.5 * (gramian + gramian.T))
        factors.append(U * np.sqrt(np.clip(w, 0.0, None)))
    S, R = factors
    U, sigma, Vt = np.linalg.svd(R.T @ S)

    def reduce(r: int) -> ContinuousObserver:
        scale = 1.0 / np.sqrt(sigma[:r])
        return observer.project(S @ Vt[:r].T * scale, R @ U[:, :r] * scale, "balanced")

    reduced = None if order is None else reduce(order)
    return reduced, sigma, reduce
