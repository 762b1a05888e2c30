r"""``Observer.noise`` and ``Observer.tradeoff``: the design object delegates, exactly.

Each method must return what :func:`phdesign.numeric.noise.figures.noise` and
:func:`phdesign.numeric.noise.tradeoff.tradeoff` return for the same numbers (the same report,
bit for bit), and refuse bad arguments with phdesign's errors naming the argument.

Closed forms (derived here, by characteristics).  The string :math:`w_{tt} = w_{zz}` on
[0, 1] (``wave``, unit parameters) observed through sensor 2 (:math:`y_2 = e_1(1) = w_t(1)`)
with gain k has the error system :math:`w_t(0) = 0`, :math:`w_z(1) = -k (w_t(1) + \nu)`,
:math:`\mathbb E[\nu(t)\nu(s)] = \sigma^2 \delta(t - s)`.  With :math:`\alpha = x_1 + x_2`
(travels left), :math:`\beta = x_1 - x_2` (travels right) and :math:`a(t) = \alpha(1, t)`:
:math:`\beta(0) = -\alpha(0)`, and at z = 1, with :math:`r = (1 - k)/(1 + k)`,

.. math::

    a(t) = -r\, a(t - 2) + c\, \nu(t), \qquad c = -\frac{2k}{1 + k} .

1. The performance output :math:`\zeta = \int_0^1 \tilde x_2\, dz` ("x2: 1") is
   :math:`\tfrac12 \int_{t-2}^{t} a(s)\, ds = \tfrac12 \sum_j (-r)^j c\, N_j` with independent
   increments :math:`N_j` of variance :math:`2\sigma^2`, so
   :math:`\mathrm{Var}\,\zeta = c^2 \sigma^2 / (2(1 - r^2)) = k\sigma^2/2` for every k > 0.
2. In the energy norm :math:`\|\tilde x\|^2 = \tfrac12\int(\alpha^2 + \beta^2) = |\hat a|^2`,
   so the L²-gain is :math:`\sigma |c| / \min_\omega |1 + r e^{-2i\omega}|`
   :math:`= \sigma \max(1, k)`: at :math:`\omega = \pi/2` for k < 1, at 0 for k > 1.
3. The decay rate is :math:`\tfrac12 \ln|(1 + k)/(1 - k)|` (the damper's abscissa).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import phdesign as phd
from phdesign.core.errors import NumericError, ObserverError, PhdesignError
from phdesign.numeric.noise.figures import noise
from phdesign.numeric.noise.tradeoff import tradeoff

SIGMA2 = 0.3  # sensor noise intensity of these tests
K = 0.5  # the string's observer gain


@pytest.fixture(scope="module")
def string():
    return phd.Observer(phd.load("wave"), sensors=[2], gain=K)


@pytest.fixture(scope="module")
def report(string):
    return string.noise(performance="x2: 1", intensity=SIGMA2)


def test_noise_is_the_noise_function_exactly(string, report):
    nm = phd.to_numeric(phd.load("wave"))  # a pipeline of its own, not the observer's cache
    direct = noise(
        nm,
        np.array([[0.0, 1.0]]),
        np.array([[K]]),
        model=phd.load("wave"),
        intensity=SIGMA2,
        performance=["x2: 1"],
    )
    assert type(report) is type(direct)
    assert report.to_dict() == direct.to_dict()
    assert str(report) == str(direct)
    assert repr(report) == repr(direct)


def test_noise_figures_match_the_closed_forms(report):
    # Var = k sigma^2 / 2 and gamma = sigma max(1, k) at omega = pi/2 (module docstring);
    # the report's own refinement tolerance is 1e-6 relative (Galerkin default), so the
    # converged figures are asserted to that tolerance, not tighter.
    (var,) = report.performance
    assert var.converged
    assert var.value == pytest.approx(K * SIGMA2 / 2, rel=1e-6)
    assert report.l2_gain.converged
    assert report.l2_gain.value == pytest.approx(math.sqrt(SIGMA2) * max(1.0, K), rel=1e-6)
    assert report.l2_gain.frequency == pytest.approx(math.pi / 2, rel=1e-6)
    # E[H~] is infinite for the PDE: reported as diverging, never as a number
    assert report.error_energy.diverges
    assert report.error_energy.value is None


def test_noise_gain_above_one_peaks_at_zero_frequency():
    # k = 2 > 1: gamma = sigma k at omega = 0; Var = k sigma^2 / 2 still (module docstring)
    obs = phd.Observer(phd.load("wave"), sensors=[2], gain=2)
    rep = obs.noise(performance="x2: 1", intensity=SIGMA2)
    assert rep.l2_gain.value == pytest.approx(2 * math.sqrt(SIGMA2), rel=1e-6)
    assert abs(rep.l2_gain.frequency) < 1e-6
    assert rep.performance[0].value == pytest.approx(2 * SIGMA2 / 2, rel=1e-6)


def test_noise_defaults_follow_the_function_on_the_beam():
    # default intensity 1 and the default performance output w(1) (the tip deflection)
    beam = phd.load("euler-bernoulli")
    obs = phd.Observer(beam, sensors=[3, 4], gain=[0.1, 1])
    direct = noise(
        phd.to_numeric(beam), np.eye(4)[2:], np.diag([0.1, 1.0]), model=beam, max_resolution=45
    )
    mine = obs.noise(max_resolution=45)
    assert mine.to_dict() == direct.to_dict()
    assert [p.name for p in mine.performance] == ["w(1)"]


def test_noise_uses_the_designs_parameters_and_discretization():
    # the overrides and the method reach the numbers: same as the function on d = 0.5, FD
    beam = phd.load("euler-bernoulli")
    obs = phd.Observer(beam, sensors=[3, 4], gain=[0.1, 1], parameters={"d": 0.5}, method="fd")
    direct = noise(
        phd.to_numeric(beam, {"d": 0.5}),
        np.eye(4)[2:],
        np.diag([0.1, 1.0]),
        model=beam.with_parameters({"d": 0.5}),
        method="fd",
    )
    assert obs.noise().to_dict() == direct.to_dict()


def test_tradeoff_is_the_tradeoff_function_exactly(string):
    mine = string.tradeoff(scales=[0.5, 1, 4], performance="x2: 1", intensity=SIGMA2)
    nm = phd.to_numeric(phd.load("wave"))
    direct = tradeoff(
        nm,
        np.array([[0.0, 1.0]]),
        direction=np.array([[K]]),  # the default direction is the observer's own gain
        scales=[0.5, 1, 4],
        performance=["x2: 1"],
        intensity=SIGMA2,
        model=phd.load("wave"),
    )
    assert mine.to_dict() == direct.to_dict()
    assert mine.to_csv() == direct.to_csv()
    assert str(mine) == str(direct)


def test_tradeoff_points_match_the_closed_forms(string):
    # k = s K: decay (1/2) ln|(1 + k)/(1 - k)| and Var = k sigma^2 / 2 (module docstring).
    # k = 1/4, 1/2, 2: k = 2 decays exactly as fast as k = 1/2 and is noisier, so it is
    # the one point that is not Pareto-optimal.
    t = string.tradeoff(scales=[0.5, 1, 4], performance="x2: 1", intensity=SIGMA2)
    ks = [0.25, 0.5, 2.0]
    # 1e-9: the converged abscissa of a Galerkin refinement (test_numeric_spectrum.py)
    assert [p.decay_rate for p in t.points] == pytest.approx(
        [0.5 * math.log(abs((1 + k) / (1 - k))) for k in ks], abs=1e-9
    )
    assert [p.rms for p in t.points] == pytest.approx(
        [math.sqrt(k * SIGMA2 / 2) for k in ks], rel=1e-6
    )
    assert [p.pareto for p in t.points] == [True, True, False]


def test_tradeoff_direction_and_grid_are_read_as_gains(string):
    # a direction given as text is read exactly as a gain is; a grid gives diagonal gains
    by_text = string.tradeoff(direction="1/2", scales=[1], performance="x2: 1")
    by_number = string.tradeoff(direction=0.5, scales=[1], performance="x2: 1")
    assert by_text.to_dict() == by_number.to_dict()
    grid = string.tradeoff(grid=[[0.25, 2]], performance="x2: 1")
    assert grid.family == "grid"
    assert [float(p.gain[0, 0]) for p in grid.points] == [0.25, 2.0]
    # without a gain, the ray is the identity's (as the function's default)
    bare = phd.Observer(phd.load("wave"), sensors=[2])
    nm = phd.to_numeric(phd.load("wave"))
    direct = tradeoff(nm, np.array([[0.0, 1.0]]), scales=[0.5], performance=["x2: 1"])
    assert bare.tradeoff(scales=[0.5], performance="x2: 1").to_dict() == direct.to_dict()


BAD_NOISE = [
    ({"intensity": -1}, NumericError, r"^intensity: .*found -1"),
    ({"intensity": [1, 2]}, NumericError, r"^intensity: expected 1 values"),
    ({"intensity": "a"}, NumericError, r"^intensity: expected numbers; found 'a'"),
    ({"input_intensity": float("nan")}, NumericError, r"^input_intensity: "),
    ({"performance": "w(2)"}, NumericError, r"^displacement point 2 is outside the interval"),
    ({"performance": "w(0.5)"}, NumericError, r"^w\(0.5\): the model 'wave' defines no"),
    ({"performance": "x9: 1"}, PhdesignError, r"unknown component 'x9'"),
    ({"performance": 3}, NumericError, r"^performance output: expected text.*found 3"),
    ({"max_resolution": 0}, NumericError, r"^max_resolution must be a positive integer"),
    ({"max_resolution": 2.5}, NumericError, r"^max_resolution must be a positive integer"),
    ({"max_resolution": 3}, NumericError, r"^max_resolution must be at least .* found 3"),
    ({"tol": 0}, NumericError, r"^tol must be a finite positive number; found 0"),
    ({"tol": "x"}, NumericError, r"^tol must be a finite positive number; found 'x'"),
]


@pytest.mark.parametrize(("kwargs", "exc", "match"), BAD_NOISE)
def test_noise_refuses_bad_arguments_by_name(string, kwargs, exc, match):
    with pytest.raises(exc, match=match):
        string.noise(**kwargs)


BAD_TRADEOFF = [
    ({"direction": -1}, ObserverError, r"^direction .*positive definite"),
    ({"direction": "abc"}, ObserverError, r"^direction .*unknown symbol 'abc'"),
    ({"direction": [1, 2]}, ObserverError, r"^direction .*expected 1 diagonal values"),
    ({"direction": "symbolic"}, ObserverError, r"needs numbers for direction"),
    ({"scales": [-1]}, NumericError, r"^scales: expected positive finite numbers"),
    ({"scales": "ab"}, NumericError, r"^scales: expected numbers"),
    ({"grid": [[1], [2]]}, NumericError, r"^grid: expected 1 axes"),
    ({"grid": "ab"}, NumericError, r"^grid: expected one sequence of gains per sensor"),
    ({"grid": [[-1]]}, NumericError, r"^grid axis 1: expected positive finite gains"),
    ({"grid": [["a"]]}, NumericError, r"^grid axis 1: expected numbers"),
    ({"grid": [[1]], "scales": [1]}, NumericError, r"either a grid of gains or a ray"),
    ({"intensity": -1}, NumericError, r"^intensity: "),
]


@pytest.mark.parametrize(("kwargs", "exc", "match"), BAD_TRADEOFF)
def test_tradeoff_refuses_bad_arguments_by_name(string, kwargs, exc, match):
    with pytest.raises(exc, match=match):
        string.tradeoff(performance="x2: 1", **kwargs)


def test_a_misspelt_option_is_not_swallowed(string):
    with pytest.raises(TypeError, match="intensities"):
        string.noise(intensities=0.3)  # type: ignore[call-arg]
    with pytest.raises(TypeError, match="scale"):
        string.tradeoff(scale=[1])  # type: ignore[call-arg]


def test_noise_needs_a_numeric_gain():
    symbolic = phd.Observer(phd.load("wave"), sensors=[2], gain="symbolic")
    with pytest.raises(ObserverError, match="noise needs numbers for L"):
        symbolic.noise()
    with pytest.raises(ObserverError, match="noise needs a gain"):
        phd.Observer(phd.load("wave"), sensors=[2]).noise()
