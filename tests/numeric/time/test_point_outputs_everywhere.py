r"""Point outputs (``at``) in the sampled, noisy and loop simulations, against closed forms.

The built-in ``timoshenko`` (x = (w_z − φ, ρ w_t, φ_z, I_ρ φ_t), clamped at 0) has
φ(z) = ∫_0^z x3 and w(z) = ∫_0^z x1 + ∫_0^z ∫_0^s x3 (tests/numeric/discretization/
test_fields.py).  Under the static tip load P (u3 = P) the equilibrium x1 = P/K,
x3 = P (1 − z)/EI, x2 = x4 = 0 stays put, and by hand (tests/numeric/time/
test_simulate_fields.py) φ(1) = P/(2EI), φ(0.5) = 3P/(8EI), w(1) = P/K + P/(3EI).  The
equilibrium's efforts have degree ≤ 1, held exactly by every Legendre space, so a run
started there (plant *and* observer) keeps these values to round-off in every simulator:

* sampled (``dt``), with an observer of lower degree than the plant: the measurements
  equal the observer's own outputs, so no correction acts, and the held input is constant;
* noisy with sensor noise only: the plant never sees the sensor noise;
* the loop u4 = −K ŷ4 (tip torque from the estimated rotation rate): ŷ4 = e4(1) = 0 at the
  equilibrium, so the feedback adds nothing.

1e-10 allows the exponentials' round-off (~1e-13 observed).  Away from the equilibrium:
the continuous observer run by the sampled simulator agrees with the plain simulation
(two implementations of the same exact stepping), and the loop's φ(1, t) − φ(1, 0) is
∫_0^t y4 (y4 = e4(1) = φ_t(1), a boundary output computed from Bᵀê, not from the field's
row), by the trapezoidal rule at its rate 2.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

import phdesign as phd

P_TIP = 0.7
VALUES = {"K": 3.0, "EI": 2.0, "rho": 1.5, "I_rho": 0.5}
K, EI = VALUES["K"], VALUES["EI"]
AT = ["rotation(1)", "rotation(0.5)", 1]
NAMES = ("rotation(1)", "rotation(0.5)", "w(1)")
EXPECTED = [P_TIP / (2 * EI), 3 * P_TIP / (8 * EI), P_TIP / K + P_TIP / (3 * EI)]
EQUILIBRIUM = f"x1: {P_TIP / K!r}, x3: {P_TIP / EI!r}*(1 - z)"
LOAD = f"u3: {P_TIP!r}"


def _observer(resolution: int = 12) -> phd.Observer:
    return phd.Observer(
        phd.load("timoshenko"), sensors=[3, 4], gain=1, parameters=VALUES, resolution=resolution
    )


def _assert_static(run, samples: int) -> None:
    assert run.at == NAMES
    for values in (run.at_values, run.at_values_hat):
        assert values == pytest.approx(np.tile(EXPECTED, (samples, 1)), rel=1e-10, abs=0)


@pytest.mark.parametrize("sampler", ["average", "point"])
def test_a_sampled_lower_order_observer_keeps_the_static_tip_load(sampler) -> None:
    run = _observer().simulate(
        EQUILIBRIUM, xhat0=EQUILIBRIUM, u=LOAD, t_end=1.0, samples=6, at=AT,
        dt=0.05, sampler=sampler, observer_resolution=8,
    )  # fmt: skip
    assert run.info["observer_resolution"] == 8
    assert run.info["dt"] == 0.05
    _assert_static(run, run.t.size)


def test_a_sensor_noise_run_reports_the_plants_static_values_and_noisy_estimates() -> None:
    run = _observer().simulate(
        EQUILIBRIUM, xhat0=EQUILIBRIUM, u=LOAD, t_end=1.0, samples=6, at=AT,
        noise_intensity=1e-2, seed=3,
    )  # fmt: skip
    assert run.at == NAMES
    assert run.at_values == pytest.approx(np.tile(EXPECTED, (6, 1)), rel=1e-10, abs=0)
    # the estimate starts exact, then the sensor noise moves it (it is read from the noisy
    # observer, not from the noise-free part); w(1)'s estimate is the displacement's
    assert run.at_values_hat[0] == pytest.approx(EXPECTED, rel=1e-10, abs=0)
    assert np.max(np.abs(run.at_values_hat[1:] - EXPECTED)) > 1e-6
    assert run.at_values_hat[:, 2] == pytest.approx(run.w_hat[:, -1], rel=1e-12, abs=1e-15)


def _loop(resolution: int = 12) -> phd.Loop:
    return phd.Loop(_observer(resolution), actuate=4, feedback=2)


def test_the_loop_keeps_the_static_tip_load() -> None:
    run = _loop().simulate(x0=EQUILIBRIUM, xhat0=EQUILIBRIUM, u=LOAD, t_end=1.0, samples=6, at=AT)
    _assert_static(run, 6)
    assert run.u[:, 3] == pytest.approx(np.zeros(6), abs=1e-12)  # ŷ4 = 0: no torque
    header = run.to_csv().splitlines()[0].split(",")
    assert header[-10:] == [
        "rotation(1)", "rotation(0.5)", "w(1)", "rotation_hat(1)", "rotation_hat(0.5)",
        "w_hat(1)", "u1", "u2", "u3", "u4",
    ]  # fmt: skip


def test_the_continuous_observer_of_the_sampled_simulator_matches_simulate() -> None:
    """Two implementations of one exact run: ``run_loop`` and ``simulate``'s stepping."""
    obs = _observer()
    kwargs = {"x0": "x4: sin(pi*z/2), x2: z**2", "t_end": 2.0, "samples": 21, "at": AT}
    plain = obs.simulate(**kwargs)
    sampled = obs.simulate(**kwargs, observer_resolution=12)  # the sampled simulator
    assert "observer_resolution" in sampled.info
    assert sampled.at == plain.at == NAMES
    scale = float(np.max(np.abs(plain.at_values)))
    assert np.max(np.abs(sampled.at_values - plain.at_values)) < 1e-9 * scale
    assert np.max(np.abs(sampled.at_values_hat - plain.at_values_hat)) < 1e-9 * scale
    assert np.max(np.abs(plain.at_values_hat[-1] - plain.at_values[-1])) > 1e-4  # not trivial


def test_the_loops_tip_rotation_is_the_integral_of_its_rate_output() -> None:
    loop = _loop(16)
    steps = (500, 1000, 2000)
    errors = []
    for n in steps:
        run = loop.simulate(x0="x4: sin(pi*z/2), x2: z**2", t_end=2.0, samples=n + 1, at=AT[0])
        phi, y4 = run.at_values[:, 0], run.y[:, 3]
        errors.append(
            float(np.max(np.abs(phi[0] + cumulative_trapezoid(y4, run.t, initial=0) - phi)))
        )
    rate = -np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert 1.9 < rate < 2.1, f"φ(1) − ∫y4 at rate {rate:.3f}, errors {errors}"
    assert np.max(np.abs(run.u[:, 3])) > 1e-3  # the feedback acts in this run
