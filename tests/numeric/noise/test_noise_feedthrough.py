r"""The noise figures of an observer whose discretization has a feedthrough D ≠ 0.

FEEDTHROUGH on staggered finite differences has a skew D ≠ 0.  From the definitions (not
from ``DiscretePHS.close()``): the plant receives :math:`B(u + w)`, the observer
:math:`B(u + \delta)` with the correction :math:`(I + K D)\,\delta = K (B^\top \tilde e +
D w) + C_m^\top L \nu`, so the error :math:`\tilde e = \hat e - \hat e_{obs}` is driven by
:math:`B (w - \delta)`.  Both sensors and a non-scalar gain make (I + K D)⁻¹ differ from I
in every block.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sl
from numeric_models import FEEDTHROUGH

from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.noise.figures import noise

C_M, GAIN = np.eye(2), np.diag([0.5, 2.0])
SIGMA, W = np.array([0.3, 0.1]), np.array([0.5, 2.0])


def _error_energy_from_the_definitions(d):
    """E[H̃] = ½ tr(E P), P the stationary covariance of ẽ, written from the module docstring."""
    K = C_M.T @ GAIN @ C_M
    loop = np.eye(d.n_ports) + K @ d.D
    A = d.J - d.R - d.B @ np.linalg.solve(loop, K) @ d.B.T
    nu = C_M.T @ GAIN @ np.diag(np.sqrt(SIGMA))
    w = np.diag(np.sqrt(W))
    G = d.B @ np.hstack([-np.linalg.solve(loop, nu), w - np.linalg.solve(loop, K @ d.D @ w)])
    F, N = np.linalg.solve(d.E, A), np.linalg.solve(d.E, G)
    P = sl.solve_continuous_lyapunov(F, -N @ N.T)
    return 0.5 * float(np.sum(d.E * P))


def test_the_expected_error_energy_with_a_feedthrough_is_its_lyapunov_value():
    nm = to_numeric(FEEDTHROUGH)
    d = discretize(nm, "fd", 12)
    assert np.abs(d.D).max() > 0.1
    report = noise(
        nm,
        C_M,
        GAIN,
        intensity=SIGMA,
        input_intensity=W,
        method="fd",
        resolution=12,
        max_resolution=18,
        performance=["x1: 1"],
    )
    expected = _error_energy_from_the_definitions(d)
    found = report.error_energy.values[0]
    assert abs(found - expected) < 1e-10 * expected
