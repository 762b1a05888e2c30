"""Boundary dynamics (issue 26): discretizations, spectra and simulations of coupled models.

Every expected eigenvalue is a root of a characteristic equation derived below by hand and
solved in mpmath (never by phdesign's discretizations).
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
from scipy.linalg import expm

from phdesign.core.errors import NumericError
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.inputs import initial_state_function
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.simulation import simulate
from phdesign.symbolic.model import BCPHS

COUPLED = ("string-tip-mass", "beam-tip-body", "flexible-arm", "string-motor")


def eigenvalues(d):
    return np.linalg.eigvals(np.linalg.solve(d.E, d.J - d.R))


def refined_root(f, guess):
    """A root of ``f`` by mpmath's secant method from ``guess`` (30 digits)."""
    with mpmath.workdps(30):
        return complex(mpmath.findroot(f, mpmath.mpc(guess)))


@pytest.mark.parametrize("name", COUPLED)
def test_coupled_discretization_is_port_hamiltonian_with_exact_energy_balance(name, rng):
    # DiscretePHS checks E > 0, J skew, R >= 0 when built; the balance
    # e^T E e' = -e^T R e + u^T y must hold to round-off for any e and u (1e-12 relative).
    nm = to_numeric(load_builtin(name))
    d = discretize(nm, "galerkin", 20)
    n_pde, n_bs = d.info["boundary_states"]
    assert n_bs == sum(b.size for b in nm.boundary)
    assert d.dim == n_pde + n_bs
    assert d.n_ports == nm.n_ports == len(nm.input_labels)
    s = d.check_structure()
    assert s["J_skew"] == 0.0
    assert s["R_min_eig"] > -1e-12 * max(1.0, np.abs(d.R).max())
    for _ in range(3):
        e = rng.standard_normal(d.dim)
        u = rng.standard_normal(d.n_ports)
        dH = e @ (d.J - d.R) @ e + e @ d.B @ u
        rhs = -e @ d.R @ e + u @ d.output(e, u)
        assert abs(dH - rhs) <= 1e-12 * (abs(e @ d.J @ e) + abs(e @ d.R @ e) + abs(rhs))
    # the boundary states are no part of the field: zero in the effort basis
    assert np.all(d.effort_basis(np.linspace(0, 1, 5))[..., n_pde:] == 0)


def tip_mass_delta(m, c):
    # u = sinh(lam z) (u(0) = 0, rho = T = 1); m u_tt(1) = -u_z(1) - c u_t(1) gives
    # m lam^2 sinh(lam) = -lam cosh(lam) - c lam sinh(lam), i.e. (lam = 0 is no mode)
    return lambda lam: (m * lam + c) * mpmath.sinh(lam) + mpmath.cosh(lam)


@pytest.mark.parametrize(("m", "c"), [(1, 1), (0.5, 2)])
def test_string_with_tip_mass_and_damper_matches_its_characteristic_equation(m, c):
    nm = to_numeric(load_builtin("string-tip-mass"), {"m": m, "c": c})
    report = spectrum(nm)
    lam = report.eigenvalues[report.resolved]
    assert lam.size >= 10
    delta = tip_mass_delta(m, c)
    for z in lam:
        exact = refined_root(delta, z)
        assert abs(z - exact) < 1e-10 * max(1.0, abs(exact)), (z, exact)
    # damped only through the mass: no exponential decay, never "exponential"
    assert report.no_decay
    assert report.spectral_abscissa == 0.0
    assert "no exponential decay found" in str(report)


def test_tip_mass_real_parts_approach_zero_like_one_over_k_squared():
    # lam_k = i pi k + eps with tanh(eps) = -1/(m lam + c): eps ~ -(c - i m pi k)/(c^2 +
    # m^2 pi^2 k^2), so Re lam_k k^2 -> -c/(m pi)^2 (m = c = 1: -0.10132).
    delta = tip_mass_delta(1, 1)
    scaled = []
    for k in (10, 20, 40, 80):
        root = refined_root(delta, 1j * np.pi * k)
        assert abs(root.imag - np.pi * k) < 1.0 / k
        scaled.append(root.real * k**2)
    assert all(r < 0 for r in scaled)
    assert abs(scaled[-1] + 1 / np.pi**2) < 2e-3, scaled
    # the discretization's resolved modes follow the same law
    report = spectrum(to_numeric(load_builtin("string-tip-mass")))
    lam = report.eigenvalues[report.resolved & (report.eigenvalues.imag > 20)]
    k = np.round(lam.imag / np.pi)
    assert np.all(np.abs(lam.real * k**2 + 1 / np.pi**2) < 0.02 / np.pi**2 * 10), lam


def cantilever_with_tip_mass(mu):
    """Clamped at 0; a tip mass mu (no rotary inertia) at z = 1 where the moment is free."""
    return BCPHS.define(
        name="cantilever with tip mass",
        interval=(0, 1),
        order=2,
        P={2: [[0, -1], [1, 0]]},
        H=[[1, 0], [0, 1]],
        # power at 1: e1'(1) e2(1) - e1(1) e2'(1); the mass imposes the tip velocity e1(1)
        inputs=["e1(0)", "e1'(0)", "e1(1)", "e2(1)"],
        outputs=["e2'(0)", "-e2(0)", "-e2'(1)", "e1'(1)"],
        parameters={"mu": mu},
        boundary_systems=[
            {"name": "mass", "ports": [3], "J": [[0]], "R": [[0]], "Q": [["1/mu"]], "G": [[-1]]}
        ],
    )


@pytest.mark.parametrize("mu", [0.2, 1, 5])
def test_cantilever_with_tip_mass_matches_the_classical_frequency_equation(mu):
    # w = A(cosh bz - cos bz) + B(sinh bz - sin bz), w''(1) = 0 and EI w'''(1) = M w_tt(1)
    # = -mu b^4 w(1) (omega = b^2, rho = EI = 1); the 2 x 2 determinant reduces to
    # 1 + cos b cosh b + mu b (cos b sinh b - sin b cosh b) = 0 (e.g. Blevins, table 8-1).
    def freq(b):
        return (
            1
            + mpmath.cos(b) * mpmath.cosh(b)
            + mu * b * (mpmath.cos(b) * mpmath.sinh(b) - mpmath.sin(b) * mpmath.cosh(b))
        )

    lam = eigenvalues(discretize(to_numeric(cantilever_with_tip_mass(mu)), "galerkin", 40))
    assert np.max(np.abs(lam.real)) < 1e-9 * np.max(np.abs(lam))  # conservative
    omegas = np.sort(lam.imag[lam.imag > 1e-6])[:4]
    # every root of the frequency equation below the fifth mode, bracketed by sign changes
    grid = np.linspace(0.05, np.sqrt(omegas[-1]) + 1.0, 2000)
    signs = np.sign([float(freq(b)) for b in grid])
    roots = []
    with mpmath.workdps(30):
        for left, right in zip(
            grid[:-1][signs[:-1] != signs[1:]], grid[1:][signs[:-1] != signs[1:]], strict=True
        ):
            roots.append(float(mpmath.findroot(freq, (left, right), solver="anderson")))
    np.testing.assert_allclose(omegas, np.array(roots[:4]) ** 2, rtol=1e-9)


def motor_delta(T, Jm, Rw, Lw, kt):
    # u = sinh(lam (1 - z)) (u(1) = 0, rho = 1, T): the motor drives u_t(0) = lam sinh(lam)
    # with u_z(0) = -lam cosh(lam). Winding: Lw lam i = -Rw i - kt w; rotor:
    # Jm lam w = kt i + T u_z(0). Eliminating i = -kt w/(Lw lam + Rw) and dividing by lam:
    # (Jm lam (Lw lam + Rw) + kt^2) sinh(lam/a) ... with a = sqrt(T):
    a = mpmath.sqrt(T)

    def delta(lam):
        motor = Jm * lam * (Lw * lam + Rw) + kt**2
        return motor * mpmath.sinh(lam / a) + T / a * (Lw * lam + Rw) * mpmath.cosh(lam / a)

    return delta


def test_motor_driven_string_matches_its_characteristic_determinant():
    values = {"T": 2, "Jm": 2, "Rw": 0.5, "Lw": 0.25, "kt": 1.5}
    report = spectrum(to_numeric(load_builtin("string-motor"), values))
    lam = report.eigenvalues[report.resolved]
    assert lam.size >= 10
    delta = motor_delta(**values)
    for z in lam:
        exact = refined_root(delta, z)
        assert abs(z - exact) < 1e-10 * max(1.0, abs(exact)), (z, exact)
    assert report.no_decay  # the string's far end is a wall: damping only at z = 0


def test_beam_tip_body_tends_to_beam_tip_damper_as_mass_and_inertia_vanish():
    # M, J -> 0: EI w''(1) = -J w_tt'(1) -> 0 and EI w'''(1) = M w_tt(1) + c w_t(1) ->
    # c w_t(1), the tip damper with k = c. Mode j moves by O((M + J) omega_j^2): the two
    # lowest pairs are compared, and the gap must shrink in proportion to M = J.
    damper = eigenvalues(discretize(to_numeric(load_builtin("beam-tip-damper")), "galerkin", 40))
    reference = damper[np.argsort(np.abs(damper))][:4]
    errors = []
    for small in (1e-5, 1e-6):
        body = to_numeric(load_builtin("beam-tip-body"), {"M": small, "J": small})
        lam = eigenvalues(discretize(body, "galerkin", 40))
        errors.append(max(np.min(np.abs(lam - r)) for r in reference))
    assert errors[1] < 1e-4 * np.abs(reference).max(), errors
    assert 5 < errors[0] / errors[1] < 20, errors  # first order in M + J


def test_simulation_energy_audit_of_H_plus_H_c():
    # Exact stepping of E e' = (J - R) e: over each step h the energy drops by
    # e_k^T W e_k, W = int_0^h exp(F^T s) R exp(F s) ds (Van Loan's block exponential),
    # with H and R including the mass's H_c and damper; audited to 1e-10 of H(0).
    model = load_builtin("string-tip-mass")
    nm = to_numeric(model)
    x0 = initial_state_function("x1: sin(pi*z), x2: z", nm, model=model)
    run = simulate(nm, x0=x0, options=SimulationOptions(t_end=2.0, samples=41, resolution=20))
    d = discretize(nm, "galerkin", 20)
    F = np.linalg.solve(d.E, d.J - d.R)
    h = run.t[1] - run.t[0]
    n = d.dim
    block = expm(np.block([[-F.T, d.R], [np.zeros((n, n)), F]]) * h)
    W = block[n:, n:].T @ block[:n, n:]
    states = run.states
    H = 0.5 * np.einsum("ti,ij,tj->t", states, d.E, states)
    np.testing.assert_allclose(H, run.H, rtol=1e-13, atol=0)
    dissipated = np.einsum("ti,ij,tj->t", states[:-1], W, states[:-1])
    assert np.max(np.abs(H[1:] - (H[:-1] - dissipated))) < 1e-10 * H[0]
    n_pde, _ = d.info["boundary_states"]
    mass_energy = 0.5 * states[:, n_pde:] ** 2 * d.E[n_pde, n_pde]
    assert mass_energy.max() > 1e-3 * H[0]  # the mass takes part


def test_finite_differences_where_they_apply(rng):
    # The arm's ports have mixed causality (velocities at 0, forces at 1): the staggered FD
    # applies and the hub's state is appended to it; its balance holds to round-off too.
    nm = to_numeric(load_builtin("flexible-arm"))
    d = discretize(nm, "fd", 30)
    assert d.info["boundary_states"][1] == 1
    e, u = rng.standard_normal(d.dim), rng.standard_normal(d.n_ports)
    dH = e @ (d.J - d.R) @ e + e @ d.B @ u
    rhs = -e @ d.R @ e + u @ d.output(e, u)
    assert abs(dH - rhs) <= 1e-12 * (abs(e @ d.R @ e) + abs(rhs) + abs(e @ d.J @ e))
    # second order: the lowest flexible frequency within 1 % of Galerkin's
    fd, gal = (eigenvalues(x) for x in (d, discretize(nm, "galerkin", 30)))
    first = [np.sort(np.abs(lam.imag[lam.imag > 1e-6]))[0] for lam in (fd, gal)]
    assert abs(first[0] - first[1]) < 1e-2 * first[1], first
    # a mass imposes the tip's velocity: velocity inputs at both ends, no mixed causality
    with pytest.raises(NumericError, match="staggered finite differences need mixed causality"):
        discretize(to_numeric(load_builtin("string-tip-mass")), "fd", 30)
