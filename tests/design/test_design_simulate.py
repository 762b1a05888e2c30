"""``Observer.simulate`` takes what ``phdesign simulate`` takes, and runs the same computation.

Each row gives the command's flags and the library's settings for one kind of run (the
continuous observer, a sampled one, a lower-order one, a noisy run) on a small wave; the
command's JSON and the library's result are the same, number for number (one route: both
go through ``Plant.run``).
"""

from __future__ import annotations

import json

import pytest

import phdesign as phd
from phdesign.cli import main

KINDS = {
    "continuous": ([], {}),
    "sampled": (["--dt", "0.125", "--sampler", "point"], {"dt": 0.125, "sampler": "point"}),
    "lower order": (["--observer-resolution", "4"], {"observer_resolution": 4}),
    "noisy": (
        ["--noise-intensity", "0.1", "--input-noise", "0.2", "--seed", "3"],
        {"noise_intensity": 0.1, "input_intensity": 0.2, "seed": 3},
    ),
}


@pytest.mark.parametrize("kind", list(KINDS))
def test_observer_simulate_runs_what_the_command_runs(capsys, kind):
    flags, settings = KINDS[kind]
    argv = "simulate wave --sensors 2 --gain 0.5 --resolution 6 --t-end 1 --samples 5 --json"
    status = main([*argv.split(), "--x0", "x2: 1", "--u", "u1: sin(t)", *flags])
    command = json.loads(capsys.readouterr().out)
    assert status == 0
    observer = phd.Observer(phd.load("wave"), sensors=[2], gain=0.5, resolution=6)
    run = observer.simulate("x2: 1", u="u1: sin(t)", t_end=1, samples=5, **settings)
    library = json.loads(run.to_json())
    assert library == command  # every series, the scheme, sampler, seed and labels
    assert library["H_err"] != command["H"]  # the series are not trivially equal
