r"""The optimal linear estimators of a discretized plant: the price of a boundary observer.

For the same plant, disturbances and sensor noise as a boundary observer
(:mod:`phdesign.numeric.noise.disturbance`), whitened on the discretization
(:math:`E = C C^\top`, :math:`\xi = C^\top \hat e`),

.. math::

    \dot\xi = F \xi + G n, \qquad y_m = H_y \xi + \Sigma_\nu^{1/2} n_\nu, \qquad
    z_p = C_z \xi, \qquad
    F = C^{-1}(J - R)C^{-\top},\; G = C^{-1}[B_d, B_{:,\text{unknown}}],\;
    H_y = C_m B^\top C^{-\top},\; C_z = C_p C^{-\top},

(known inputs at zero: they enter plant and estimator alike).

* **Kalman–Bucy.**  The steady-state filter :math:`\dot{\hat\xi} = F\hat\xi +
  P H_y^\top \Sigma_\nu^{-1}(y_m - H_y \hat\xi)` has the error covariance P of the
  filter Riccati equation :math:`F P + P F^\top - P H_y^\top \Sigma_\nu^{-1} H_y P + G
  G^\top = 0` (scipy's ``solve_continuous_are``); no linear estimator has a smaller
  error variance of any linear functional, so its H₂ error
  :math:`\sqrt{\operatorname{tr}(C_z P C_z^\top)}` bounds every boundary observer's
  from below (at every resolution: both are estimators of the same discrete plant).
* **H∞-optimal level.**  A filter with :math:`\|T_{n \to \tilde z}\|_\infty < \gamma`
  exists exactly when :math:`F P + P F^\top + P(\gamma^{-2} C_z^\top C_z - H_y^\top
  \Sigma_\nu^{-1} H_y) P + G G^\top = 0` has a stabilizing solution :math:`P \succeq 0`
  (Nagpal and Khargonekar, 1991); :math:`\gamma^*` is found by bisection on that test
  (the Riccati equation with the indefinite weight
  :math:`\operatorname{diag}(\Sigma_\nu, -\gamma^2 I)`).

The full-order optimal filters have a distributed gain :math:`P H_y^\top
\Sigma_\nu^{-1}` that no boundary sensor can realise without a model-sized filter; the
ratio of the boundary observer's figures to these says what the simple, passive,
implementable observer gives up.  Both need sensor noise on every sensor
(:math:`\Sigma_\nu \succ 0`) and a discretization without feedthrough of the unknown
inputs into the measurements.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sl

from phdesign.numeric.discretization.phs import DiscretePHS
from phdesign.numeric.noise.settle import Estimate, settle

__all__ = ["OptimalEstimators", "optimal_filters"]

#: Relative width at which the bisection for γ* stops.
LEVEL_RTOL = 1e-7


@dataclass(frozen=True)
class OptimalEstimators:
    """The optimal full-order estimators' figures under refinement (module docstring).

    Attributes
    ----------
    h2 : Estimate
        The Kalman–Bucy filter's H₂ error (the smallest of any linear estimator).
    hinf : Estimate
        The H∞-optimal level γ*.
    note : str
        Why they were not computed, when they were not (else empty).
    """

    h2: Estimate | None = None
    hinf: Estimate | None = None
    note: str = ""

    def to_dict(self) -> dict[str, object]:
        """JSON-ready dictionary."""
        return {
            "kalman_h2": None if self.h2 is None else self.h2.to_dict(),
            "hinf_level": None if self.hinf is None else self.hinf.to_dict(),
            "note": self.note or None,
        }


def _whitened(
    d: DiscretePHS, G: np.ndarray, rows: np.ndarray, C_m: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Return F, G, H_y and C_z of the whitened plant (module docstring)."""
    C = np.linalg.cholesky(d.E)
    F = sl.solve_triangular(C, d.J - d.R, lower=True)
    F = sl.solve_triangular(C, F.T, lower=True).T
    Gx = sl.solve_triangular(C, G, lower=True)
    to_xi = sl.solve_triangular(C, np.eye(d.dim), lower=True)  # C⁻¹; x̂ = C⁻ᵀ ξ
    Hy = C_m @ d.B.T @ to_xi.T
    Cz = rows @ to_xi.T
    return F, Gx, Hy, Cz


def kalman_h2(
    d: DiscretePHS, G: np.ndarray, rows: np.ndarray, C_m: np.ndarray, sigma: np.ndarray
) -> float:
    """Return the Kalman–Bucy filter's H₂ error on ``d`` (module docstring)."""
    F, Gx, Hy, Cz = _whitened(d, G, rows, C_m)
    P = sl.solve_continuous_are(F.T, Hy.T, Gx @ Gx.T, np.diag(sigma))
    return math.sqrt(max(float(np.trace(Cz @ P @ Cz.T)), 0.0))


def hinf_level(
    d: DiscretePHS,
    G: np.ndarray,
    rows: np.ndarray,
    C_m: np.ndarray,
    sigma: np.ndarray,
    upper: float,
) -> float:
    """Return γ*, the H∞-optimal filtering level on ``d``, by bisection below ``upper``.

    ``upper`` is a level some filter attains (the boundary observer's H∞ norm): the
    bracket halves from it until a level is infeasible, then the bisection runs on log γ
    to a relative width :data:`LEVEL_RTOL`.
    """
    F, Gx, Hy, Cz = _whitened(d, G, rows, C_m)
    Q = Gx @ Gx.T
    B = np.hstack([Hy.T, Cz.T])
    r = Cz.shape[0]

    def feasible(gamma: float) -> bool:
        weight = sl.block_diag(np.diag(sigma), -(gamma**2) * np.eye(r))
        try:
            P = sl.solve_continuous_are(F.T, B, Q, weight)
        except (np.linalg.LinAlgError, ValueError):
            return False
        if not np.all(np.isfinite(P)):
            return False
        P = 0.5 * (P + P.T)
        scale = max(float(np.max(np.abs(P))), 1e-300)
        return bool(np.linalg.eigvalsh(P)[0] >= -1e-8 * scale)

    hi, lo = upper, 0.5 * upper
    while feasible(lo):  # the boundary observer attains upper: step down to a bracket
        hi, lo = lo, 0.5 * lo
        if lo < upper * 1e-12:
            return lo
    while hi / lo > 1 + LEVEL_RTOL:
        mid = math.sqrt(lo * hi)
        if feasible(mid):
            hi = mid
        else:
            lo = mid
    return hi


def optimal_filters(
    figures: Sequence[tuple[int, float, float]], tol: float, note: str = ""
) -> OptimalEstimators:
    """Judge ``(resolution, kalman_h2, gamma_star)`` per resolution under refinement."""
    if note or not figures:
        return OptimalEstimators(note=note or "not computed")
    res = [f[0] for f in figures]
    return OptimalEstimators(
        h2=settle("Kalman-Bucy H2", [f[1] for f in figures], res, tol),
        hinf=settle("H∞-optimal level", [f[2] for f in figures], res, tol),
    )
