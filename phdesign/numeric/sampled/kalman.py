r"""The steady-state Kalman predictor of the exact sampled model: one design of the export.

The observer's model :math:`\dot x = F x + G(u + n)`, :math:`y = H x + D u`
(:class:`~phdesign.numeric.sampled.period_maps.ObserverModel`) is driven at its boundary
inputs by white process noise n of intensity :math:`W = \operatorname{diag}(w_j)`
(``process``: the boundary-noise model; the disturbance of a boundary-controlled system
enters where its inputs do). Over one period, exactly (Van Loan),

.. math::

    x_{k+1} = \Phi x_k + \Gamma u_k + n_k, \qquad
    \mathbb E[n_k n_k^\top] = Q_d = \int_0^{\Delta t} e^{F s} G W G^\top e^{F^\top s}\,ds,
    \qquad y_{m,k} = C_y x_k + D_y u_k + \nu_k,

with :math:`(\Phi, \Gamma, C_y, D_y) = (\Phi, \Gamma, C_m C_s, C_m D_s)` the sampler's exact
map (:func:`~phdesign.numeric.sampled.period_maps.sample_plant`: the mean over the period for
``average``, :math:`y(t_k)` for ``point``) and :math:`\mathbb E[\nu_k\nu_k^\top] = R =
\operatorname{diag}(r_i)` (``sensor``: the variance of each sample's noise). The predictor
gain :math:`K = (\Phi P C_y^\top)(C_y P C_y^\top + R)^{-1}`, P the stabilizing solution of
the discrete Riccati equation (scipy's ``solve_discrete_are``), gives

.. math::

    \hat x_{k+1} = (\Phi - K C_y)\hat x_k + [\Gamma - K D_y,\ K]\,v_k, \qquad
    \hat y_k = H\hat x_k + D u_k,

the export's form :math:`(A, B, C, D)` for every format. The outputs of step k are the
prediction at :math:`t_k` from the samples before it, as the averaged observer's are.

One simplification, stated: with the ``average`` sampler the process noise of period k
also moves the mean :math:`\bar y_k`, so :math:`n_k` and the measurement noise are
correlated; the exact joint covariance (the augmented Van Loan exponential) was measured
on the paper's beam to make the symplectic pencil of the Riccati equation singular to
working precision or, where it solves, the design 5–100x worse on the fine plant. The
predictor here treats them as independent.

Nothing proves this design: its error system is not dissipative in the model's energy,
and it is fragile across orders (docs/sampled.rst, "The sampled limit"), so the export verifies
it against the fine plant on every initial state of the set before ``design="auto"``
takes it (:mod:`phdesign.numeric.sampled.gain_design`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg as sl

from phdesign.core.errors import NumericError
from phdesign.numeric.sampled.period_maps import Realization, sample_plant
from phdesign.numeric.sampled.samplers import ContinuousObserver

__all__ = ["KalmanNoise", "kalman_predictor", "process_covariance"]


def _intensities(value: Any, count: int, name: str) -> np.ndarray:
    """Return a positive number, or one positive number per channel, as ``(count,)``."""
    found = np.atleast_1d(np.asarray(value, dtype=float)) if _numeric(value) else None
    if found is None or found.ndim != 1 or found.size not in (1, count):
        raise NumericError(
            f"{name} must be a positive number or {count} positive numbers (one per "
            f"channel); found {value!r}"
        )
    if not np.all(np.isfinite(found)) or not np.all(found > 0):
        raise NumericError(f"{name} must be finite and positive; found {value!r}")
    return np.broadcast_to(found, (count,)).copy()


def _numeric(value: Any) -> bool:
    if isinstance(value, bool):
        return False
    try:
        np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return True


@dataclass(frozen=True)
class KalmanNoise:
    """The noise model of the Kalman design (module docstring).

    Attributes
    ----------
    process : float or tuple of float
        Intensity of the white noise at each plant input (one number for all).
    sensor : float or tuple of float
        Variance of each sample's sensor noise (one number for all sensors).
    """

    process: float | tuple[float, ...] = 1.0
    sensor: float | tuple[float, ...] = 1.0

    def matrices(self, inputs: int, sensors: int) -> tuple[np.ndarray, np.ndarray]:
        """Return ``(W, R)``, checked: diagonal, positive."""
        W = np.diag(_intensities(self.process, inputs, "process noise intensity"))
        R = np.diag(_intensities(self.sensor, sensors, "sensor noise variance"))
        return W, R

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        return {"process": _listed(self.process), "sensor": _listed(self.sensor)}


def _listed(value: float | tuple[float, ...]) -> float | list[float]:
    return [float(v) for v in value] if isinstance(value, tuple) else float(value)


def process_covariance(F: np.ndarray, G: np.ndarray, W: np.ndarray, dt: float) -> np.ndarray:
    r"""Return :math:`Q_d = \int_0^{\Delta t} e^{Fs} G W G^\top e^{F^\top s} ds` (Van Loan).

    .. math::

        \exp\left(\begin{bmatrix} -F & G W G^\top \\ 0 & F^\top \end{bmatrix}\Delta t\right)
        = \begin{bmatrix} \cdot & \Phi^{-1} Q_d \\ 0 & \Phi^\top \end{bmatrix}.

    Examples
    --------
    A scalar :math:`\dot x = -a x + n`: :math:`Q_d = (1 - e^{-2a\Delta t})/(2a)`.

    >>> q = process_covariance(np.array([[-2.0]]), np.eye(1), np.eye(1), 0.5)
    >>> bool(np.isclose(q[0, 0], (1 - np.exp(-2.0)) / 4.0))
    True
    """
    n = F.shape[0]
    block = np.zeros((2 * n, 2 * n))
    block[:n, :n] = -F
    block[:n, n:] = G @ W @ G.T
    block[n:, n:] = F.T
    exponential = sl.expm(block * dt)
    Q = exponential[n:, n:].T @ exponential[:n, n:]
    return np.asarray(0.5 * (Q + Q.T))


def kalman_predictor(
    observer: ContinuousObserver,
    dt: float,
    sampler: str,
    noise: KalmanNoise | None = None,
) -> tuple[Realization, np.ndarray]:
    r"""Return the Kalman predictor of ``observer``'s model and its gain K (module docstring).

    The outputs are the observer's: the model outputs :math:`H\hat x_k + D u_k`, then its
    point rows. Raises NumericError when the Riccati equation has no stabilizing solution.
    """
    noise = KalmanNoise() if noise is None else noise
    model = observer.model
    C_m = model.C_m
    m = model.G.shape[1]
    W, R = noise.matrices(m, C_m.shape[0])
    s = sample_plant(model.F, model.G, model.H, model.D, dt, sampler)
    Cy, Dy = C_m @ s.C_s, C_m @ s.D_s
    Q = process_covariance(model.F, model.G, W, dt)
    try:
        P = sl.solve_discrete_are(s.Phi.T, Cy.T, Q, R)
    except (np.linalg.LinAlgError, ValueError) as error:
        raise NumericError(
            f"the discrete Riccati equation of the Kalman design has no stabilizing "
            f"solution at dt = {dt:g} ({error})"
        ) from error
    K = np.linalg.solve(Cy @ P @ Cy.T + R, Cy @ P @ s.Phi.T).T
    points = observer.C[m:]
    C = np.vstack([model.H, points])
    D = np.zeros((C.shape[0], m + C_m.shape[0]))
    D[:m, :m] = model.D
    return Realization(A=s.Phi - K @ Cy, B=np.hstack([s.Gamma - K @ Dy, K]), C=C, D=D), K
