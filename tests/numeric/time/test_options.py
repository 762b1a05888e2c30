"""The simulators' one options object: each bad value refused once, naming the option.

A table of ``(options, error, message)`` exercises every check of
:class:`SimulationOptions` (python-control's habit: one row a constructor path), then the
refusals that need a simulator: an option of a kind of run it does not do, a setting
that is not an option, a discretization that belongs to the plant.
"""

from __future__ import annotations

import numpy as np
import pytest
from numeric_models import numeric

import phdesign as phd
from phdesign.core.errors import ArgumentError, NumericError
from phdesign.numeric.control.assembly import NumericLoop
from phdesign.numeric.control.simulation import simulate_loop
from phdesign.numeric.sampled.simulation import simulate_sampled
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.simulation import simulate
from phdesign.numeric.time.stochastic import simulate_noisy

BAD = [
    ({"t_end": 0.0}, NumericError, r"t_end must be a finite positive number; found 0.0"),
    ({"t_end": "1"}, NumericError, r"t_end must be a finite positive number; found '1'"),
    ({"samples": 1}, NumericError, r"samples must be an integer >= 2; found 1"),
    ({"samples": 2.5}, NumericError, r"samples must be an integer >= 2; found 2.5"),
    ({"method": "fem"}, NumericError, r"method must be one of 'galerkin', 'fd'; found 'fem'"),
    ({"resolution": 0}, NumericError, r"resolution must be a positive integer; found 0"),
    ({"scheme": 1}, ArgumentError, r"scheme must be a name such as 'expm'; found 1"),
    ({"scheme": "rk4"}, NumericError, r"unknown time-stepping scheme 'rk4'; expected one of"),
    ({"tol": -1e-6}, NumericError, r"tol must be a finite positive number; found -1e-06"),
    ({"z_w": []}, NumericError, r"z_w must be a non-empty list of finite points; found \[\]"),
    ({"z_w": [0, np.nan]}, NumericError, r"z_w must be a non-empty list of finite points"),
    ({"z_w": "a"}, NumericError, r"z_w must be a non-empty list of finite points"),
    ({"check_resolution": 1}, ArgumentError, r"check_resolution must be True or False"),
    ({"dt": 0}, NumericError, r"dt must be a finite positive number of seconds; found 0"),
    ({"dt": 1e-3, "sampler": "zoh"}, NumericError, r"sampler must be one of 'average', 'point'"),
    ({"sampler": "point"}, NumericError, r"sampler needs dt, the sampling period"),
    ({"observer_resolution": -2}, NumericError, r"observer_resolution must be a positive"),
    ({"dt": 1e-3, "scheme": "midpoint"}, NumericError, r"stepped exactly: scheme must be 'expm'"),
    ({"noise_intensity": -1.0}, NumericError, r"noise_intensity: intensities must be finite"),
    ({"input_intensity": [0.1, "x"]}, NumericError, r"input_intensity: expected numbers"),
    ({"noise_intensity": 1e300}, NumericError, r"noise_intensity: intensities must be at most"),
    ({"seed": 1}, NumericError, r"seed needs noise_intensity or input_intensity"),
    ({"seed": -1, "noise_intensity": 1.0}, NumericError, r"seed must be an integer >= 0"),
    ({"noise_intensity": 1.0, "dt": 1e-3}, NumericError, r"the noise options run the continuous"),
    ({"input_intensity": 1.0, "scheme": "midpoint"}, NumericError, r"a noisy simulation steps"),
]


@pytest.mark.parametrize(("changes", "error", "message"), BAD, ids=[str(row[0]) for row in BAD])
def test_each_bad_option_is_refused_naming_it(changes, error, message):
    with pytest.raises(error, match=message):
        SimulationOptions(**changes)


def test_the_options_say_which_run_they_ask_for():
    assert SimulationOptions().kind == "continuous"
    assert SimulationOptions(observer_resolution=8).kind == "sampled"
    assert SimulationOptions(input_intensity=0.5, seed=3).kind == "noisy"
    assert SimulationOptions(noise_intensity=[0.1, 0.2]).noise_intensity == (0.1, 0.2)
    assert SimulationOptions(dt=1e-3).sampler_name == "average"
    assert SimulationOptions().midpoint_tol == 1e-6
    assert SimulationOptions(z_w=np.array([0.5, 1.0])).z_w == (0.5, 1.0)


WAVE = numeric("wave")
DESIGN = (np.array([[0.0, 1.0]]), np.array([[0.5]]))
LOOP = NumericLoop((1,), np.eye(1), *DESIGN)
REFUSED = [
    (lambda o: simulate(WAVE, *DESIGN, options=o), {"dt": 1e-2}, "simulate_sampled does"),
    (lambda o: simulate(WAVE, *DESIGN, options=o), {"seed": 1, "input_intensity": 1}, "noisy"),
    (lambda o: simulate_noisy(WAVE, *DESIGN, options=o), {"dt": 1e-2}, "simulate_sampled"),
    (lambda o: simulate_sampled(WAVE, *DESIGN, options=o), {"noise_intensity": 1}, "noisy"),
    (lambda o: simulate_loop(WAVE, LOOP, options=o), {"observer_resolution": 4}, "sampled"),
]


@pytest.mark.parametrize(("call", "changes", "message"), REFUSED)
def test_a_simulator_refuses_another_kind_of_run_and_names_the_one_that_does_it(
    call, changes, message
):
    with pytest.raises(ArgumentError, match=message):
        call(SimulationOptions(**changes))


def test_what_a_simulator_does_not_use_is_refused_not_ignored():
    with pytest.raises(ArgumentError, match=r"^tol: the loop's midpoint steps once"):
        simulate_loop(WAVE, LOOP, options=SimulationOptions(tol=1e-3, scheme="midpoint"))
    with pytest.raises(NumericError, match=r"a noisy simulation steps exactly"):
        simulate_noisy(WAVE, options=SimulationOptions(scheme="midpoint"))
    with pytest.raises(NumericError, match=r"stepped exactly: scheme must be 'expm'"):
        simulate_sampled(WAVE, *DESIGN, options=SimulationOptions(scheme="midpoint"))


def test_the_design_objects_check_the_names_and_keep_their_discretization():
    obs = phd.Observer(phd.load("wave"), sensors=[2], gain=0.5, resolution=6)
    with pytest.raises(ArgumentError, match=r"^tend is not a simulation option; expected one"):
        obs.simulate(tend=1.0)
    with pytest.raises(ArgumentError, match=r"^options must be SimulationOptions; found dict"):
        obs.simulate(options={"t_end": 1.0})
    with pytest.raises(ArgumentError, match=r"^resolution belongs to the Plant .*found resol"):
        obs.simulate(resolution=12)
    with pytest.raises(ArgumentError, match=r"^method belongs to the Plant"):
        obs.plant.simulate(options=SimulationOptions(method="fd"))
    run = obs.simulate(options=SimulationOptions(t_end=0.5, samples=3), samples=5)
    assert run.t.size == 5  # a setting overrides the options
    assert run.resolution == 6  # the plant's
