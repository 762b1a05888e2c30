"""Simulation driven by the model's disturbances: a signal ``w`` and white disturbances.

Closed forms of the damped-tip string (ρ = T = 1, fixed at 0, damper k at 1, force w,
z_p = ∫₀¹ u_t dz; :mod:`disturbance_models`).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from disturbance_models import damped_tip_wave, string_with_unknown_tip_force, wave_transfer

from phdesign import Observer
from phdesign.core.errors import ObserverError, ParameterError
from phdesign.design.plant import Plant
from phdesign.io import model_from_dict, model_to_dict
from phdesign.models import load_builtin
from phdesign.numeric.discretization.functionals import performance_functional
from phdesign.numeric.disturbance_inputs import performance_terms


def performance_row(plant: Plant) -> np.ndarray:
    """The row C_p of the model's one performance output on the plant's discretization."""
    (terms,) = performance_terms(plant.design_model, plant.numeric)
    return performance_functional(plant.numeric, *terms).row(plant.discrete())


def string_with_force():
    """The built-in string (inputs e1(0), e2(1)) under a uniform force, ∫ e1 judged."""
    data = model_to_dict(load_builtin("wave"))
    data["disturbances"] = {"B": [[1], [0]]}
    data["performance"] = {"outputs": ["integral(e1)"]}
    return model_from_dict(data)


def viscous_damped_tip_wave(k: float):
    """The damped-tip string with viscous damping d = 1 on the momentum (P0 = -diag(1, 0)).

    Every mode of every discretization decays at least like e^{-t/2} (the top, unresolved
    ones at exactly d/2: they lose the tip damper, not the viscous one), so a run from
    rest reaches its steady state, and white noise its stationary variance, in tens of
    seconds.  Without d the top modes of the discretization are nearly undamped.
    """
    return damped_tip_wave(k, P={0: [[-1, 0], [0, 0]], 1: [[0, 1], [1, 0]]})


def test_a_constant_force_bends_the_damped_string_to_its_static_shape():
    r"""Steady state under w = 1: p_t = q_z - p + w, q_t = p_z, p(0) = 0, q(1) = -k p(1).

    At rest p ≡ 0 (p_z = q_t = 0 and p(0) = 0), so q(1) = 0 and q_z = -1: q = 1 - z, and
    H = ½∫₀¹ (1 - z)² dz = 1/6.  Started there, the state stays (q is linear: the
    Galerkin space holds it, to round-off); from rest every mode decays at least like
    e^{-t/2}: by t = 80 the transient is below e^{-40} of its start.  Tolerance 1e-12.
    """
    plant = Plant(viscous_damped_tip_wave(0.5))
    still = plant.simulate("x2: 1 - z", w="w1: 1", t_end=10.0, samples=3)
    np.testing.assert_allclose(still.H, 1 / 6, rtol=0, atol=1e-12)
    run = plant.simulate(w="w1: 1", t_end=80.0, samples=3)
    assert run.H[0] == 0.0
    assert run.H[-1] == pytest.approx(1 / 6, abs=1e-12)


def test_the_observers_error_under_a_sinusoidal_force_is_the_transfer_function():
    r"""The observer of the string with sensor y2 = e1(1) and gain k knows u, not w.

    Its error obeys ẽ1(0) = 0 (ũ1 = 0) and ẽ2(1) = -k ẽ1(1): the damped-tip string driven
    by the same force, so z̃_p(t) → Im(G(3i) e^{3it}) with G hand-derived
    (:func:`disturbance_models.wave_transfer`).  Tolerance 2e-5: w is linear between the
    output samples (dt = 1/400: error ≤ dt²·9/8 = 7e-6 in w, times ‖G‖∞ = 0.84), the
    transient is e^{-0.549·30} = 7e-8 of its start.
    """
    k, omega = 0.5, 3.0
    obs = Observer(string_with_force(), sensors=[2], gain=k)
    run = obs.simulate(w="w1: sin(3*t)", t_end=30.0, samples=12001)
    error = (run.states - run.states_hat) @ performance_row(obs.plant)
    G = wave_transfer(1j * omega, k)
    late = run.t >= 28.0
    exact = (G * np.exp(1j * omega * run.t[late])).imag
    np.testing.assert_allclose(error[late], exact, rtol=0, atol=2e-5)
    # the plant (lossless, free at 1) is driven too: the observer does not see w
    assert np.max(np.abs(run.states @ performance_row(obs.plant))) > 0.1


def test_an_unknown_tip_force_reaches_the_error_by_its_hand_derived_transfer_function():
    r"""The string with its tip stress input u2 marked unknown, y2 = e1(1) measured, gain k.

    The observer does not know u2: its error obeys ẽ1(0) = 0 and u_z(1) = -k u_t(1) + w_b.
    Laplace in t from rest: U = A sinh(sz), A s cosh s = -k s A sinh s + W, so
    Z = ∫₀¹ sU dz = A (cosh s - 1) and G_b(s) = (cosh s - 1)/(s (cosh s + k sinh s)).
    Under w_b = sin(3t), z̃_p(t) → Im(G_b(3i) e^{3it}); tolerance 2e-5 as for the force
    (the same sampling and transient).
    """
    k, omega = 0.5, 3.0
    string = string_with_unknown_tip_force(["integral(e1)"])
    obs = Observer(string, sensors=[2], gain=k)
    run = obs.simulate(w="u2: sin(3*t)", t_end=30.0, samples=12001)
    error = (run.states - run.states_hat) @ performance_row(obs.plant)
    s = 1j * omega
    G = (np.cosh(s) - 1) / (s * (np.cosh(s) + k * np.sinh(s)))
    late = run.t >= 28.0
    np.testing.assert_allclose(error[late], (G * np.exp(s * run.t[late])).imag, atol=2e-5)


def test_an_unknown_input_is_no_known_input_of_an_observer():
    # the observer copies every input of u (û = u + C_mᵀL(y_m − ŷ_m)): u2, marked unknown,
    # cannot be driven through u in an observer's run (it would be known); w drives it.
    # The plant alone has no observer to hide it from: there u drives it as any input.
    string = string_with_unknown_tip_force(["integral(e1)"])
    obs = Observer(string, sensors=[2], gain=0.5)
    refused = r"u2 is marked unknown .* through `w` \(the same 'u2: \.\.\.' text\)"
    with pytest.raises(ParameterError, match=refused):
        obs.simulate(u="u2: sin(3*t)", t_end=1.0)
    by_u = Plant(string).simulate(u="u2: sin(3*t)", t_end=1.0, samples=11)
    by_w = Plant(string).simulate(w="u2: sin(3*t)", t_end=1.0, samples=11)
    # the same column of the same system, the same solver: equal to round-off
    np.testing.assert_allclose(by_u.states, by_w.states, atol=1e-12)


def test_white_disturbances_have_the_gain_reports_variance():
    r"""Var z_p = s ‖G‖₂² at the simulation's resolution (the gain report's Lyapunov value).

    One path of 20000 exact (Van Loan) samples 4 s apart of the viscously damped string
    (every mode decays at least like e^{-t/2}, so consecutive samples correlate by at most
    e^{-2} = 0.14): the sample variance of a zero-mean Gaussian sequence then has a
    relative standard error of about √(2/N)·(1 + 2·0.14²)^{1/2} = 1.0 %; tolerance 5 %
    (five standard errors), the seed fixed.  The first 10 samples (40 s) are left out: the
    path starts at rest.
    """
    model, s = viscous_damped_tip_wave(0.8), 0.5
    plant = Plant(model)
    run = plant.simulate(
        t_end=80000.0, samples=20001, disturbance_intensity=s, seed=7, check_resolution=False
    )
    z = run.states[10:] @ performance_row(plant)
    report = Plant(model, resolution=run.resolution).gain(max_resolution=run.resolution)
    assert report.resolutions == (run.resolution,)
    assert np.mean(z**2) == pytest.approx(s * report.h2.values[0] ** 2, rel=0.05)
    assert run.info["noise"] == "disturbance intensity 0.5"
    # an observer (y1 = -e2(0), gain 2, no sensor noise) does not know w: its error's
    # variance is the report's from w1 (the error system damps at least like the plant)
    obs = Observer(model, sensors=[1], gain=2, resolution=run.resolution)
    run = obs.simulate(
        t_end=80000.0, samples=20001, disturbance_intensity=s, seed=8, check_resolution=False
    )
    error = (run.states - run.states_hat)[10:] @ performance_row(plant)
    report = obs.gain(intensity=0, max_resolution=run.resolution)
    assert np.mean(error**2) == pytest.approx(s * report.h2.values[0] ** 2, rel=0.05)


def test_disturbances_need_a_model_that_has_them():
    with pytest.raises(ParameterError, match="has no disturbance channel"):
        Plant(load_builtin("wave")).simulate(w="w1: 1", t_end=1.0)
    with pytest.raises(ParameterError, match="unknown disturbance 'w2'"):
        Plant(damped_tip_wave(0.5)).simulate(w="w2: 1", t_end=1.0)
    with pytest.raises(ParameterError, match="has no disturbance channel"):
        Plant(load_builtin("wave")).simulate(disturbance_intensity=1.0, t_end=1.0)
    obs = Observer(string_with_force(), sensors=[2], gain=1)
    with pytest.raises(ObserverError, match="continuous observer"):
        obs.simulate(w=lambda t: [math.sin(t)], t_end=1.0, dt=0.01)
