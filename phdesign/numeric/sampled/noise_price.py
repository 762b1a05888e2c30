r"""The noise price of a sampled observer: the variance its estimate takes from sensor noise.

Sensor noise :math:`\nu` of unit intensity (continuous white noise,
:math:`\mathbb E[\nu(t)\nu(s)^\top] = I\delta(t - s)`, as :mod:`phdesign.numeric.noise`
takes it) reaches a sampled observer as one sample per period with covariance
:math:`I/\Delta t` (the mean over the period of unit white noise; the same figure is used for
point samples, as the noise of a front end of bandwidth :math:`1/(2\Delta t)`). The error
is the plant minus the estimate, and by linearity the noise enters it only through the
observer, :math:`\hat x_{k+1} = A\hat x_k + B_y\nu_k`, estimate :math:`C\hat x_k + D_y\nu_k`,
so its stationary covariance solves the discrete Lyapunov equation (scipy's
``solve_discrete_lyapunov``)

.. math::

    P = A P A^\top + \tfrac{1}{\Delta t} B_y B_y^\top, \qquad
    \sigma_j^2 = c_j P c_j^\top + \tfrac{1}{\Delta t} d_j d_j^\top

for each performance output j (rows :math:`c_j, d_j` of C and of the sensor columns of D).
Its root :math:`\sigma_j` is the noise *gain* (the :math:`H_2` norm from unit sensor noise to
the output's error, an amplitude; the reports print both). For a smooth performance functional
(the beam's tip w(1)) and the averaged sampler this
tends to the continuous observer's variance as :math:`\Delta t \to 0`
(:func:`phdesign.numeric.noise.statistics.error_statistics` on the same observer's model).
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sl

from phdesign.numeric.sampled.period_maps import Realization

__all__ = ["noise_price"]


def noise_price(
    realization: Realization, n_inputs: int, performance: tuple[int, ...], dt: float
) -> np.ndarray:
    r"""Return the stationary error variance of each performance output (module docstring).

    ``inf`` for every output when the recursion is not stable (spectral radius >= 1).

    Examples
    --------
    The scalar :math:`\hat x_{k+1} = a\hat x_k + b\nu_k`:
    :math:`\sigma^2 = b^2/((1 - a^2)\Delta t)`.

    >>> r = Realization(np.array([[0.5]]), np.array([[0.0, 2.0]]), np.eye(1), np.zeros((1, 2)))
    >>> float(noise_price(r, 1, (0,), 0.1)[0])  # 4 / 0.75 / 0.1
    53.333333333333336
    """
    A, By = realization.A, realization.B[:, n_inputs:]
    perf = list(performance)
    Cp, Dp = realization.C[perf], realization.D[perf, n_inputs:]
    if not float(np.max(np.abs(np.linalg.eigvals(A)), initial=0.0)) < 1.0:
        return np.full(len(perf), math.inf)
    P = sl.solve_discrete_lyapunov(A, By @ By.T / dt)
    variance = np.einsum("ij,jk,ik->i", Cp, P, Cp) + np.sum(Dp * Dp, axis=1) / dt
    return np.asarray(variance)
