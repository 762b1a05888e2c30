"""``phdesign gain``: the norms of the plant and of an observer's error, and bad input."""

from __future__ import annotations

import json

import pytest

from phdesign.cli import main
from phdesign.io import model_from_dict, model_to_dict, model_to_toml
from phdesign.models import load_builtin


@pytest.fixture
def beam_file(tmp_path):
    """The paper's beam under a uniform load, its tip deflection judged."""
    data = model_to_dict(load_builtin("euler-bernoulli"))
    data["disturbances"] = {"B": [[1], [0]]}
    data["performance"] = {"outputs": ["w(1)"]}
    path = tmp_path / "beam.toml"
    path.write_text(model_to_toml(model_from_dict(data)))
    return str(path)


def test_gain_of_the_plant_as_json(beam_file, capsys):
    assert main(["gain", beam_file, "--max-resolution", "30", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["sources"] == ["w1"]
    assert out["outputs"] == ["w(1)"]
    assert out["sensors"] is None
    # the tip deflection's peak at the first resonance (the modal closed form of
    # tests/numeric/noise/test_disturbance_gain.py: 2.2277802740)
    assert out["hinf"]["value"] == pytest.approx(2.2277802740, rel=1e-8)
    assert out["hinf"]["frequency"] == pytest.approx(3.5132, rel=1e-4)
    assert out["h2"]["converged"]


def test_gain_of_an_observer_prints_the_split(beam_file, capsys):
    argv = ["gain", beam_file, "--sensors", "3,4", "--gain", "0.1,1", "--noise", "0.01"]
    assert main([*argv, "--max-resolution", "30"]) == 0
    out = capsys.readouterr().out
    assert "sources: w1, nu1, nu2" in out
    assert "by source:" in out
    assert "H2 sources -> the error of z_p" in out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["gain", "wave-damper"], "needs performance outputs"),
        (["gain", "wave-damper", "--performance", "integral(e1)"], "has no disturbance"),
        (["gain", "{beam}", "--noise", "0.1"], "--noise needs --sensors or --cm"),
        (["gain", "{beam}", "--optimal"], "--optimal needs --sensors or --cm"),
        (["gain", "{beam}", "--performance", "integral(e1(1))"], "integral\\(\\) of a trace"),
        (["gain", "{beam}", "--sensors", "3,4"], "--gain"),
    ],
)
def test_gain_refuses_bad_input_in_one_line(argv, message, beam_file, capsys):
    import re

    assert main([a.replace("{beam}", beam_file) for a in argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert re.search(message, err), err
