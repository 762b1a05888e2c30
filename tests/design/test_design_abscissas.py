"""Observer.abscissas and Observer.pair: the abscissa at many gains at one resolution pair.

Expected values: the wave with the damper u_z(1) = -k u_t(1) (sensor y2, gain k) has the
exact abscissa ½ ln|(1 - k)/(1 + k)| (the closed form of tests/design/test_design.py); the
beam's values are what spectrum() reports at the same first pair (its refinement is
switched off by max_resolution = the fine resolution).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import phdesign as phd
from phdesign.core.errors import ArgumentError, ObserverError


@pytest.fixture(scope="module")
def string():
    return phd.Observer(phd.load("wave"), sensors=[2])


@pytest.mark.parametrize("k", [0.25, 0.5, 3.0])
def test_abscissas_of_the_wave_are_the_exact_damper(string, k):
    (alpha,) = string.abscissas([k], resolution=(20, 30))
    exact = 0.5 * math.log(abs((1 - k) / (1 + k)))
    assert alpha == pytest.approx(exact, abs=1e-9), f"k = {k}: {alpha} against {exact}"


def test_gain_forms_agree_and_the_pair_is_discretized_once(string):
    values = string.abscissas([0.5, [0.5], np.array([[0.5]])], resolution=20)
    assert values[0] == values[1] == values[2]
    evaluator = string._evaluators[20]
    string.abscissas([0.7], resolution=20)
    assert string._evaluators[20] is evaluator
    assert evaluator.evaluations == 4


def test_abscissas_equal_the_spectrum_at_its_first_pair():
    beam = phd.Observer(phd.load("euler-bernoulli"), sensors=[3, 4])
    gains = [(0.1, 1.0), (0.03, 0.3)]
    alphas = beam.abscissas(gains, resolution=(20, 30))
    for gain, alpha in zip(gains, alphas, strict=True):
        report = beam.with_gain(list(gain)).spectrum(max_resolution=30)
        assert alpha == report.spectral_abscissa, f"gain {gain}: {alpha} != spectrum"


def test_pair_holds_the_fine_eigenvalues_and_their_drift_test(string):
    pair = string.pair(0.5, resolution=(20, 30))
    assert pair.resolutions == (20, 30)
    assert pair.resolved.shape == pair.eigenvalues.shape
    rightmost = np.max(pair.eigenvalues.real[pair.resolved])
    assert rightmost == pytest.approx(0.5 * math.log(1 / 3), abs=1e-9)


@pytest.mark.parametrize(
    ("sensors", "gain", "exc", "regex"),
    [
        ([2], [1.0, 2.0], ArgumentError, r"gain: expected a number, 1 numbers .* \(2,\)"),
        ([2], np.eye(2), ArgumentError, r"found shape \(2, 2\)"),
        ([], 1.0, ObserverError, "needs at least one sensor"),
    ],
)
def test_abscissas_refuse_gains_of_the_wrong_shape(sensors, gain, exc, regex):
    obs = phd.Observer(phd.load("wave"), C_m=np.zeros((0, 2))) if not sensors else None
    obs = obs or phd.Observer(phd.load("wave"), sensors=sensors)
    with pytest.raises(exc, match=regex):
        obs.abscissas([gain], resolution=20)
