r"""``Observer.noise_samples``: Monte Carlo runs of plant and observer, a check of ``noise``.

The runs are sampled exactly (Van Loan), so at a time long after the start the samples'
variance estimates the Lyapunov variance that :meth:`Observer.noise` reports at the same
resolution, with no time-stepping bias: the two agree within a few standard errors
:math:`\mathrm{Var}\sqrt{2/(n - 1)}` of a Gaussian sample's variance.  The string of
``wave`` with gain k = 0.5 decays at rate :math:`\tfrac12\ln 3 \approx 0.55`
(tests/design/test_design_noise.py), so after 10 time units the start is forgotten to
:math:`e^{-11}` in variance.
"""

from __future__ import annotations

import numpy as np
import pytest

import phdesign as phd
from phdesign.core.errors import NumericError, ObserverError

SIGMA2 = 0.3  # sensor noise intensity
OUTPUT = "x2: 1"  # the integral of the error velocity, Var = k sigma^2 / 2 for the PDE


@pytest.fixture(scope="module")
def string() -> phd.Observer:
    return phd.Observer(phd.load("wave"), sensors=[2], gain=0.5, resolution=8)


def test_the_samples_variance_is_the_lyapunov_variance(string):
    lyapunov = string.noise(intensity=SIGMA2, performance=OUTPUT, max_resolution=8)
    expected = lyapunov.performance[0].values[0]
    samples = string.noise_samples(
        steps=5, dt=2.0, runs=4000, intensity=SIGMA2, performance=OUTPUT, seed=3
    )[-1, 0]
    standard_error = expected * np.sqrt(2 / (samples.size - 1))
    found = samples.var(ddof=1)
    assert abs(found - expected) < 4 * standard_error, (
        f"Monte Carlo variance {found:.5f}, Lyapunov {expected:.5f} (se {standard_error:.5f})"
    )


def test_the_samples_start_at_zero_and_follow_the_seed(string):
    first = string.noise_samples(steps=3, dt=0.5, runs=4, performance=["x2: 1", "x1: 1"], seed=7)
    again = string.noise_samples(steps=3, dt=0.5, runs=4, performance=["x2: 1", "x1: 1"], seed=7)
    other = string.noise_samples(steps=3, dt=0.5, runs=4, performance=["x2: 1", "x1: 1"], seed=8)
    assert first.shape == (4, 2, 4)
    assert not first[0].any()
    np.testing.assert_array_equal(first, again)
    assert not np.array_equal(first, other)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"steps": 0}, "steps"),
        ({"runs": 1.5}, "runs"),
        ({"dt": -1.0}, "dt"),
        ({"intensity": -1.0}, "intensity"),
    ],
)
def test_noise_samples_refuses_bad_arguments_by_name(string, kwargs, match):
    arguments = {"steps": 2, "dt": 1.0, "runs": 2, "performance": OUTPUT, **kwargs}
    with pytest.raises(NumericError, match=match):
        string.noise_samples(**arguments)


def test_noise_samples_needs_a_numeric_gain():
    without = phd.Observer(phd.load("wave"), sensors=[2], resolution=8)
    with pytest.raises(ObserverError, match="noise_samples"):
        without.noise_samples(steps=2, dt=1.0, runs=2, performance=OUTPUT)
