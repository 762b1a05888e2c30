"""Structure of the discretizations: PH form, exact energy balance, beam modes."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl
from numeric_models import BUILTINS, COUPLED, FEEDTHROUGH, VARYING, numeric
from scipy.optimize import brentq

from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.stepping import step_lti

FD_MODELS = ("wave", "timoshenko", "euler-bernoulli")
CASES = [(name, "galerkin", 24) for name in BUILTINS] + [(n, "fd", 30) for n in FD_MODELS]


def _numeric(name):
    if name == "varying":
        return to_numeric(VARYING)
    if name == "coupled":
        return to_numeric(COUPLED)
    if name == "feedthrough":
        return to_numeric(FEEDTHROUGH)
    return numeric(name)


@pytest.mark.parametrize(
    ("name", "method", "res"),
    [
        *CASES,
        ("varying", "galerkin", 24),
        ("varying", "fd", 40),
        ("coupled", "galerkin", 20),
        ("feedthrough", "galerkin", 20),
        ("feedthrough", "fd", 20),
    ],
)
def test_port_hamiltonian_structure_and_exact_energy_balance(name, method, res, rng):
    # The discrete system E e' = (J - R) e + B u, y = B^T e + D u must have J = -J^T,
    # R = R^T >= 0, E = E^T > 0, D = -D^T; then dH_d/dt = e^T E e' equals
    # -e^T R e + u^T y identically.  Checked for random e and u: the residual is pure
    # round-off, so 1e-12 relative to the size of the terms.
    d = discretize(_numeric(name), method, res)
    s = d.check_structure()
    assert s["J_skew"] == 0.0
    assert s["R_sym"] < 1e-15
    assert s["D_skew"] == 0.0
    assert s["R_min_eig"] > -1e-12 * max(1.0, np.abs(d.R).max())
    assert s["E_min_eig"] > 0
    for _ in range(5):
        e = rng.standard_normal(d.dim)
        u = rng.standard_normal(d.n_ports)
        edot = np.linalg.solve(d.E, (d.J - d.R) @ e + d.B @ u)
        dH = e @ d.E @ edot
        y = d.output(e, u)
        terms = np.array([e @ d.J @ e, e @ d.R @ e, u @ y, e @ d.B @ u])
        rhs = -e @ d.R @ e + u @ y
        scale = np.abs(terms).sum() + abs(e @ d.E @ edot)
        assert abs(dH - rhs) <= 1e-12 * scale, (dH, rhs, scale)


@pytest.mark.parametrize("name", [*BUILTINS, "varying"])
def test_weak_form_identity_of_the_galerkin_method(name):
    # Integration by parts: sym(A - T^T Y^T U T) = int Psi^T sym(P0) Psi = -R, exactly
    # for polynomials; a residual above round-off would mean a wrong port identity.
    d = discretize(_numeric(name), "galerkin", 20)
    assert d.info["weak_form_symmetry_defect"] < 1e-11


def test_fd_refuses_unsupported_models():
    with pytest.raises(NumericError, match="N = 1 and 2"):
        discretize(numeric("airy"), "fd", 20)
    with pytest.raises(NumericError, match="block diagonal"):
        discretize(to_numeric(COUPLED), "fd", 20)
    with pytest.raises(NumericError, match="method must be one of 'galerkin', 'fd'"):
        discretize(numeric("wave"), "chebyshev", 20)
    with pytest.raises(NumericError, match="at least N \\+ 1"):
        discretize(numeric("airy"), "galerkin", 3)


def _cantilever_betas(count):
    # Clamped-free Euler-Bernoulli beam: cos(b) cosh(b) = -1 (classical, e.g. Meirovitch).
    f = lambda b: np.cos(b) * np.cosh(b) + 1.0  # noqa: E731
    return np.array(
        [brentq(f, (k + 0.5) * np.pi - 1.0, (k + 0.5) * np.pi + 1.0) for k in range(count)]
    )


def test_cantilever_roots_match_the_tabulated_values():
    # DESIGN.md: beta L = 1.8751, 4.6941, 7.8548, 10.9955, 14.1372 (5 significant digits).
    np.testing.assert_allclose(
        _cantilever_betas(5), [1.8751, 4.6941, 7.8548, 10.9955, 14.1372], atol=6e-5
    )


@pytest.mark.parametrize(("method", "res", "rtol"), [("galerkin", 30, 1e-10), ("fd", 140, 2e-3)])
def test_cantilever_frequencies(method, res, rtol):
    # Undamped beam (d = 0), u = 0: clamped at 0 (e1 = e1' = 0), free at 1 (e2 = e2' = 0),
    # omega_k = beta_k^2.  Galerkin is spectral (1e-10); FD is second order: the 5th mode
    # at h = 1/140 is off by ~1.2e-3 (measured; the error ratio 4.1-4.3 between 70 and 140
    # nodes per group confirms h^2).
    d = discretize(numeric("euler-bernoulli", d=0), method, res)
    lam = sl.eigvals(d.closed_matrix(), d.E)
    omega = np.sort(lam.imag[lam.imag > 0])[:5]
    np.testing.assert_allclose(omega, _cantilever_betas(5) ** 2, rtol=rtol)


@pytest.mark.parametrize("method", ["galerkin", "fd"])
def test_viscous_damping_shifts_every_mode_by_minus_half_d(method):
    # rho w_tt + d w_t = -w_zzzz with rho = EI = 1: lambda = -d/2 +- i sqrt(omega^2 - d^2/4)
    # for every mode; the discretization keeps R = d * (mass on e1) so this holds for all
    # discrete modes that oscillate, to round-off.
    dd = 0.2
    d = discretize(numeric("euler-bernoulli", d=dd), method, 30)
    lam = sl.eigvals(d.closed_matrix(), d.E)
    osc = lam[np.abs(lam.imag) > 1.0]
    np.testing.assert_allclose(osc.real, -dd / 2, atol=1e-9 * np.abs(lam).max() ** 0.5)


def test_implicit_midpoint_conserves_energy_of_an_undamped_closed_system(rng):
    # Implicit midpoint is the Cayley transform of E^{-1}J: for R = 0, u = 0 it preserves
    # e^T E e exactly (to round-off per step): relative drift over 400 steps < 1e-12.
    d = discretize(numeric("euler-bernoulli", d=0), "galerkin", 24)
    e0 = rng.standard_normal(d.dim)
    t = np.linspace(0.0, 4.0, 401)
    X = step_lti(d.E, d.J - d.R, d.B, e0, t, scheme="midpoint")
    H = d.hamiltonian(X)
    assert np.max(np.abs(H / H[0] - 1.0)) < 1e-12


def test_implicit_midpoint_discrete_energy_balance_with_damping_and_input(rng):
    # For implicit midpoint H_{k+1} - H_k = dt (-m^T R m + u_m^T y_m) exactly, with
    # m = (e_k + e_{k+1})/2 and u_m the averaged input: the discrete analogue of the
    # power balance, to round-off.
    d = discretize(numeric("euler-bernoulli"), "fd", 20)
    t = np.linspace(0.0, 1.0, 101)
    dt = t[1] - t[0]
    U = np.column_stack([np.sin(3 * t), np.cos(t), t, 1 - t])
    X = step_lti(d.E, d.J - d.R, d.B, rng.standard_normal(d.dim), t, U, scheme="midpoint")
    H = d.hamiltonian(X)
    m = 0.5 * (X[1:] + X[:-1])
    um = 0.5 * (U[1:] + U[:-1])
    power = -np.einsum("ki,ij,kj->k", m, d.R, m) + np.einsum("ki,ki->k", um, d.output(m, um))
    np.testing.assert_allclose(np.diff(H), dt * power, rtol=0, atol=1e-12 * np.abs(H).max())


def test_fd_feedthrough_from_port_change_and_observer_loop():
    # Outputs y = y_nat + K u (K skew) and scaled inputs: the staggered grid imposes its
    # native ports, so u = S u_nat, y = S^-T y_nat + K_d u_nat gives B = B_nat S^-1 and the
    # skew feedthrough D = K_d S^-1.  Here u = (2 e1(0), e2(1)), y = (-e2(0)/2 + e2(1),
    # e1(1) - 2 e1(0)): S = diag(2, 1), and D = [[0, 1], [-1, 0]] by hand.
    nm = to_numeric(FEEDTHROUGH)
    d = discretize(nm, "fd", 20)
    np.testing.assert_allclose(d.D, [[0.0, 1.0], [-1.0, 0.0]], atol=1e-14)
    # The observer loop u_hat = u + K (y - y_hat) with y_hat = B^T e + D u_hat is solved
    # exactly; the error energy must agree with Galerkin (which has D = 0 and the same
    # PDE).  The error solution has kinks (second-order compatibility fails), so both
    # converge algebraically: measured max |FD200 - Gal60| = 1.0e-5 (FD100: 2.6e-5,
    # FD400: 6.4e-6; Gal30: 3.3e-5, Gal45: 1.2e-5 against Gal60), bound 1e-4 H_err(0).
    from phdesign.numeric.time.simulation import simulate

    def x0(z):
        return np.column_stack([np.sin(np.pi * z), 0 * z])

    C, L = np.array([[0.0, 1.0]]), np.array([[0.5]])
    a = simulate(
        nm,
        C,
        L,
        x0=x0,
        options=SimulationOptions(t_end=2.0, samples=101, method="fd", resolution=200),
    )
    b = simulate(
        nm,
        C,
        L,
        x0=x0,
        options=SimulationOptions(t_end=2.0, samples=101, method="galerkin", resolution=60),
    )
    assert np.max(np.abs(a.H_err - b.H_err)) < 1e-4 * b.H_err[0]
