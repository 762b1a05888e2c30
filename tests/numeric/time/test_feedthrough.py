r"""The noisy and the noiseless simulation close the observer's loop through a feedthrough.

FEEDTHROUGH on staggered finite differences has a skew D ≠ 0, so the observer's input
:math:`\hat u = u + C_m^\top L (y_m + \nu - \hat y_m)` with :math:`\hat y = B^\top \hat e_{obs}
+ D \hat u` is implicit.  Both sensors and a non-scalar gain make (I + K D)⁻¹ differ from I
in every block (one sensor leaves K D nilpotent and hides a dropped D).  The expected
values are written from these definitions, never from ``DiscretePHS.close()``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from numeric_models import FEEDTHROUGH, observer_loop_residual

from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.simulation import simulate
from phdesign.numeric.time.stochastic import noisy_coupled_system, simulate_noisy

C_M, GAIN = np.eye(2), np.diag([0.5, 2.0])
RESOLUTION = 12


def _inputs(t):
    return np.array([np.sin(3 * t), 0.5 * np.cos(t)])


def _setup():
    nm = to_numeric(FEEDTHROUGH)
    d = discretize(nm, "fd", RESOLUTION)
    assert np.abs(d.D).max() > 0.1
    return nm, d


@pytest.mark.parametrize("noisy", [False, True], ids=["simulate", "simulate_noisy"])
def test_the_observer_output_solves_its_implicit_input(noisy):
    nm, d = _setup()
    x0 = lambda z: np.column_stack([np.sin(np.pi * z), z])  # noqa: E731
    options = SimulationOptions(t_end=0.5, samples=6, method="fd", resolution=RESOLUTION)
    if noisy:
        noise = replace(options, noise_intensity=0.1, input_intensity=[0.2, 0.3], seed=1)
        run = simulate_noisy(nm, C_M, GAIN, x0=x0, u=_inputs, options=noise)
    else:
        run = simulate(nm, C_M, GAIN, x0=x0, u=_inputs, options=options)
    U = np.array([_inputs(t) for t in run.t])
    y_plant = run.states @ d.B + U @ d.D.T
    assert np.max(np.abs(run.y - y_plant)) < 1e-12 * np.max(np.abs(y_plant))
    K = C_M.T @ GAIN @ C_M
    assert observer_loop_residual(d, K, run.states_hat, U, run.y, run.y_hat) < 1e-12


def test_the_noise_enters_the_observer_through_the_solved_correction():
    r"""The observer's correction δ = û − u solves (I + K D) δ = K D w + C_mᵀ L ν (its
    measurement y_m + ν carries D w, its own ŷ the D δ): the noise columns of the plant and
    the observer are B [0, Σ_w^{1/2}] and B δ."""
    _, d = _setup()
    sigma, w = np.array([0.3, 0.1]), np.array([0.5, 2.0])
    N2 = noisy_coupled_system(d, C_M, GAIN, sigma, w)[3]
    K = C_M.T @ GAIN @ C_M
    channels = np.hstack([C_M.T @ GAIN @ np.diag(np.sqrt(sigma)), K @ d.D @ np.diag(np.sqrt(w))])
    delta = np.linalg.solve(np.eye(d.n_ports) + K @ d.D, channels)
    plant = np.hstack([np.zeros((d.dim, sigma.size)), d.B @ np.diag(np.sqrt(w))])
    expected = np.vstack([plant, d.B @ delta])
    assert np.max(np.abs(N2 - expected)) < 1e-13 * np.max(np.abs(expected))
