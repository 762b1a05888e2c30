"""H∞ and H₂ from in-domain disturbances to performance outputs, against closed forms."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from disturbance_models import (
    beam_under_load,
    damped_tip_wave,
    string_with_unknown_tip_force,
    wave_h2_squared,
    wave_hinf,
    wave_transfer,
)
from scipy.integrate import quad
from scipy.optimize import minimize_scalar

from phdesign import Observer
from phdesign.core.errors import NumericError
from phdesign.design.plant import Plant
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.functionals import disturbance_matrix
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.disturbance_inputs import disturbance_inputs


def test_the_hand_derivations_agree_with_each_other():
    # Parseval: (1/π)∫₀^∞ |G(iω)|² dω = ∫₀^∞ g² dt; the tail beyond 400 is 1/(400π)
    # to O(400⁻²) (G ≈ 1/s), an error far below the tolerance 1e-4 used here
    for k in (0.5, 2.0):
        head, _ = quad(lambda w, k=k: abs(wave_transfer(1j * w, k)) ** 2, 1e-9, 400, limit=2000)
        assert head / math.pi + 1 / (400 * math.pi) == pytest.approx(wave_h2_squared(k), rel=1e-4)
    assert wave_h2_squared(0.5) == pytest.approx(5 / 12, rel=1e-15)
    # the exact H∞ norm of PIETOOLS' example (its library's comment says γ = 2)
    assert wave_hinf(0.5)[0] == pytest.approx(0.84188, abs=5e-6)


@pytest.mark.slow
@pytest.mark.parametrize("k", [0.25, 0.5, 2.0])
def test_damped_tip_wave_hinf_matches_its_transfer_function(k):
    exact, frequency = wave_hinf(k)
    report = Plant(damped_tip_wave(k)).gain(max_resolution=45)
    assert report.hinf.converged, report
    # the peak is a smooth maximum of |G|: both agree to 1e-8 (observed: 1e-13)
    assert report.hinf.value == pytest.approx(exact, rel=1e-8)
    assert report.hinf.frequency == pytest.approx(frequency, rel=1e-5)
    # H₂ of the undamped string: unresolved modes lose the boundary damping and keep the
    # force's energy ever longer, so the discrete H₂ is not the PDE's; the report must
    # never state a wrong converged number
    h2 = report.h2
    if h2.converged:
        assert h2.value == pytest.approx(math.sqrt(wave_h2_squared(k)), rel=1e-6)
    else:
        assert h2.value is None
        assert any("did not converge" in w or "diverges" in w for w in report.warnings)


def cantilever_modes(count: int):
    """Cantilever modes (ρ = EI = 1): β from 1 + cosh β cos β = 0, φ normalized in L².

    φ = cosh βz - cos βz - σ(sinh βz - sin βz) loses e^β to cancellation: each mode is
    computed with β/ln 10 more digits.
    """
    out = []
    for j in range(1, count + 1):
        guess = (2 * j - 1) * math.pi / 2 + (0.3 if j == 1 else 0)
        with mpmath.workdps(30 + int(guess / 2.3)):
            b = mpmath.findroot(lambda x: mpmath.cos(x) + 1 / mpmath.cosh(x), guess)
            ch, c, sh, s = mpmath.cosh(b), mpmath.cos(b), mpmath.sinh(b), mpmath.sin(b)
            sigma = (ch + c) / (sh + s)
            tip = ch - c - sigma * (sh - s)
            area = (sh - s - sigma * (ch + c - 2)) / b  # ∫₀¹ φ dz
            out.append((float(b), float(tip * area)))
    return out


def test_beam_under_uniform_load_matches_the_modal_closed_form():
    r"""w_tt + d w_t + w_zzzz = f(t), clamped at 0, free at 1, z = w(1).

    Modes (proportional damping): G(s) = Σ c_m/(s² + d s + β_m⁴), c_m = φ_m(1)∫φ_m;
    h_m(t) = e^(-dt/2) sin(ν_m t)/ν_m, ν_m² = β_m⁴ - d²/4, and
    ∫₀^∞ h_m h_l = [d/(d² + (ν_m-ν_l)²) - d/(d² + (ν_m+ν_l)²)]/(2 ν_m ν_l).
    The terms decay like β⁻⁶: 80 modes leave less than 1e-12 (the static sum, β⁻⁵: 1e-10).
    """
    beam = beam_under_load()
    d = 0.2
    modes = cantilever_modes(80)
    beta = np.array([b for b, _ in modes])
    c = np.array([cm for _, cm in modes])
    assert np.sum(c / beta**4) == pytest.approx(1 / 8, rel=1e-9)  # static deflection qL⁴/8EI

    def G(w):
        return np.sum(c / (beta**4 - w**2 + 1j * d * w))

    peak = minimize_scalar(
        lambda w: -abs(G(w)), bounds=(3.0, 4.0), method="bounded", options={"xatol": 1e-12}
    )
    nu = np.sqrt(beta**4 - d**2 / 4)
    gram = (d / (d**2 + (nu[:, None] - nu) ** 2) - d / (d**2 + (nu[:, None] + nu) ** 2)) / (
        2 * np.outer(nu, nu)
    )
    h2 = math.sqrt(c @ gram @ c)
    report = Plant(beam).gain()
    assert report.hinf.converged, report
    assert report.h2.converged, report
    assert report.hinf.value == pytest.approx(-peak.fun, rel=1e-8)
    assert report.h2.value == pytest.approx(h2, rel=1e-8)


def test_the_disturbance_matrix_supplies_the_power_of_the_pde():
    """êᵀ B_d w = ∫ e_hᵀ B(z) w dz (the supplied power of the discrete energy balance).

    Checked against an independent rule (scipy's adaptive quad) for B(z) with z.
    """
    wave = damped_tip_wave(0.5, disturbances={"B": [["sin(3*z)", 1], ["z**2", 0]]})
    nm = to_numeric(wave)
    d = discretize(nm, "galerkin", 12)
    B, _ = disturbance_inputs(wave, nm)
    rng = np.random.default_rng(7)
    e_hat, w = rng.standard_normal(d.dim), rng.standard_normal(2)

    def density(z: float) -> float:
        e = d.effort_basis(np.array([z]))[0] @ e_hat  # (n,)
        return float(e @ B(np.array([z]))[0] @ w)

    power, _ = quad(density, 0.0, 1.0, epsabs=1e-13, epsrel=1e-13, limit=200)
    assert e_hat @ disturbance_matrix(d, B) @ w == pytest.approx(power, rel=1e-11)


def test_an_observer_splits_the_h2_norm_over_its_sources():
    """H₂² = Σ_sources H₂² (independent white sources); each source's H∞ ≤ the total's."""
    obs = Observer(beam_under_load(), sensors=[3, 4], gain=[0.1, 1])
    report = obs.gain(intensity=0.01, max_resolution=30)
    assert report.sources == ("w1", "nu1", "nu2")
    total = report.h2.values[-1] ** 2
    assert sum(s.h2.values[-1] ** 2 for s in report.by_source) == pytest.approx(total, rel=1e-12)
    for s in report.by_source:
        assert s.hinf.estimate.values[-1] <= report.hinf.estimate.values[-1] * (1 + 1e-12)
    # a steady load is invisible to velocity sensors: the static error is the plant's
    # static tip deflection, qL⁴/(8EI) = 1/8
    assert report.by_source[0].hinf.frequency == 0.0
    assert report.by_source[0].hinf.value == pytest.approx(0.125, rel=1e-8)


def test_a_trace_driven_at_the_boundary_has_no_h2_norm():
    """An unknown tip force on the string observed through the tip velocity (gain k).

    The error system is the string with the damper u_z(1) = -k u_t(1), driven by the
    force at the tip: the tip velocity's response tends to a constant at high frequency,
    so its H₂ norm is infinite and the report says so (diverging, no number), while the
    total momentum ∫ẽ1 has a finite one.
    """
    string = string_with_unknown_tip_force(["integral(e1)", "e1(1)"])
    report = Observer(string, sensors=[2], gain=0.5).gain(intensity=0)
    assert report.sources == ("u2",)
    momentum, tip = report.h2_outputs
    assert momentum.converged
    assert tip.value is None
    assert not tip.converged
    assert any("H2 to e1(1)" in w for w in report.warnings)


def test_no_disturbance_or_no_output_is_refused():
    with pytest.raises(NumericError, match="has no disturbance"):
        Plant(load_builtin("wave-damper")).gain(performance=["integral(e1)"])
    with pytest.raises(NumericError, match="needs performance outputs"):
        Plant(damped_tip_wave(0.5, performance=None)).gain()


@pytest.mark.slow
def test_no_boundary_observer_beats_the_kalman_bucy_filter():
    """The Kalman–Bucy filter has the least error variance of every linear estimator.

    Both estimate the same discretized plant from the same measurements, so at every
    resolution the boundary observer's H₂ error is at least the filter's, and its H∞
    norm at least the H∞-optimal level γ*; below would be a bug.  The static load is
    invisible to velocity sensors, so no filter does better than its deflection 1/8
    at ω = 0: γ* >= 0.125.
    """
    beam = beam_under_load()
    for gain in ([0.1, 1],):
        observer = Observer(beam, sensors=[3, 4], gain=gain)
        report = observer.gain(intensity=0.01, optimal=True, max_resolution=45)
        opt = report.optimal
        assert opt.h2.converged, report
        assert opt.hinf.converged, report
        for mine, best in zip(report.h2.values, opt.h2.values, strict=True):
            assert mine >= best * (1 - 1e-9), (gain, report.h2.values, opt.h2.values)
        assert report.hinf.value >= opt.hinf.value * (1 - 1e-9)
        assert opt.hinf.value >= 0.125 * (1 - 1e-6)
        assert "Kalman-Bucy H2 error" in str(report)


def test_the_kalman_error_is_the_filters_stationary_error():
    """tr(C_z P C_zᵀ) of the Riccati solution = the H₂ norm of the filter's error system.

    The error ξ̃' = (F - K H_y) ξ̃ + G n - K Σ^(1/2) n_ν with K = P H_yᵀ Σ⁻¹, solved by the
    Lyapunov route of the noise figures (an independent code path).
    """
    import scipy.linalg as sl

    from phdesign.numeric.discretization.functionals import performance_functional
    from phdesign.numeric.disturbance_inputs import performance_terms
    from phdesign.numeric.noise.disturbance import disturbance_statistics
    from phdesign.numeric.noise.lyapunov import triangularize
    from phdesign.numeric.noise.optimal import _whitened, kalman_h2

    beam = beam_under_load()
    nm = to_numeric(beam)
    d = discretize(nm, "galerkin", 16)
    B, unknown = disturbance_inputs(beam, nm)
    outputs = [performance_functional(nm, *t) for t in performance_terms(beam, nm)]
    C_m = np.eye(4)[[2, 3]]
    sigma = np.array([0.01, 0.04])
    stats = disturbance_statistics(d, B, unknown, outputs)
    F, G, Hy, Cz = _whitened(d, stats.plant_input, stats.rows, C_m)
    P = sl.solve_continuous_are(F.T, Hy.T, G @ G.T, np.diag(sigma))
    K = P @ Hy.T / sigma
    noise = np.hstack([G, -K * np.sqrt(sigma)])
    covariance = triangularize(F - K @ Hy, np.eye(d.dim), noise).covariance()
    expected = math.sqrt(np.trace(Cz @ covariance @ Cz.T))
    assert kalman_h2(d, stats.plant_input, stats.rows, C_m, sigma) == pytest.approx(
        expected, rel=1e-8
    )
