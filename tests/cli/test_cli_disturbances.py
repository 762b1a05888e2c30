"""The disturbances on the command line: ``simulate --w``, ``--disturbance-noise`` (issue 27)."""

from __future__ import annotations

import json
import math

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


#: The string with ρ = T = 2 under a uniform force, ∫ e1 judged: with sensor y2 and gain k
#: its error is the damped-tip string of damper k/2 scaled by 1/2
#: (tests/numeric/noise/test_disturbance_tuning.py)
STRING = """
name = "string under a force"
interval = [0, 1]
order = 1
[parameters]
rho = 2
T = 2
[matrices]
P1 = [[0, 1], [1, 0]]
H = [["1/rho", 0], [0, "T"]]
[ports]
inputs = ["e1(0)", "e2(1)"]
outputs = ["-e2(0)", "e1(1)"]
[disturbances]
B = [[1], [0]]
[performance]
outputs = ["integral(e1)"]
"""


@pytest.fixture
def string(tmp_path):
    path = tmp_path / "string.toml"
    path.write_text(STRING)
    return str(path)


@pytest.mark.slow
def test_tune_objective_hinf_prints_the_gain_report_of_its_gain(string, capsys):
    from phdesign import Observer, load

    argv = ["tune", string, "--sensors", "2", "--objective", "hinf", "--intensity", "0"]
    assert main([*argv, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    # recomputed from scratch at the printed gain: the same number, no worse than L = I
    again = Observer(load(string), sensors=[2], gain=out["gain"]).gain(intensity=0)
    assert out["hinf"] == again.hinf.value
    assert out["hinf"] < out["start"]["hinf"]
    assert out["objective"] == "hinf"
    assert out["feasible"] is True


def test_tradeoff_against_hinf_is_the_damped_strings_closed_form(string, capsys):
    from disturbance_models import wave_hinf

    argv = ["tradeoff", string, "--sensors", "2", "--against", "hinf", "--intensity", "0"]
    assert main([*argv, "--scales", "0.5:1.5:2", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for point, k in zip(out["points"], (0.5, 1.5), strict=True):
        r = k / 2  # the damper of the unit string
        # -α = ½ ln|(1 + r)/(1 - r)| (to the abscissa's 1e-10) and γ = γ₁(r)/2 (to 1e-8)
        assert point["decay_rate"] == pytest.approx(0.5 * math.log((1 + r) / (1 - r)), abs=1e-9)
        assert point["hinf"] == pytest.approx(wave_hinf(r)[0] / 2, rel=1e-8)
    assert out["pareto"] == [1]  # k = 1.5 decays faster and lets less through


def test_an_unknown_input_driven_by_u_in_an_observers_run_is_refused(tmp_path, capsys):
    # the tip stress u2 marked unknown: --u would hand it to the observer, --w does not
    text = DAMPED.replace('[feedback]\ninputs = [2]\ngain = [["k"]]\n', "")
    path = tmp_path / "unknown.toml"
    path.write_text(text.replace('outputs = "conjugate"', 'outputs = "conjugate"\nunknown = [2]'))
    argv = ["simulate", str(path), "--sensors", "2", "--t-end", "1", "--samples", "3"]
    assert main([*argv, "--u", "u2: sin(t)"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert "u2 is marked unknown in [ports]" in err
    assert "--u cannot drive it" in err
    assert "through --w (the same 'u2: ...' text)" in err
    assert main([*argv, "--w", "u2: sin(t)"]) == 0
