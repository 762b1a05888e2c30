"""Issue 29: gain designs for the sampled observer, verified over a set of initial states.

The acceptance case (the paper's beam, sensors y3, y4, L = diag(0.1, 1), averaged sampler,
34 states = Legendre degree 16, plant of degree 48, observer from 0): the five initial
states (x1, x2) = (0, z - 0.9), (z^2, 0), (0, 1), (0, 1 - z), (z^3, 0); F is the largest tip
error |w(1, t_k) - w_hat_k| over the records of [4, 5] s (every 10 ms), F_c the same for the
continuous degree-16 observer with the paper's gain. Targets (issue 29, "What it must
show"): at 10 ms the ``auto`` export has F <= 1.5 F_c on all five and F <= 2e-5 on the
paper's state, for at most 1.5 x the noise gain of the paper-gain design; at 1 ms
F <= 1.2 F_c on all five. Measured when written (load ~8 on two cores does not move them):
10 ms, auto = kalman, F/F_c = 0.65, 1.20, 0.86, 0.83, 1.30, F = 1.65e-5 on the paper's state;
the paper's gain 2.04, 4.46, 2.50, 1.76, 3.60 (the issue's independent check: 2.07, 4.46,
2.44, 1.71, 3.60, on a 400-mode modal plant); noise variance of the tip 0.232 against
0.1347 (x 1.72), noise gain x 1.31; the passive design 1.33..1.68.

The floors of the set are computed by replaying each candidate on shared plant runs
(:class:`phdesign.numeric.sampled.state_runs.StateRuns`); the verification of the first
state runs plant and observer together through the block exponential of
:func:`phdesign.numeric.sampled.runs.run_loop`, a separate path: the two must agree.
"""

from __future__ import annotations

import numpy as np
import pytest

from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.points import point_rows
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.inputs import initial_state_function
from phdesign.numeric.noise.statistics import error_statistics
from phdesign.numeric.sampled.export import KalmanNoise, export_observer
from phdesign.numeric.sampled.gain_design import design_gain
from phdesign.numeric.sampled.noise_price import noise_price
from phdesign.numeric.sampled.period_maps import sample_plant
from phdesign.numeric.sampled.state_runs import StateRuns
from phdesign.numeric.sampled.state_set import InitialState, boundary_states
from phdesign.symbolic.ports import trace_index

SENSORS = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
GAIN = np.diag([0.1, 1.0])
FIVE = ("x1: 0, x2: z - 0.9", "x1: z**2, x2: 0", "x1: 0, x2: 1", "x1: 0, x2: 1 - z",
        "x1: z**3, x2: 0")  # fmt: skip


@pytest.fixture(scope="module")
def beam():
    return to_numeric(load_builtin("euler-bernoulli"))


@pytest.fixture(scope="module")
def five(beam):
    model = load_builtin("euler-bernoulli")
    return [InitialState(s, initial_state_function(s, beam, model=model)) for s in FIVE]


def _export(beam, five, dt, **options):
    return export_observer(
        beam, SENSORS, GAIN, dt=dt, order=34, plant_resolution=48, x0=five, verify=True,
        **options,
    )  # fmt: skip


@pytest.fixture(scope="module")
def at_10ms(beam, five):
    return _export(beam, five, 1e-2)


@pytest.mark.slow
def test_auto_design_at_10_ms_meets_the_floor_targets_on_five_states(at_10ms):
    design = at_10ms.design
    chosen = design.selected
    ratios = chosen.floors.ratios
    assert at_10ms.order == 34
    assert at_10ms.verification.plant_degree == 48
    assert chosen.floors.window == (4.0, 5.0)
    assert np.all(ratios <= 1.5), f"{design.chosen}: F/F_c = {np.round(ratios, 3)}"
    assert chosen.floors.floors[0] <= 2.0e-5, chosen.floors.floors[0]
    # the noise gain (the H2 norm from unit sensor noise to the tip error, the root of the
    # variance: the "35 % more noise gain" is sqrt(1.72) = 1.31 of these variances):
    # at most 1.5 x the paper-gain design's
    given = design.candidate("given")
    assert chosen.noise_gain <= 1.5 * given.noise_gain, (chosen.noise, given.noise)
    # the reference: the paper's gain used at the discrete level misses the 1.5 x
    assert given.worst > 1.5
    assert "verification set" in design.reason or design.chosen == "passive"


@pytest.mark.slow
def test_shared_runs_agree_with_the_verification_run_of_the_first_state(at_10ms):
    # two paths: the replay on shared plant runs against run_loop's block exponential;
    # 1e-9 relative: 500 products of matrices of norm <= 1 either way, in double precision
    floors = at_10ms.design.selected.floors
    v = at_10ms.verification
    assert floors.floors[0] == pytest.approx(v.floor, rel=1e-9)
    assert floors.continuous_floors[0] == pytest.approx(v.continuous_floor, rel=1e-9)


@pytest.mark.slow
def test_passive_design_stays_dissipative(at_10ms):
    # ||Q^(1/2) A_d Q^(-1/2)||_2 <= 1 (the proof in period_maps.py, for every gain with
    # sym(L) > 0): Q = E = R^T R, so the norm is that of R A_d R^-1. 1e-12: round-off of
    # the exponential and the solve.
    passive = at_10ms.design.candidate("passive")
    R = np.linalg.cholesky(at_10ms.energy_matrix).T
    A = passive.realization.A
    assert np.linalg.norm(R @ A @ np.linalg.inv(R), 2) <= 1 + 1e-12
    assert np.min(np.linalg.eigvalsh(passive.gain + passive.gain.T)) > 0
    assert passive.worst <= at_10ms.design.candidate("given").worst  # never worse on the set


@pytest.mark.slow
def test_kalman_design_is_a_predictor_of_the_exact_sampled_model(at_10ms):
    # A = Phi - K C_m C_s, B = [Gamma - K C_m D_s, K] (kalman.py), 1e-12 absolute
    kalman = at_10ms.design.candidate("kalman")
    model = at_10ms.continuous.model
    s = sample_plant(model.F, model.G, model.H, model.D, 1e-2, "average")
    K = kalman.gain
    np.testing.assert_allclose(kalman.realization.A, s.Phi - K @ SENSORS @ s.C_s, atol=1e-12)
    np.testing.assert_allclose(kalman.realization.B[:, 4:], K, atol=0)
    assert np.max(np.abs(np.linalg.eigvals(kalman.realization.A))) < 1


@pytest.mark.slow
def test_auto_refuses_a_kalman_design_that_fails_verification(beam, five, at_10ms):
    plant = discretize(beam, "galerkin", 48)
    runs = StateRuns.run(
        plant, at_10ms.continuous, SENSORS, states=five, dt=1e-2, sampler="average", t_end=5.0
    )
    common = {"design": "auto", "dt": 1e-2, "sampler": "average"}
    # a bound below the Kalman design's worst ratio (1.30): it fails, the passive one is taken
    strict = design_gain(at_10ms.continuous, runs, noise_model=KalmanNoise(), bound=1.0, **common)
    assert strict.chosen == "passive"
    assert "failed verification: its worst F/F_c 1.3" in strict.reason
    # almost no process noise: a gain too small to correct, hundreds of times the floor
    timid = design_gain(
        at_10ms.continuous, runs, noise_model=KalmanNoise(process=1e-6), bound=10.0, **common
    )
    assert timid.chosen == "passive"
    assert timid.candidate("kalman").worst > 10
    assert timid.candidate("kalman").failure is not None


@pytest.mark.slow
def test_auto_design_at_1_ms_is_within_1_2_of_the_continuous_floor(beam, five):
    obs = _export(beam, five, 1e-3)
    ratios = obs.design.selected.floors.ratios
    assert np.all(ratios <= 1.2), f"{obs.design.chosen}: F/F_c = {np.round(ratios, 3)}"


def test_noise_price_tends_to_the_continuous_variance(beam):
    # sampled error variance of w(1) for unit sensor noise, against the continuous error
    # system's (noise/statistics.py, another Lyapunov solver); measured differences 3.6e-5
    # relative at 10 ms, 8e-6 at 1 ms, 1e-9 at 0.1 ms: 1e-6 at 0.1 ms
    from phdesign.numeric.sampled.samplers import ContinuousObserver

    d = discretize(beam, "galerkin", 16)
    obs = ContinuousObserver.from_discretization(d, SENSORS, GAIN, (1.0,))
    continuous = error_statistics(d, SENSORS, GAIN, np.ones(2)).variance(
        point_rows(d, obs.points)[0]
    )
    sampled = noise_price(obs.sampled(1e-4, "average"), 4, obs.performance, 1e-4)[0]
    assert sampled == pytest.approx(continuous, rel=1e-6)


@pytest.mark.parametrize(
    "name", ["euler-bernoulli", "wave", "wave-damper", "timoshenko", "airy", "beam-tip-damper"]
)
def test_default_states_meet_the_boundary_conditions(name):
    # the efforts e = H x of each state, fitted by numpy's Chebyshev series (exact for a
    # polynomial) and differentiated there: their traces must satisfy U v = 0 on the open
    # ports and (U_c + K Y_c) v = 0 on the closed ones, to 1e-10 of their size
    nm = to_numeric(load_builtin(name))
    states = boundary_states(nm)
    assert len(states) == 2 * nm.size
    a, b = nm.interval
    z = np.cos(np.linspace(0, np.pi, 40)) * (b - a) / 2 + (a + b) / 2
    rows = np.array(nm.U, dtype=float)
    if nm.feedback is not None:
        closed = list(nm.feedback.closed)
        rows[closed] += nm.feedback.gain @ np.asarray(nm.Y, dtype=float)[closed]
    for state in states:
        e = np.einsum("mij,mj->mi", nm.H(z), state.function(z))
        v = np.zeros(2 * nm.order * nm.size)
        for i in range(nm.size):
            series = np.polynomial.Chebyshev.fit(z, e[:, i], 12, domain=[a, b])
            for k in range(nm.order):
                for side, point in (("a", a), ("b", b)):
                    v[trace_index(i + 1, k, side, nm.order, nm.size)] = series.deriv(k)(point)
        assert np.max(np.abs(e)) > 0.1
        assert np.max(np.abs(rows @ v)) <= 1e-10 * max(1.0, np.max(np.abs(v))), state.text


@pytest.mark.slow
def test_the_designs_plot_side_by_side(at_10ms):
    pytest.importorskip("matplotlib")
    ax = at_10ms.design.plot()
    assert len(ax.patches) == 3 * 5  # given, passive, kalman on the five states
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert f"{at_10ms.design.chosen} (exported)" in " ".join(labels)
