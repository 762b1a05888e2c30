"""Numeric sensors and gains are checked in floating point, with the exact checks' messages."""

from __future__ import annotations

import numpy as np
import pytest

import phdesign as phd
import phdesign.symbolic.observer as exact
from phdesign.core.errors import ObserverError
from phdesign.numeric.checks import check_sensors_and_gain

BEAM = phd.to_numeric(phd.load("euler-bernoulli"))
SENSORS = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


@pytest.fixture
def exact_checks_forbidden(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("valid floats reached the exact checks")

    monkeypatch.setattr(exact, "measurement_matrix", refuse)
    monkeypatch.setattr(exact, "gain_matrix", refuse)


@pytest.mark.parametrize(
    ("C_m", "L"),
    [
        (SENSORS, np.diag([0.1, 1.0])),
        (SENSORS, np.array([[1.0, 3.0], [-3.0, 1.0]])),  # L + Lᵀ = 2 I: a skew part is free
        (SENSORS.astype(int), np.eye(2, dtype=int)),
        ([[0, 0, 1, 0], [0, 0, 0, 1]], [[0.01, 0.0], [0.0, 100.0]]),
        (SENSORS[:1] + 0.5, np.array([[2.0]])),
    ],
)
def test_valid_floats_never_reach_the_exact_checks(C_m, L, exact_checks_forbidden):
    check_sensors_and_gain(BEAM, C_m, L)
    check_sensors_and_gain(BEAM, C_m, None, gain_required=False)  # tune: sensors only


@pytest.mark.parametrize(
    ("C_m", "L", "message"),
    [
        # the messages of the exact checks (symbolic/sensors.py), which word every refusal
        (np.zeros((1, 4)), np.eye(1), r"full row rank.*expected rank 1 but found 0"),
        (np.array([[0.0, 0, 1, 0], [0, 0, 2, 0]]), np.eye(2), r"expected rank 2 but found 1"),
        (np.zeros((1, 3)), np.eye(1), r"C_m matrix; expected \(q, 4\) but found \(1, 3\)"),
        (np.zeros((0, 4)), np.eye(1), r"C_m: expected a non-empty list of non-empty rows"),
        (SENSORS, np.diag([1.0, -1.0]), r"positive definite.*but found minor 2 = -4"),
        (SENSORS, np.diag([1.0, 0.0]), r"but found minor 2 = 0"),
        (SENSORS, np.diag([1.0, np.nan]), r"finite"),
        (SENSORS, np.eye(3), r"L matrix; expected \(2, 2\)"),
        # PD in floating point by 3e-17 only; the decimals 0.1, 0.3, 0.9 give minor 0
        (SENSORS, np.array([[0.1, 0.3], [0.3, 0.9]]), r"but found minor 2 = 0"),
    ],
)
def test_bad_floats_get_the_exact_checks_message(C_m, L, message):
    with pytest.raises(ObserverError, match=message):
        check_sensors_and_gain(BEAM, C_m, L)


def test_a_gain_definite_within_the_margin_only_is_decided_exactly():
    # λ_min(L + Lᵀ) = 2e-12 against 2: below the margin, so the exact checks decide (yes)
    check_sensors_and_gain(BEAM, SENSORS, np.diag([1.0, 1e-12]))


def test_an_observer_converts_its_sensors_and_gain_to_floats_once():
    obs = phd.Observer(phd.load("euler-bernoulli"), sensors=[3, 4], gain=[0.1, 1])
    C, L = obs.numeric_gain("spectrum")
    assert obs.numeric_gain("simulate")[1] is L
    assert L.tolist() == [[0.1, 0.0], [0.0, 1.0]]
    assert not C.flags.writeable
    assert not L.flags.writeable
    with pytest.raises(ObserverError, match="spectrum needs numbers for L"):
        obs.with_gain("symbolic").numeric_gain("spectrum")


@pytest.mark.parametrize(
    ("x0", "found"),
    [
        # a list of components, one of them a number: numpy cannot stack it (a raw
        # "inhomogeneous shape" ValueError before; issue 28)
        (lambda z: [0, z - 0.9], "found a list of 2 entries of shapes (), (17,)"),
        (lambda z: (z, z[:3]), "found a tuple of 2 entries of shapes (17,), (3,)"),
        # components stacked the other way round: (n, m) instead of (m, n)
        (lambda z: np.vstack([0 * z, z - 0.9]), "found (2, 17)"),
    ],
)
def test_an_initial_state_of_the_wrong_shape_is_refused_naming_the_shape(x0, found):
    obs = phd.Observer(phd.load("euler-bernoulli"), sensors=[3, 4], gain=[0.1, 1])
    with pytest.raises(ValueError, match="x0") as error:
        obs.simulate(x0=x0, t_end=0.1)
    assert "x0(z) must return an array of shape (len(z), n) = (17, 2)" in str(error.value)
    assert found in str(error.value)
    # the same state as the check asks for it runs
    good = obs.simulate(x0=lambda z: np.column_stack([np.zeros_like(z), z - 0.9]), t_end=0.01)
    assert good.t.size > 0
