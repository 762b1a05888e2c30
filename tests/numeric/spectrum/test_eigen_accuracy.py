"""The eigen stage (shift and invert) against characteristic determinants solved in mpmath.

The model where QZ loses digits: the paper's beam (rho = EI = 1, d = 0.2) with the tip torque
damper u3 = -k y3 (e2(1) = -k e1'(1)), a damper on a derivative trace whose Galerkin matrix
grows like p^4 (norm 1.5e8 at degree 30, 2e11 at degree 102).  QZ has a normwise backward
error, so its slow eigenvalues err by ~eps ||A||: measured against the mpmath root, 4.6e-12,
1.1e-10, 1.6e-9, 5.8e-7 at degrees 30, 45, 68, 102.  Shift and invert errs by
~eps |lambda - sigma|^2 ||(A - sigma E)^-1 E||, independent of ||A||: below 1e-13 at every
degree.  The references are the roots of the tip determinant of w_tt = -d w_t - w_zzzz
clamped at 0 (``beam_determinant`` of test_loop_numbers.py, derived there), found at 30
digits and checked (|f| < 1e-20).  Each test fails on the QZ eigen stage.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from characteristic import beam_determinant
from string_models import SENSOR2, string

from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.control.assembly import NumericLoop
from phdesign.numeric.control.spectrum import loop_spectrum
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.scales import problem_scales
from phdesign.numeric.spectrum.converged import eigen, spectrum
from phdesign.numeric.spectrum.refinement import choose_pair, refine
from phdesign.symbolic.closing import close_inputs

BEAM = load_builtin("euler-bernoulli")

#: Relative accuracy required of a slow eigenvalue: the eigen stage's ~1e-13 (module
#: docstring) with a margin of 100, and 100 times below what QZ reaches at degree 68.
RELATIVE = 1e-11


def _tip_torque_root(torque: float, guess: complex) -> complex:
    """The root of the damped beam's tip determinant near ``guess`` (30 digits, checked)."""
    with mpmath.workdps(30):

        def f(x):
            return beam_determinant(x, torque=torque, damping=0.2)

        root = mpmath.findroot(f, mpmath.mpc(guess), tol=1e-40, verify=False)
        assert abs(f(root)) < 1e-20
        return complex(root)


@pytest.mark.parametrize("degree", [68, 102])
def test_slow_eigenvalues_of_the_stiff_tip_damper_keep_eleven_digits(degree):
    nm = to_numeric(close_inputs(BEAM, [3], [[0.5]]))
    lam, kappa = eigen(discretize(nm, "galerkin", degree), condition=True)
    assert kappa is not None
    # the two rightmost modes (approximations from spectrum(nm), refined in mpmath)
    for guess in (-1.4033 + 4.889j, -2.0872 + 74.422j):
        root = _tip_torque_root(0.5, guess)
        error = np.min(np.abs(lam - root)) / abs(root)
        assert error < RELATIVE, (degree, root, error)
        # the shift does not change an eigenvector: a damped mode stays well conditioned
        assert kappa[np.argmin(np.abs(lam - root))] < 10


def test_the_tuned_tip_damper_spectrum_converges_to_the_determinant_root():
    """The controlled plant of ``phdesign loop tune`` (K = 0.39509...): QZ agreed to 4.1e-8.

    The controlled plant as ``loop_spectrum`` refines it: the beam closed by u3 = -K y3
    through the sensors-and-gain path of ``spectrum`` (C_m = S_a, L = K).
    """
    K = 0.3950973361487566  # the optimum ``phdesign loop tune`` returned (one start)
    report = spectrum(to_numeric(BEAM), np.eye(4)[[2]], np.array([[K]]))
    assert report.converged, report.warnings
    alpha = report.spectral_abscissa
    root = _tip_torque_root(K, complex(alpha, abs(report.rightmost[0].imag)))
    assert abs(alpha - root.real) < RELATIVE * max(1.0, abs(alpha)), alpha - root.real
    assert report.digits > 11


def test_the_loop_spectrum_is_refined_by_the_spectrum_rules_and_stays_honest():
    """A string whose abscissa is a high-frequency limit that no mode attains, in a loop.

    rho = 1, T = 1 + z, fixed at 0, the damper end z = 1 actuated (u2 = -K y2, K = 0.5)
    and measured (y2, L = 3).  WKB (test_spectrum_trust.py derives it): a round trip of
    tau = 4 (sqrt 2 - 1) reflects at the damper with r = (Z - k)/(Z + k), Z = sqrt 2, so
    Re lambda_m -> ln|r| / tau from below.  The loop's spectrum is the union of the
    controlled plant's (k = K: limit -0.44602) and the error system's (k = L), whose
    limit -0.6179 lies further left, so the loop's abscissa is the plant's limit.  The old
    loop refinement reported the largest attained mode, 3.6e-5 right of the limit, with 6.7
    digits claimed; then an extrapolation, not converged; now the chains' limits of both
    blocks are derived from the principal part (numeric/spectrum/branches.py) and the loop's is the
    plant's, to round-off.
    """

    def limit(k: float) -> float:
        return math.log(abs((math.sqrt(2) - k) / (math.sqrt(2) + k))) / (4 * (math.sqrt(2) - 1))

    nm = to_numeric(string("1 + z"))
    loop = NumericLoop((1,), np.array([[0.5]]), SENSOR2, np.array([[3.0]]))
    report = loop_spectrum(nm, loop)
    exact = limit(0.5)
    assert limit(3.0) < exact
    rate = problem_scales(nm).rate  # digits are relative to max(rate, |alpha|)
    claim = 10.0 ** (-report.digits) * max(rate, abs(report.spectral_abscissa))
    assert abs(report.spectral_abscissa - exact) <= claim, report.spectral_abscissa - exact
    assert report.uncertainty is not None
    assert abs(report.spectral_abscissa - exact) <= report.uncertainty
    assert report.converged  # a derived limit, no longer an extrapolation
    assert abs(report.spectral_abscissa - exact) < 1e-12
    chains = [w for w in report.warnings if w.startswith("loop: the abscissa is the limit")]
    assert chains
    assert "controlled plant" in chains[0]
    assert not any("separation structure is not reproduced" in w for w in report.warnings)


class _SpoiledAtHighDegree:
    """A per-resolution solver (``ResolutionSolver``) whose rightmost eigenvalue -9.25
    agrees at resolutions 8 and 12 and is spoiled to -9.9 from resolution 18 on: what
    QZ's round-off did to airy's Legendre basis at degree 27.  Damped modes
    -(20 + m) + i (3m + 3), m < p/2 - 3 (few at low p, so the first pairs do not see
    enough modes above the rightmost to converge), and an unresolved high pair.
    """

    rate = 1.0
    dissipative = True
    branches = None  # no principal part to derive: the band alone decides

    def __call__(self, p: int, condition: bool = True) -> tuple[np.ndarray, np.ndarray]:
        m = np.arange(p // 2 - 3)
        modes = -(20.0 + m) + 1j * (3.0 * m + 3.0)
        special = -9.25 if p < 18 else -9.9
        high = -0.1 + 1j * 1000.0 * p
        lam = np.concatenate([modes, modes.conj(), [special, high, np.conj(high)]])
        return lam, np.ones(lam.size)


def test_an_agreed_eigenvalue_is_kept_when_round_off_spoils_finer_pairs():
    """The refinement rule (``choose_pair``) on a solver that spoils the rightmost.

    Shift and invert removed the real-model trigger (airy, Legendre basis, sensors y1, y3:
    QZ lost -9.250156 at degree 27; shift and invert converges there to 14 digits,
    test_numeric_conditioning.py), so the rule is pinned here on a synthetic solver.
    """
    trail = refine(_SpoiledAtHighDegree(), start=8, stop=60, tol=1e-10, rtol_resolved=1e-6)
    assert [r.pair.resolutions for r in trail] == [(8, 12), (12, 18), (18, 27)]
    assert trail[-1].converged
    assert trail[-1].abscissa.value == pytest.approx(-9.9, abs=1e-12)
    chosen, notes = choose_pair(trail)
    assert chosen.pair.resolutions == (8, 12)
    assert chosen.abscissa.value == pytest.approx(-9.25, abs=1e-12)
    assert len(notes) == 1
    assert "an eigenvalue that once agreed is real" in notes[0]
