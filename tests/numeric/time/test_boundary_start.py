"""Initial states of the boundary systems (issue 26): a simulation starts them where asked.

The string with a tip mass (rho = T = 1 on [0, 1], u(0) = 0, m u_tt(1) = -u_z(1) - c u_t(1))
has the modes u = Re(sinh(lam z) e^{lam t}) with (m lam + c) sinh(lam) + cosh(lam) = 0
(tests/numeric/test_boundary_dynamics.py derives it). Started on one mode, field *and* mass
(x_c = m u_t(1) = Re(m lam sinh(lam))), the solution stays that mode: its mass velocity,
energy H + H_c and the audit dH/dt = -c u_t(1)^2 are closed forms, computed here in mpmath.
"""

from __future__ import annotations

import json

import mpmath
import numpy as np
import pytest

import phdesign as phd
from phdesign.cli import main
from phdesign.core.errors import NumericError, ParameterError
from phdesign.numeric.boundary_start import with_boundary_states

M, C = 2.0, 0.5


def lowest_oscillating_mode(m, c):
    with mpmath.workdps(30):
        delta = lambda lam: (m * lam + c) * mpmath.sinh(lam) + mpmath.cosh(lam)  # noqa: E731
        return complex(mpmath.findroot(delta, mpmath.mpc(-0.1, 3.3)))


def mode_start(lam, m):
    """The mode at t = 0: momentum u_t, strain u_z, and the mass's momentum m u_t(1)."""

    def field(z):
        z = np.atleast_1d(z)
        return np.column_stack([(lam * np.sinh(lam * z)).real, (lam * np.cosh(lam * z)).real])

    return phd.CoupledInitialState(field, np.array([(m * lam * np.sinh(lam)).real]))


def mode_energy(lam, m, t):
    """H + H_c of the mode at time t: 1/2 int (u_t^2 + u_z^2) dz + 1/2 m u_t(1)^2."""
    lam = mpmath.mpc(lam)

    def density(z):
        g = mpmath.exp(lam * t)
        return (
            (lam * mpmath.sinh(lam * z) * g).real ** 2 + (lam * mpmath.cosh(lam * z) * g).real ** 2
        ) / 2

    tip = (lam * mpmath.sinh(lam) * mpmath.exp(lam * t)).real
    return float(mpmath.quad(density, [0, 1]) + m * tip**2 / 2)


def test_a_mode_started_with_its_mass_stays_that_mode():
    lam = lowest_oscillating_mode(M, C)
    plant = phd.Plant(phd.load("string-tip-mass"), {"m": M, "c": C})
    run = plant.simulate(mode_start(lam, M), t_end=3, samples=16)
    # the mass velocity u_t(1, t) = Re(lam sinh(lam) e^{lam t}); Galerkin of degree 20 resolves
    # this smooth mode to round-off (its eigenvalue to 1e-10: test_boundary_dynamics), and the
    # stepping is exact: 1e-10 of the peak leaves three orders for round-off (1e-13 measured)
    velocity = (lam * np.sinh(lam) * np.exp(lam * run.t)).real
    assert run.output_labels[-1] == "mass velocity"
    assert np.max(np.abs(run.y[:, -1] - velocity)) < 1e-10 * np.max(np.abs(velocity))
    # the mass's position u(1, t) = Re(sinh(lam) e^{lam t}): the [displacement] integrates
    # the strain from the fixed end (u(0) = 0); the same 1e-10 of the peak
    position = (np.sinh(lam) * np.exp(lam * run.t)).real
    assert run.z_w[-1] == 1.0
    assert np.max(np.abs(run.w[:, -1] - position)) < 1e-10 * np.max(np.abs(position))
    energy = np.array([mode_energy(lam, M, t) for t in run.t])
    np.testing.assert_allclose(run.H, energy, rtol=1e-10)
    # the energy audit of H + H_c against the closed form: H(t) = H(0) - c int_0^t u_t(1)^2
    with mpmath.workdps(20):
        tip = lambda s: (mpmath.mpc(lam) * mpmath.sinh(lam) * mpmath.exp(lam * s)).real  # noqa: E731
        dissipated = [float(C * mpmath.quad(lambda s: tip(s) ** 2, [0, t])) for t in run.t]
    assert np.max(np.abs(run.H - (energy[0] - np.array(dissipated)))) < 1e-10 * energy[0]
    # without its boundary state the same field is no mode: the mass would start at rest
    at_rest = plant.simulate(mode_start(lam, M).field, t_end=3, samples=16)
    assert np.max(np.abs(at_rest.y[:, -1] - velocity)) > 1e-2 * np.max(np.abs(velocity))


def test_an_undamped_tip_mass_started_alone_keeps_its_energy():
    # c = 0: lossless, H + H_c = H_c(0) = p0^2 / (2 m) for all t (the mass's momentum p0, the
    # string at rest); exact stepping keeps it to round-off (1e-12 relative)
    plant = phd.Plant(phd.load("string-tip-mass"), {"m": 4, "c": 0})
    run = plant.simulate("mass momentum: 2", t_end=5, samples=26)
    np.testing.assert_allclose(run.H, 2**2 / (2 * 4), rtol=1e-12)
    assert abs(run.y[0, -1] - 2 / 4) < 1e-14  # the mass velocity p0 / m at t = 0
    assert np.max(np.abs(run.y[5:, 0])) > 1e-2  # and the wave reaches z = 0


def test_the_observer_estimate_starts_with_its_own_boundary_state():
    # x0 the mode, xhat0 only the mass (momentum q): H_hat(0) = q^2 / (2 m) and
    # H_err(0) = field energy + (p - q)^2 / (2 m), p = Re(m lam sinh(lam))
    lam = lowest_oscillating_mode(M, C)
    obs = phd.Observer(phd.load("string-tip-mass"), [2], gain=1, parameters={"m": M, "c": C})
    start = mode_start(lam, M)
    (p,) = start.boundary
    run = obs.simulate(start, xhat0="mass.x1: m/4", t_end=1, samples=3)
    q = M / 4
    assert run.H_hat[0] == pytest.approx(q**2 / (2 * M), rel=1e-13)
    field = mode_energy(lam, M, 0) - p**2 / (2 * M)
    assert run.H_err[0] == pytest.approx(field + (p - q) ** 2 / (2 * M), rel=1e-10)
    assert np.all(np.diff(run.H_err) <= 1e-12 * run.H_err[0])  # the error system dissipates


def test_the_command_line_reads_boundary_states_in_x0(capsys):
    status = main(
        [
            "simulate", "string-tip-mass", "--param", "c=0", "--param", "m=2",
            "--x0", "mass momentum: 1/m", "--t-end", "2", "--samples", "5", "--json",
        ]
    )  # fmt: skip
    assert status == 0
    out = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose(out["H"], (1 / 2) ** 2 / (2 * 2), rtol=1e-12)


def test_bad_boundary_states_are_refused_naming_them():
    plant = phd.Plant(phd.load("string-motor"))
    with pytest.raises(ParameterError, match=r"expected 2 boundary states \(winding flux, "):
        with_boundary_states(None, [1], plant.numeric)
    with pytest.raises(ParameterError, match="unknown boundary state 'rotor'; expected one of"):
        with_boundary_states(None, {"rotor": 1}, plant.numeric)
    with pytest.raises(NumericError, match=r"x0.boundary must hold the 2 boundary states"):
        plant.simulate(phd.CoupledInitialState(lambda z: np.zeros((z.size, 2)), np.ones(3)))
    wave = phd.Plant(phd.load("wave"))
    with pytest.raises(ParameterError, match="model 'wave' has no boundary systems"):
        with_boundary_states(None, [1], wave.numeric)


def test_a_sampled_observer_estimates_the_mass_from_its_own_start():
    # the sampled observer (period dt, averaging sampler) is a discretization of its own;
    # its mass state maps to the plant's by the identity: H_err(0) = (p - q)^2 / (2 m)
    # exactly, and the sampled error follows the continuous one to O(dt) (1e-3 at dt = 0.01;
    # 2e-6 measured, the averaging sampler is second order)
    obs = phd.Observer(phd.load("string-tip-mass"), [2], gain=1)
    start = {"x0": "mass momentum: 1", "xhat0": "mass momentum: 0.5", "t_end": 1, "samples": 11}
    sampled = obs.simulate(**start, dt=0.01)
    continuous = obs.simulate(**start)
    assert sampled.H_err[0] == pytest.approx(0.5**2 / 2, rel=1e-13)
    np.testing.assert_allclose(sampled.x_c_hat[0], [0.5])
    assert np.max(np.abs(sampled.H_err - continuous.H_err)) < 1e-3 * continuous.H_err[0]
