"""The averaged sampler's observer: exact, dissipative for every period, consistent.

The claims come from the derivation in ``phdesign.numeric.sampled.period_maps``: over
each period the observer's model runs with its input held at u_k + w_k, and w_k =
C_mᵀL (ȳ_m,k − C_m ȳ̂_k) compares the measured mean with the exact mean of the model's own
outputs. The references below are independent of that construction: scipy's DOP853 with
a Gauss-Legendre mean of its dense output (the correction found from the affine map
w -> ȳ̂(w), built from m + 1 integrations), and the energy ½ ẽᵀEẽ of the Galerkin model.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.sampled.runs import run_loop
from phdesign.numeric.sampled.samplers import ContinuousObserver

BEAM_SENSORS = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
BEAM_GAIN = np.diag([0.1, 1.0])


def _beam_with_feedthrough(rng, degree):
    # no built-in model has a feedthrough; a skew D = -Dᵀ keeps the system port-Hamiltonian
    # and exercises the correction loop (I + K D_s)⁻¹
    d = discretize(to_numeric(load_builtin("euler-bernoulli")), "galerkin", degree)
    W = rng.standard_normal((4, 4))
    return dataclasses.replace(d, D=0.3 * (W - W.T)), BEAM_SENSORS, BEAM_GAIN


def _beam_with_tip_damper(_rng, degree):
    # the model's own [feedback] (u4 = -k y4) closed in its discretization: R gains the damper
    d = discretize(to_numeric(load_builtin("beam-tip-damper")), "galerkin", degree)
    return d, np.array([[0.0, 0.0, 1.0]]), np.array([[1.0]])


CASES = {
    "beam with feedthrough": _beam_with_feedthrough,
    "beam with tip damper": _beam_with_tip_damper,
}


def _reference_step(d, C_m, L, e, u, y_m, dt):
    """One period of the sampled-data observer by an independent integrator."""
    F = np.linalg.solve(d.E, d.J - d.R)
    G = np.linalg.solve(d.E, d.B)
    nodes, weights = np.polynomial.legendre.leggauss(60)
    ts = 0.5 * dt * (nodes + 1)

    def integrate(u_hat):
        sol = solve_ivp(
            lambda _t, x: F @ x + G @ u_hat, (0, dt), e, method="DOP853",
            rtol=1e-12, atol=1e-14, dense_output=True,
        )  # fmt: skip
        mean = 0.5 * sum(
            w * (d.B.T @ sol.sol(t) + d.D @ u_hat) for t, w in zip(ts, weights, strict=True)
        )
        return sol.y[:, -1], mean

    m = d.n_ports
    _, base = integrate(u)
    columns = [integrate(u + np.eye(m)[j])[1] - base for j in range(m)]
    slope = np.column_stack(columns)  # ȳ̂(w) = base + slope @ w, exactly (linearity)
    gain = C_m.T @ L
    w = np.linalg.solve(np.eye(m) + gain @ C_m @ slope, gain @ (y_m - C_m @ base))
    u_hat = u + w
    end, _ = integrate(u_hat)
    return end, d.B.T @ e + d.D @ u_hat  # the state at t_k+1, the outputs at t_k


@pytest.mark.parametrize("case", list(CASES))
def test_averaged_observer_is_exact_against_an_independent_integrator(case, rng):
    d, C_m, L = CASES[case](rng, 6)
    observer = ContinuousObserver.from_discretization(d, C_m, L)
    dt = 0.02
    discrete = observer.sampled(dt, "average")
    x = rng.standard_normal(d.dim)
    for _ in range(3):
        v = rng.standard_normal(len(observer.inputs))
        u, y_m = v[: d.n_ports], v[d.n_ports :]
        end, outputs = _reference_step(d, C_m, L, x, u, y_m, dt)
        ours_end = discrete.A @ x + discrete.B @ v
        ours_out = discrete.C @ x + discrete.D @ v
        # the integrator's tolerance 1e-12 on states of order 1, over ~1e3 steps: 1e-9
        assert np.max(np.abs(ours_end - end)) <= 1e-9 * np.max(np.abs(end))
        assert np.max(np.abs(ours_out - outputs)) <= 1e-9 * np.max(np.abs(outputs))
        x = end


def _runs_on_the_observers_own_model(case, rng, periods, *, perfect_start):
    """Averaged loops whose plant is the observer's model: random efforts and inputs."""
    d, C_m, L = CASES[case](rng, 8)
    observer = ContinuousObserver.from_discretization(d, C_m, L)
    x0 = rng.standard_normal(d.dim)
    n_steps = 60
    U = rng.standard_normal((n_steps + 1, d.n_ports))
    xhat0 = x0 if perfect_start else None
    for dt in periods:
        run = run_loop(
            d, observer, C_m, x0=x0, xhat0=xhat0, dt=dt, n_steps=n_steps, sampler="average", u=U
        )
        yield dt, d, run


@pytest.mark.parametrize("case", list(CASES))
def test_error_energy_never_increases_whatever_the_period(case, rng):
    # plant = the observer's own model: H̃_{k+1} - H̃_k = -∫ẽᵀRẽ - Δt (C_m ȳ̃)ᵀ L (C_m ȳ̃) <= 0
    # for every Δt (module docstring); random efforts excite every mode, random inputs must
    # cancel. Round-off: the exponentials are exact to ~1e-15 of the energy's scale.
    periods = (1e-3, 1e-2, 0.1, 1.0, 10.0)
    for dt, d, run in _runs_on_the_observers_own_model(case, rng, periods, perfect_start=False):
        energy = d.hamiltonian(run.x - run.xhat)
        increase = float(np.max(np.diff(energy)))
        assert increase <= 1e-12 * energy[0], (dt, increase / energy[0])
        assert energy[-1] < energy[0], dt


@pytest.mark.parametrize("case", list(CASES))
def test_a_perfect_estimate_stays_perfect(case, rng):
    # the error obeys ẽ_{k+1} = (Φ - ΓMKC_s) ẽ_k with no trace of the plant's state or
    # input: from ẽ_0 = 0 it stays at round-off (the held-mean update drifts by O(1) here)
    periods = (1e-3, 1e-2, 0.1)
    for dt, d, run in _runs_on_the_observers_own_model(case, rng, periods, perfect_start=True):
        drift = np.max(np.abs(run.x - run.xhat)) / np.max(np.abs(run.x))
        assert drift <= 1e-10, (dt, drift)
        model_outputs = run.yhat[:, : d.n_ports]
        scale = np.max(np.abs(run.y))
        assert np.max(np.abs(model_outputs - run.y)) <= 1e-10 * scale, dt


def test_the_continuous_observer_is_the_limit_of_the_averaged_one(rng):
    # Φ = I + F Δt + O(Δt²), Γ = G Δt + O(Δt²), C_s = H + O(Δt), D_s = D + O(Δt): the
    # averaged map is I + Δt A_o + O(Δt²) and its input map Δt B_o + O(Δt²), so both
    # generators converge at rate 1 (fitted on log Δt; round-off ε/Δt stays below 1e-9)
    d, C_m, L = _beam_with_feedthrough(rng, 4)
    observer = ContinuousObserver.from_discretization(d, C_m, L)
    periods = np.array([1e-4, 1e-5, 1e-6])
    errors = []
    for dt in periods:
        discrete = observer.sampled(dt, "average")
        errors.append(
            [
                np.max(np.abs((discrete.A - np.eye(d.dim)) / dt - observer.A))
                / np.max(np.abs(observer.A)),
                np.max(np.abs(discrete.B / dt - observer.B)) / np.max(np.abs(observer.B)),
            ]
        )
    rates = np.polyfit(np.log(periods), np.log(np.array(errors)), 1)[0]
    assert np.all((rates > 0.95) & (rates < 1.05)), f"observed rates {rates}, expected 1"
    assert max(errors[-1]) < 1e-3
