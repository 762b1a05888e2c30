"""The proved decay rate for z-dependent H(z) (issue 25, part 2), against closed forms.

Closed forms used below (every one also solved from its characteristic equation in mpmath
inside the test, so that it is not only taken on trust).

String of speed c(z) = 1 + z and constant impedance: rho = 1/c, T = c, so
H = diag(1/rho, T) = (1 + z) I, P1 = [[0, 1], [1, 0]] on [0, 1]; fixed at 0 (e1(0) = 0),
damper at 1 (e2(1) = -k e1(1), sensor y2 with gain k).  With e = Hx the eigenproblem
lambda x = P1 (Hx)' reads e' = (lambda / c) P1 e; with theta(z) = int_0^z dz/c = ln(1 + z)
(the travel time), e(z) = exp(lambda theta(z) P1) e(0), and e(0) = (0, 1) gives
e(1) = (sinh(lambda ln 2), cosh(lambda ln 2)).  The damper: cosh(x) + k sinh(x) = 0,
x = lambda ln 2, i.e. e^(2x) = (k - 1)/(k + 1).  For k = 1/2: e^(2 lambda ln 2) = -1/3,

    Re lambda = -ln(3) / (2 ln 2) = -0.79248...   for every mode.

The Riemann invariants v +- f travel at speed c without internal reflection (the impedance
sqrt(rho T) = 1 is constant) and the energy norm int (v^2 + f^2)/c dz is the L2 norm in
theta, so the energy after a round trip 2 ln 2 is multiplied by r^2 exactly: the decay
rate in the energy norm is ln(3)/(2 ln 2), not only the spectral abscissa.

Transport x_t = ((1 + z) x)_z on [0, 1] (H = 1 + z, P1 = 1), input u = e(1) - e(0) and
output y = (e(1) + e(0))/2 at both ends, closed by u = -k y: e(1) = r e(0),
r = (2 - k)/(2 + k); e = Hx travels from 1 to 0 along dz/dt = -(1 + z) in the time
int_0^1 dz/(1 + z) = ln 2, so e(0, t + ln 2) = r e(0, t) and the rate is
-ln|r| / ln 2 = ln(5/3)/ln 2 = 0.73697 for k = 1/2.

Transport x_t = x_z - z x (H = 1, P0(z) = -z), the same ports and closing: along a
characteristic (speed 1, from 1 to 0 in unit time) e is damped by exp(-int_0^1 z dz) =
exp(-1/2), so e(0, t + 1) = r e^(-1/2) e(0, t) and the rate is ln(5/3) + 1/2 = 1.01083
for k = 1/2.

String of density rho = 1 + z/2, T = 1 (H = diag(1/(1 + z/2), 1)), fixed at 0, damper
k = 1/2 at 1: the impedance varies, so there is no closed form for the low modes; the
characteristic determinant Delta(lambda) = f(1) + k v(1) of the shooting solution
e' = lambda P1 H^-1 e, e(0) = (0, 1) is solved in mpmath.  Its zeros approach, from the
left, the high-frequency limit Re lambda = ln|r1| / (2 T_travel) with
r1 = (Z1 - k)/(Z1 + k), Z1 = sqrt(rho(1) T(1)) = sqrt(3/2) (the reflection at the damper)
and T_travel = int_0^1 sqrt(rho/T) dz = (4/3)((3/2)^(3/2) - 1): the decay rate is
-ln|r1| / (2 T_travel) = 0.388393 (the eigenvectors of the damped string form a Riesz basis:
Cox and Zuazua, Comm. PDE 19, 1994).
"""

from __future__ import annotations

import copy
import json
import math
from fractions import Fraction

import mpmath
import pytest
import sympy
from checker_blocked import run_blocked
from rate_models import (
    DAMPED_TRANSPORT,
    DENSITY,
    SPEED,
    STRING_PORTS,
    TRANSPORT_SPEED,
    string,
)

from phdesign.cli import main
from phdesign.core.errors import RateProofError
from phdesign.numeric.certified.exact_system import closed_system
from phdesign.numeric.certified.rate import prove_decay_rate
from phdesign.numeric.certified.rate_exact import positive_on
from phdesign.numeric.certified.rate_poly import failures
from phdesign.proofcheck import check_proof
from phdesign.proofcheck.check import _rate
from phdesign.proofcheck.rate_poly import _positive_on, check_rate_polynomial
from phdesign.symbolic.expressions import Z
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import sensor_matrix

pytest.importorskip("cvxpy", reason="the proved decay rate needs the certify extra")


def damped(model: BCPHS, gain: str = "1/2"):
    sensor = 1 if model.size == 1 else 2
    return closed_system(model, sensor_matrix([sensor], model.n_ports), [gain])


def determinant(H_inverse, k: float = 0.5):
    """Delta(lambda) = f(1) + k v(1) of e' = lambda P1 H^-1(z) e, e(0) = (0, 1) (mpmath)."""

    def delta(lam):
        # P1 H^-1 e = (H^-1_22 f, H^-1_11 v) for a diagonal H
        def rhs(z, y):
            return [lam * H_inverse(z)[1] * y[1], lam * H_inverse(z)[0] * y[0]]

        v1, f1 = mpmath.odefun(rhs, 0, [mpmath.mpf(0), mpmath.mpf(1)])(1)
        return f1 + k * v1

    return delta


@pytest.fixture(scope="module")
def speed_proof():
    return prove_decay_rate(damped(SPEED))


@pytest.fixture(scope="module")
def speed_section(speed_proof):
    return json.loads(json.dumps(speed_proof.to_json()))


SPEED_RATE = math.log(3) / (2 * math.log(2))


def test_the_closed_form_of_the_string_of_speed_1_plus_z_is_a_zero_of_its_determinant():
    delta = determinant(lambda z: (1 / (1 + z), 1 / (1 + z)))
    # e^(2 λ ln 2) = -1/3: λ = (-ln 3 + iπ) / (2 ln 2), the slowest mode m = 0
    closed_form = mpmath.mpc(-SPEED_RATE, math.pi / (2 * math.log(2)))
    with mpmath.workdps(15):
        # |Δ| ~ 0.03 a distance 0.05 away; odefun integrates to about 15 digits
        assert abs(delta(closed_form)) < 1e-13 < 1e-2 < abs(delta(closed_form + 0.05))


def test_the_string_of_speed_1_plus_z_reaches_its_closed_form_rate(speed_proof):
    true = SPEED_RATE
    # a Lyapunov rate never beats the true one; measured 0.998 of it at degree 6
    assert 0.99 * true <= speed_proof.sigma < true, (float(speed_proof.sigma), true)
    assert speed_proof.M >= 1
    assert failures(speed_proof.problem, speed_proof.data) == []
    assert "on all of [a, b] by Sturm sequences" in str(speed_proof)


def test_a_transport_with_ports_at_both_ends_reaches_its_closed_form_rate():
    true = math.log(5 / 3) / math.log(2)
    proof = prove_decay_rate(damped(TRANSPORT_SPEED))
    assert 0.99 * true <= proof.sigma < true, (float(proof.sigma), true)  # measured 0.999
    assert check_rate_polynomial(json.loads(json.dumps(proof.to_json()))) == []


def test_a_transport_damped_by_a_z_dependent_p0_reaches_its_closed_form_rate():
    true = math.log(5 / 3) + 0.5
    proof = prove_decay_rate(damped(DAMPED_TRANSPORT))
    assert 0.99 * true <= proof.sigma < true, (float(proof.sigma), true)  # measured 0.999
    assert check_rate_polynomial(json.loads(json.dumps(proof.to_json()))) == []


@pytest.mark.slow
def test_a_string_of_varying_density_stays_below_its_true_rate():
    proof = prove_decay_rate(damped(DENSITY))
    Z1, k = math.sqrt(1.5), 0.5
    travel = 4 / 3 * (1.5**1.5 - 1)
    true = -math.log((Z1 - k) / (Z1 + k)) / (2 * travel)
    delta = determinant(lambda z: (1 + z / 2, 1))
    with mpmath.workdps(10):  # the two lowest modes, from the determinant (10 digits)
        for m in (0, 1):
            guess = mpmath.mpc(-true, math.pi * (2 * m + 1) / (2 * travel))
            root = complex(mpmath.findroot(delta, guess))
            # they decay faster than the high-frequency limit (measured -0.4017, -0.3900)
            assert -0.45 < root.real < -true
            assert proof.sigma < -root.real
    # measured 0.905 of the true rate at every degree 4..10: a local weight Π(z) pays for
    # the internal reflection Z'/Z of the varying impedance; the constant-impedance
    # string above reaches 0.998
    assert 0.88 * true <= proof.sigma < true, (float(proof.sigma), true)


def test_the_checker_verifies_the_proof_and_rejects_a_perturbed_pi(speed_section):
    assert _rate(speed_section) == []
    bad = copy.deepcopy(speed_section)
    entry = bad["Pi"][0][0]["num"]
    entry[0] = str(Fraction(entry[0]) + Fraction(1, 100))  # Π₁₁ moved, Π₂₂ not
    found = check_rate_polynomial(bad)
    assert any("Pi(z) P1 H(z) must be symmetric" in f for f in found), found
    bad = copy.deepcopy(speed_section)
    bad["sigma"] = "4/5"  # above the true rate ln(3)/(2 ln 2) = 0.7925
    found = check_rate_polynomial(bad)
    assert any("'pointwise': the matrix is not negative definite on [a, b]" in f for f in found)


def test_the_checker_rejects_a_claim_on_part_of_the_interval(speed_section):
    bad = copy.deepcopy(speed_section)
    bad["interval"] = ["0/1", "1/2"]  # the proof is for [0, 1]: the boundary form moves
    found = check_rate_polynomial(bad)
    assert "rate: inequality 'boundary' is missing or differs from its data" in found, found


def test_a_dip_between_samples_is_found_by_both_exact_deciders():
    # p(z) = (z − c)² − 10⁻¹⁰ is negative only on (c − 10⁻⁵, c + 10⁻⁵), c = 0.318355,
    # 4.5·10⁻⁵ from the nearest of 10001 equispaced samples of [0, 1]: every one sees p > 0
    c, dip = Fraction(318355, 10**6), Fraction(1, 10**10)
    samples = [Fraction(i, 10000) for i in range(10001)]
    assert all((s - c) ** 2 - dip > 0 for s in samples)
    z = Z
    p = (z - sympy.Rational(c.numerator, c.denominator)) ** 2 - sympy.Rational(1, 10**10)
    assert positive_on(sympy.Matrix([[p, 0], [0, 1]]), (0, 1)) is False
    assert positive_on(sympy.Matrix([[p + 2 * dip, 0], [0, 1]]), (0, 1)) is True
    coefficients = [c * c - dip, -2 * c, Fraction(1)]
    one = [Fraction(1)]
    matrix = [[(coefficients, one), ([], one)], [([], one), (one, one)]]
    assert _positive_on(matrix, Fraction(0), Fraction(1)) is False
    matrix[0][0] = ([coefficients[0] + 2 * dip, *coefficients[1:]], one)
    assert _positive_on(matrix, Fraction(0), Fraction(1)) is True


@pytest.mark.parametrize(
    ("H", "message"),
    [
        (
            [["1 + z", 0], [0, "sqrt(1 + z)"]],
            r"H\[2,2\] = sqrt\(z \+ 1\) is not a rational function",
        ),
        ([["1 + z", 0], [0, "exp(z)"]], r"H\[2,2\] = exp\(z\) is not a rational function"),
        (
            [["1 + z", 0], [0, "1 + sqrt(2)*z"]],
            r"H\[2,2\] = .* coefficient that is not a rational",
        ),
    ],
)
def test_non_rational_z_dependence_is_refused_naming_the_entry(H, message):
    with pytest.raises(RateProofError, match=message):
        prove_decay_rate(damped(string("bad", H)))


def test_the_exponential_weight_is_refused_for_z_dependent_coefficients():
    # t^-1 Π₋ + t Π₊ makes the pointwise form affine in e^{2μz} only for constant H
    with pytest.raises(RateProofError, match=r"exponential weight needs constant H and P0"):
        prove_decay_rate(damped(SPEED), weight="exponential")


@pytest.mark.slow
def test_certify_rate_writes_a_proof_that_check_verifies(tmp_path, capsys):
    import tomli_w

    graded = {
        "name": "graded string",
        "interval": [0, 1],
        "order": 1,
        "matrices": {"P1": [[0, 1], [1, 0]], "H": [[1, 0], [0, "1 + z"]]},
        "ports": STRING_PORTS,
    }
    (tmp_path / "graded.toml").write_text(tomli_w.dumps(graded))
    model, proof = str(tmp_path / "graded.toml"), str(tmp_path / "proof.json")
    assert main(["certify", model, "--sensors", "2", "--gain", "1", "--rate", "-o", proof]) == 0
    out = capsys.readouterr().out
    assert "spectral abscissa: not certified" in out
    assert "decay rate:" in out
    assert "the spectrum is not certified: H or P0 depends on z" in out
    assert main(["check", proof]) == 0
    assert "no spectrum section: the spectral abscissa is not claimed" in capsys.readouterr().out
    # the checker alone, with the prover's libraries blocked
    done = run_blocked([proof])
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == repr(([], []))
    # a claim added to a rate-only proof has nothing behind it
    data = json.loads((tmp_path / "proof.json").read_text())
    data["claim"]["abscissa_interval"] = ["-1/1", "-1/2"]
    assert check_proof(data) == [
        "the claim states a spectral abscissa, but the proof has no spectrum section"
    ]
