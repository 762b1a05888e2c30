"""The proved decay rate (issue 25, part 2) against closed forms, and its exact check.

Closed forms used below.

String, rho = T = 1 on [0, 1], fixed at 0 (e1(0) = u_t(0) = 0), damper at 1
(e2(1) = u_z(1) = -k u_t(1)).  A mode u = exp(lambda t) sinh(lambda z) meets u(0) = 0;
the damper gives lambda cosh(lambda) = -k lambda sinh(lambda), i.e.
(1 + k) e^(2 lambda) = k - 1, so

    lambda_m = 1/2 ln|(1 - k)/(1 + k)| + i pi (m + 1/2)   (k < 1, the right side < 0),
    lambda_m = 1/2 ln|(1 - k)/(1 + k)| + i pi m           (k > 1),

(DESIGN.md's "exact eigenvalues of the damped wave"; the brief of this work had the two
imaginary parts swapped).  Every mode has the same real part, the eigenvectors form a
Riesz basis, and the decay rate in the energy norm is -1/2 ln|(1 - k)/(1 + k)|: for
k = 1/2 and k = 2 both ln(3)/2.  The test solves the characteristic equation in mpmath
as well, from the predicted root, so the closed form is not only taken on trust.

Transport, x_t = x_z on [0, 1] (P1 = H = 1), with input u = e(1) - e(0) and output
y = (e(1) + e(0))/2 (u y = (e(1)^2 - e(0)^2)/2, the power), closed by u = -k y: then
(1 + k/2) e(1) = (1 - k/2) e(0), e(1) = r e(0) with r = (2 - k)/(2 + k); a value
travels from 1 to 0 in unit time, so
e(0, t + 1) = r e(0, t): lambda = ln|r| + i pi (2m or 2m + 1) and the rate is -ln|r|.

String with a damper at each end (tests/rate_models.STRING_TWO_ENDS, sensors y1, y2, gains
k0, k1): e2(0) = k0 e1(0), e2(1) = -k1 e1(1).  With H = I, lambda e = P1 e', so
e(1) = expm(lambda P1) e(0) = (cosh + k0 sinh, sinh + k0 cosh) for e(0) = (1, k0), and the
condition at 1 is Delta(lambda) = (1 + k0 k1) sinh(lambda) + (k0 + k1) cosh(lambda) = 0,
i.e. e^(2 lambda) = r0 r1 with r_i = (1 - k_i)/(1 + k_i) (the reflections at the two
ends): Re lambda = 1/2 ln|r0 r1| for every mode.  k0 = 1/2, k1 = 2: r0 r1 = -1/9, so
lambda = -ln 3 + i pi (m + 1/2), rate ln 3.
"""

from __future__ import annotations

import math
from dataclasses import replace
from fractions import Fraction

import mpmath
import pytest
import sympy
from rate_models import STRING_TWO_ENDS, TRANSPORT, closed

from phdesign.core.errors import ArgumentError, RateProofError
from phdesign.models import load_builtin
from phdesign.numeric.certified.exact_system import closed_system
from phdesign.numeric.certified.rate import prove_decay_rate
from phdesign.numeric.certified.rate_exact import failures
from phdesign.numeric.certified.rate_problem import rate_problem
from phdesign.proofcheck.check import _rate as check_rate
from phdesign.symbolic.observer import sensor_matrix

pytest.importorskip("cvxpy", reason="the proved decay rate needs the certify extra")


def string_rate(gain: str) -> float:
    """-Re lambda of the damped string, checked against the characteristic equation."""
    with mpmath.workdps(30):
        k = mpmath.mpf(sympy.Rational(gain).p) / sympy.Rational(gain).q
        closed_form = mpmath.log(abs((1 - k) / (1 + k))) / 2 + 1j * mpmath.pi * (
            mpmath.mpf(1) / 2 if k < 1 else 1
        )
        start = closed_form + mpmath.mpf("0.01")  # findroot must move to the root itself
        root = mpmath.findroot(lambda s: mpmath.cosh(s) + k * mpmath.sinh(s), start)
        assert abs(root - closed_form) < 1e-25  # the closed form is a root (30 digits)
        return -float(closed_form.real)


@pytest.fixture(scope="module")
def string_proof():
    return prove_decay_rate(closed(load_builtin("wave"), [2], "1/2"))


@pytest.mark.slow
@pytest.mark.parametrize("k", ["1/2", "2"])
def test_string_with_a_damper_reaches_ninety_percent_of_the_true_rate(k, string_proof):
    true = string_rate(k)
    # k = 1/2: the best rate the search finds; k = 2: the 90 % asked as a target
    if k == "1/2":
        proof = string_proof
    else:
        proof = prove_decay_rate(closed(load_builtin("wave"), [2], k), target=0.9 * true)
    # a Lyapunov estimate can never beat the true rate; the issue asks for >= 90 % of it
    # (the target is rounded down to 6 decimals, hence the 1e-6)
    assert 0.9 * true - 1e-6 <= proof.sigma < true, (float(proof.sigma), true)
    assert proof.M >= 1
    assert not failures(proof.problem, proof.data)


@pytest.mark.slow
def test_the_target_is_proved_as_asked():
    true = -math.log(3 / 5)  # transport with k = 1/2: r = (2 - k)/(2 + k) = 3/5
    proof = prove_decay_rate(closed(TRANSPORT, [1], "1/2"), target=0.9 * true)
    assert float(proof.sigma) == pytest.approx(0.9 * true, rel=1e-6)
    assert float(proof.sigma) <= 0.9 * true  # rounded down, never up
    with pytest.raises(RateProofError, match="above the best rate"):
        prove_decay_rate(closed(TRANSPORT, [1], "1/2"), target=1.01 * true)


def test_the_exact_check_rejects_a_perturbed_pi_and_a_perturbed_sigma(string_proof):
    problem, data = string_proof.problem, string_proof.data
    assert failures(problem, data) == []
    # one entry of Π₋ lowered: Π₋ stays symmetric only if both off-diagonal entries move,
    # so move the diagonal one, which breaks the symmetry of Π₋P₁H and a norm bound
    Pi = sympy.Matrix(data.Pi_minus)
    Pi[0, 0] = -10 * Pi[0, 0]
    found = failures(problem, replace(data, Pi_minus=sympy.ImmutableMatrix(Pi)))
    assert any("lower bound" in f for f in found), found
    # σ above the true rate ln(3)/2 ≈ 0.549 cannot satisfy the pointwise inequality
    found = failures(problem, replace(data, sigma=sympy.Rational(3, 5)))
    assert found
    assert all("pointwise" in f for f in found), found


@pytest.mark.slow
def test_a_timoshenko_beam_with_tip_dampers_gets_a_rate_below_its_abscissa():
    from phdesign.design.observer import Observer

    model = load_builtin("timoshenko")
    proof = prove_decay_rate(closed(model, [3, 4], "1"))
    spectrum = Observer(model, sensors=[3, 4], gain=1).spectrum()
    assert spectrum.converged
    # the converged abscissa agrees with independent determinants to 1e-10 (DESIGN.md);
    # the proved σ is a lower bound of the true rate, hence of |α|
    assert 0 < proof.sigma <= abs(spectrum.spectral_abscissa)
    compared = proof.compared(spectrum.spectral_abscissa, "converged spectrum")
    assert "sigma/|alpha|" in str(compared)
    # "best" keeps the larger of the two weights' proved rates: here the polynomial one's,
    # at least 1.5 times the exponential weight's (0.408 against 0.196 measured: the
    # zero-order shear coupling is what the exponential weight pays for)
    exponential = prove_decay_rate(closed(model, [3, 4], "1"), weight="exponential")
    assert proof.sigma == max(proof.sigma, exponential.sigma)
    assert proof.sigma >= Fraction(3, 2) * exponential.sigma
    assert check_rate(proof.to_json()) == []
    assert "polynomial weight" in str(proof)


def test_a_weight_is_one_of_three_and_the_exponential_needs_constant_coefficients():
    with pytest.raises(RateProofError, match=r"weight must be one of 'best', 'exponential'"):
        prove_decay_rate(closed(load_builtin("wave"), [2], "1/2"), weight="chebyshev")


def test_the_beam_is_refused_saying_what_is_proved_instead():
    with pytest.raises(RateProofError, match=r"spectral bound.*Riesz basis.*does not check"):
        prove_decay_rate(closed(load_builtin("euler-bernoulli"), [3], "1"))


def test_a_system_of_another_kind_is_refused():
    with pytest.raises(ArgumentError, match=r"system must be an ExactClosedSystem.*found BCPHS"):
        prove_decay_rate(load_builtin("wave"))  # the model, not its closed system


def test_an_irrational_entry_is_refused():
    with pytest.raises(RateProofError, match=r"kernel basis\[1,1\] = sqrt\(2\).*not a rational"):
        rate_problem(
            name="m",
            order=1,
            interval=(0, 1),
            H=[[1]],
            P=([[0]], [[1]]),
            boundary=[[1, 1]],
            kernel=[[sympy.sqrt(2)], [-sympy.sqrt(2)]],
        )


def test_a_string_with_a_damper_at_each_end_reaches_ninety_percent_of_its_rate():
    k0, k1 = mpmath.mpf(1) / 2, mpmath.mpf(2)
    with mpmath.workdps(30):
        closed_form = -mpmath.log(3) + 1j * mpmath.pi / 2  # e^(2 lambda) = r0 r1 = -1/9
        root = mpmath.findroot(
            lambda s: (1 + k0 * k1) * mpmath.sinh(s) + (k0 + k1) * mpmath.cosh(s),
            closed_form + mpmath.mpf("0.01"),
        )
        assert abs(root - closed_form) < 1e-25
    true = math.log(3)
    system = closed_system(STRING_TWO_ENDS, sensor_matrix([1, 2], 2), ["1/2", "2"])
    proof = prove_decay_rate(system, target=0.9 * true)
    assert 0.9 * true - 1e-6 <= proof.sigma < true
