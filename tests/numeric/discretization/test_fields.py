r"""The Timoshenko beam's deflection and rotation against the static tip load.

Derivation (the built-in ``timoshenko``; x = (w_z - φ, ρ w_t, φ_z, I_ρ φ_t), e = Hx =
(K x1, w_t, EI x3, φ_t), P1 and P0 of DESIGN.md):

    ∂t x1 = ∂z e2 - e4 = ∂z w_t - φ_t,     ∂t x2 = ∂z e1 = ∂z (K (w_z - φ)),
    ∂t x3 = ∂z e4 = ∂z φ_t,                ∂t x4 = ∂z e3 + e1 = ∂z (EI φ_z) + K (w_z - φ),

the Timoshenko equations ρ w_tt = ∂z(K(w_z - φ)), I_ρ φ_tt = ∂z(EI φ_z) + K(w_z - φ).
So φ_z = x3 and w_z = x1 + φ.  The inputs at 0 are the velocities e2(0) = w_t(0) and
e4(0) = φ_t(0); with them zero, w(0) and φ(0) stay at their initial values, 0 for a
clamped beam, which fixes the constants:

    φ(z) = ∫_0^z x3,        w(z) = ∫_0^z x1 + ∫_0^z ∫_0^s x3.

Static tip load (inputs at both ends: u = (e2(0), e4(0), e1(1), e3(1)) = (0, 0, P, 0)):
∂z e1 = 0 gives the shear force e1 = K x1 = P; ∂z e3 = -e1 with e3(1) = 0 gives the
moment e3 = P (1 - z), x3 = P (1 - z)/EI.  Hence, by hand,

    φ(z) = P (z - z²/2)/EI,   w(z) = P z/K + P (z²/2 - z³/6)/EI,

and w(1) = P L/K + P L³/(3 EI) with L = 1: the textbook cantilever deflection
P L³/(3EI) + P L/(κGA) (K = κGA).  The static discrete state solves (J - R) ê + B u = 0.
The static efforts are polynomials of degree ≤ 1, which the Legendre Galerkin space holds
exactly, so the Galerkin numbers agree to round-off (1e-10 allows the conditioning of a
degree-8 solve, ~1e-13 observed); the staggered grid's trapezoidal integration of
x3 (linear) is exact once and O(h²) twice, so it is checked at the rate.
"""

from __future__ import annotations

import numpy as np
import pytest

import phdesign as phd
from phdesign.io import model_from_dict, model_to_dict
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.functionals import parse_functional
from phdesign.numeric.discretization.registry import discretize

P_TIP = 0.7
VALUES = {"K": 3.0, "EI": 2.0, "rho": 1.5, "I_rho": 0.5}


def _w(z: np.ndarray, K: float, EI: float) -> np.ndarray:
    """Hand derivation above: w = P z/K + P (z²/2 - z³/6)/EI."""
    return P_TIP * z / K + P_TIP * (z**2 / 2 - z**3 / 6) / EI


def _static(model, method: str, resolution: int):
    nm = to_numeric(model, VALUES)
    d = discretize(nm, method, resolution)
    u = np.array([0.0, 0.0, P_TIP, 0.0])
    e_hat = -np.linalg.solve(d.J - d.R, d.B @ u)
    return nm, d, e_hat


def test_timoshenko_tip_deflection_is_the_cantilever_formula() -> None:
    model = phd.load("timoshenko")
    nm, d, e_hat = _static(model, "galerkin", 8)
    K, EI = VALUES["K"], VALUES["EI"]
    tip = parse_functional("w(1)", nm, model).row(d) @ e_hat
    assert tip == pytest.approx(P_TIP / K + P_TIP / (3 * EI), rel=1e-10, abs=0)
    z = np.linspace(0.0, 1.0, 7)
    assert np.allclose(d.displacement_basis(z) @ e_hat, _w(z, K, EI), rtol=0, atol=1e-10)
    rotation = parse_functional("rotation(1)", nm, model).row(d) @ e_hat
    assert rotation == pytest.approx(P_TIP / (2 * EI), rel=1e-10, abs=0)  # φ(1) = P/(2EI)


def test_timoshenko_deflection_on_the_staggered_grid_converges_at_rate_two() -> None:
    model = phd.load("timoshenko")
    exact = P_TIP / VALUES["K"] + P_TIP / (3 * VALUES["EI"])
    sizes = np.array([10, 20, 40])
    errors = []
    for m in sizes:
        _nm, d, e_hat = _static(model, "fd", int(m))
        errors.append(abs(float(d.displacement_basis(np.array([1.0]))[0] @ e_hat) - exact))
    rate = -np.polyfit(np.log(sizes), np.log(errors), 1)[0]
    assert rate > 1.8, f"observed rate {rate:.2f}, errors {errors}"


def test_a_field_from_b_with_a_coefficient() -> None:
    """f(z) = -K ∫_1^z x1 = K ∫_z^1 x1 = P (1 - z): start b and a parameter coefficient."""
    data = model_to_dict(phd.load("timoshenko"))
    data["fields"]["shear_from_tip"] = {
        "terms": [{"component": 1, "integrations": 1, "coefficient": "-K"}],
        "start": "b",
    }
    model = model_from_dict(data)
    nm, d, e_hat = _static(model, "galerkin", 6)
    for z0 in (0.0, 0.25, 1.0):
        value = parse_functional(f"shear_from_tip({z0})", nm, model).row(d) @ e_hat
        assert value == pytest.approx(P_TIP * (1 - z0), abs=1e-12)
    nm, d, e_hat = _static(model, "fd", 20)
    basis = d.field_basis(nm.field_spec("shear_from_tip"))
    # x1 = P/K is constant: the trapezoidal rule integrates it exactly
    assert basis(np.array([0.0]))[0] @ e_hat == pytest.approx(P_TIP, abs=1e-12)


def test_timoshenko_first_mode_shape_against_the_characteristic_determinant() -> None:
    r"""The first mode's w(z)/w(1) and φ(1)/w(1) against an mpmath root of Δ(λ).

    Reference (``tests/characteristic.py``, nothing of phdesign's discretizations): the
    eigenvalue λ is a root of Δ(λ) = det(U (Φ(1); I)) refined with mpmath from the
    discrete one, the eigenfunction is e(z) = expm(M z) e(0) with M = P1⁻¹(λ H⁻¹ − P0) and
    e(0) the null vector of U (Φ(1); I); then x = H⁻¹ e and, by the Cauchy formula for
    repeated integrals, w(z) = ∫_0^z (x1(s) + (z − s) x3(s)) ds, φ(z) = ∫_0^z x3 (scipy's
    quad).  The Galerkin eigenvector at degree 24 resolves the first mode (ω = 1.8624 at
    these parameters) to round-off: its eigenvalue agrees to 8e-15, the normalized shape
    and rotation to 1.5e-15 and 5e-15; 1e-12 leaves room for the quadrature (asked for
    1e-13) and the null vector's conditioning.
    """
    import mpmath
    from characteristic import characteristic_determinant
    from scipy.integrate import quad
    from scipy.linalg import expm, null_space

    model = phd.load("timoshenko")
    nm = to_numeric(model, VALUES)
    d = discretize(nm, "galerkin", 24)
    lams, vecs = np.linalg.eig(np.linalg.solve(d.E, d.J - d.R))
    first = np.argmin(np.where(lams.imag > 1e-6, lams.imag, np.inf))
    delta = characteristic_determinant(nm, dps=30)
    with mpmath.workdps(30):
        lam = complex(mpmath.findroot(delta, mpmath.mpc(lams[first])))
    assert abs(lam - lams[first]) < 1e-9 * abs(lam)
    Hinv = np.linalg.inv(nm.H_at(np.array([0.0]))[0])
    M = np.linalg.solve(nm.P[1], lam * Hinv - nm.P[0])
    S = np.vstack([expm(M), np.eye(4)])
    e0 = null_space(nm.U @ S, rcond=1e-9)[:, 0]

    def x(s: float) -> np.ndarray:
        return Hinv @ (expm(M * s) @ e0)

    def integral(f, z0: float) -> complex:
        re = quad(lambda s: f(s).real, 0, z0, epsabs=1e-13)[0]
        im = quad(lambda s: f(s).imag, 0, z0, epsabs=1e-13)[0]
        return complex(re, im)

    def w_exact(z0: float) -> complex:
        return integral(lambda s: x(s)[0] + (z0 - s) * x(s)[2], z0)

    points = np.array([0.25, 0.5, 0.75, 1.0])
    exact = np.array([w_exact(z0) for z0 in points]) / w_exact(1.0)
    discrete = d.displacement_basis(points) @ vecs[:, first]
    assert np.allclose(discrete / discrete[-1], exact, rtol=0, atol=1e-12)
    phi_exact = integral(lambda s: x(s)[2], 1.0) / w_exact(1.0)
    phi = parse_functional("rotation(1)", nm, model).row(d) @ vecs[:, first] / discrete[-1]
    assert abs(phi - phi_exact) < 1e-12
