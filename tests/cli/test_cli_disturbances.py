"""The disturbances on the command line: ``simulate --w``, ``--disturbance-noise`` (issue 27)."""

from __future__ import annotations

import json

import pytest

from phdesign.cli import main

#: PIETOOLS' damped-tip string with viscous damping d = 1, under a uniform force w1
DAMPED = """
name = "viscous damped-tip wave"
interval = [0, 1]
order = 1
[parameters]
k = 0.5
[matrices]
P0 = [[-1, 0], [0, 0]]
P1 = [[0, 1], [1, 0]]
H = [[1, 0], [0, 1]]
[ports]
inputs = ["e1(0)", "e2(1)"]
outputs = "conjugate"
[feedback]
inputs = [2]
gain = [["k"]]
[disturbances]
B = [[1], [0]]
[performance]
outputs = ["integral(e1)"]
"""


@pytest.fixture
def damped(tmp_path):
    path = tmp_path / "damped.toml"
    path.write_text(DAMPED)
    return str(path)


def test_simulate_w_reaches_the_static_shape(damped, capsys):
    # q = 1 - z under w = 1 (tests/numeric/time/test_disturbance_simulation.py): H = 1/6
    argv = ["simulate", damped, "--w", "w1: 1", "--t-end", "80", "--samples", "3", "--json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["H"][-1] == pytest.approx(1 / 6, abs=1e-12)


def test_simulate_disturbance_noise_names_its_intensity(damped, capsys):
    argv = ["simulate", damped, "--disturbance-noise", "0.5", "--seed", "1", "--json"]
    assert main([*argv, "--t-end", "1", "--samples", "3"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["noise"] == "disturbance intensity 0.5"
    assert out["H"][-1] > 0  # driven from rest
