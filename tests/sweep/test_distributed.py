"""z-dependent P0(z): validation on [a, b] and discretization by quadrature.

The spectrum is checked against the characteristic function of the variable-coefficient
ODE (a damping linear in z: an Airy equation), evaluated from its exact Taylor series in
mpmath.
"""

from __future__ import annotations

import itertools

import mpmath
import numpy as np
import pytest
import scipy.linalg as sl
import sympy

from phdesign.core.errors import ExpressionError, ModelError
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.inputs import initial_state_function
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.simulation import simulate
from phdesign.symbolic.model import BCPHS

D0 = 0.5


def string(P0, interval=(0, 1), **extra):
    """A unit string, fixed at a and free at b when u = 0, with distributed P0(z)."""
    b = interval[1]
    return BCPHS.define(
        name="string",
        interval=interval,
        order=1,
        P={0: P0, 1: [[0, 1], [1, 0]]},
        H=[[1, 0], [0, 1]],
        inputs=[f"e1({interval[0]})", f"e2({b})"],
        **extra,
    )


def test_rational_P0_is_validated_exactly_and_a_sign_change_is_refused_at_its_point():
    damped = string([["-d0*(1 - z)", 0], [0, 0]], parameters={"d0": D0})
    assert "P0 + P0^T <= 0: exact on [a, b] at the parameter defaults" in damped.checks[1]
    # 1/100 - (z - 1/2)^2 > 0 near z = 1/2: inside (0, 1), where the minimum of
    # -(P0 + P0^T) = 2 (z - 1/2)^2 - 1/50 is attained
    with pytest.raises(ModelError, match=r"minimum -1/50 at z = 1/2 \(parameter defaults\)"):
        string([["1/100 - (z - 1/2)**2", 0], [0, 0]])
    # coupling: sym(P0) = [[-1, z], [z, -1]] is <= 0 iff |z| <= 1, fine on [0, 1] ...
    assert "exact on [a, b]" in string([["-1", "2*z"], [0, "-1"]]).checks[1]
    # ... not on [0, 2]: the 2 x 2 minor 4 - 4 z^2 is -12 at z = 2
    with pytest.raises(ModelError, match=r"principal minor \{1, 2\}.* minimum -12 at z = 2"):
        string([["-1", "2*z"], [0, "-1"]], interval=(0, 2))


def test_non_rational_P0_is_validated_on_a_grid():
    assert "grid of 2001 points" in string([["-exp(-z)", 0], [0, 0]]).checks[1]
    # -cos(3 z) changes sign at pi/6; P0 + P0^T = -2 cos(3z) is largest (2 cos 3 ...) at 1
    with pytest.raises(ModelError, match=r"largest eigenvalue 1.97998 at z = 1 \("):
        string([["-cos(3*z)", 0], [0, 0]])


def test_only_P0_and_H_may_depend_on_z_and_the_message_says_why():
    with pytest.raises(ExpressionError, match=r"derived for constant P_1\.\.P_N; only P0 and H"):
        BCPHS.define(
            name="s",
            interval=(0, 1),
            order=1,
            P={1: [[0, "1 + z"], ["1 + z", 0]]},
            H=[[1, 0], [0, 1]],
            inputs=["e1(0)", "e2(1)"],
        )


def _characteristic_roots(count: int) -> list[complex]:
    r"""Eigenvalues of λ e1 = e2' - d(z) e1, λ e2 = e1', e1(0) = 0, e2(1) = 0, d = d0 (1 - z).

    Eliminating e2: e1'' = (α + β z) e1 with α = λ² + d0 λ, β = -d0 λ (an Airy equation,
    whose Ai/Bi pair cancels catastrophically here).  e1 is entire: from e1(0) = 0,
    e1'(0) = 1 its Taylor coefficients obey c_{j+2} = (α c_j + β c_{j-1}) / ((j+2)(j+1)),
    and the characteristic function is F(λ) = e1'(1) = λ e2(1) = Σ j c_j (mpmath, 50
    digits, summed until the terms vanish).  Starting guesses from first-order
    perturbation of the undamped modes sin(ω z), ω = (m + 1/2) π:
    Re λ ≈ -½ ∫ d sin² / ∫ sin² = -d0/4 + d0/(4 ω²), Im λ ≈ ω.
    """

    def F(lam):
        alpha, beta = lam**2 + D0 * lam, -D0 * lam
        c = [mpmath.mpc(0), mpmath.mpc(1)]
        total, j = mpmath.mpc(1), 1
        while True:
            j += 1  # c_j from c_{j-2}, c_{j-3}
            c.append((alpha * c[j - 2] + (beta * c[j - 3] if j >= 3 else 0)) / (j * (j - 1)))
            total += j * c[j]
            if j > 20 and abs(c[j]) * j < mpmath.mpf(10) ** -45 * abs(total):
                return total

    roots = []
    with mpmath.workdps(50):
        for m in range(count):
            omega = (m + 0.5) * np.pi
            guess = mpmath.mpc(-D0 / 4 + D0 / (4 * omega**2), omega)
            roots.append(complex(mpmath.findroot(F, guess)))
    return roots


def test_spectrum_with_variable_damping_matches_the_characteristic_function():
    roots = _characteristic_roots(5)
    # the perturbation formula orders the modes: Re λ_m decreases towards -d0/4
    assert all(a.real > b.real > -D0 / 4 for a, b in itertools.pairwise(roots))
    nm = to_numeric(string([["-d0*(1 - z)", 0], [0, 0]], parameters={"d0": D0}))
    assert not nm.P0_constant
    assert np.isnan(nm.P[0]).all()
    report = spectrum(nm, count=10)  # the five rightmost modes and their conjugates
    assert report.converged
    assert abs(report.spectral_abscissa - roots[0].real) < 1e-10  # spectral accuracy
    for root in roots:
        nearest = min(report.rightmost, key=lambda z: abs(z - root))
        assert abs(nearest - root) < 1e-9
    # the paper's finite differences (second order): errors fall like h^2
    errors = []
    for m in (40, 80):
        d = discretize(nm, "fd", m)
        assert d.check_structure()["R_min_eig"] > -1e-14  # nodal P0 keeps R >= 0
        lam = sl.eigvals(d.closed_matrix(), d.E)
        errors.append(min(abs(lam - roots[0])))
    rate = np.log2(errors[0] / errors[1])
    assert 1.7 < rate < 2.3, f"observed FD rate {rate:.2f}, expected 2"


def test_simulation_with_variable_damping_keeps_its_exact_energy_balance():
    model = string([["-d0*(1 - z)", "z"], ["-z", 0]], parameters={"d0": D0})  # + skew coupling
    nm = to_numeric(model)
    d = discretize(nm, "galerkin", 20)
    # the weak form: ∫ Ψᵀ P0 Ψ splits into J (skew z-coupling) and R = -∫ Ψᵀ sym(P0) Ψ
    assert d.check_structure()["R_min_eig"] > -1e-13
    run = simulate(
        nm,
        x0=initial_state_function("x1: sin(pi*z)", nm),
        discrete=d,
        options=SimulationOptions(t_end=3.0),
    )
    assert run.info["energy_balance_residual_plant"] < 1e-12
    # dissipated energy is positive: H decreases monotonically
    assert np.all(np.diff(run.H) <= 1e-15)


def test_P0_z_round_trips_exactly():
    from phdesign.io import model_from_toml, model_to_toml

    model = string([["-d0*(1 - z)**2", "z/3"], ["-z/3", 0]], parameters={"d0": D0})
    again = model_from_toml(model_to_toml(model))
    assert again == model
    assert again.P[0] == sympy.Matrix(model.P[0])
