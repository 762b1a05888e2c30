"""The ``phdesign loop`` command: JSON contract, printing, files (argument table style)."""

from __future__ import annotations

import csv
import io
import json

import pytest

from phdesign.cli import main

BEAM_LOOP = ["euler-bernoulli", "--actuate", "3", "--feedback", "1", "--sensors", "4"]


def run(argv, capsys):
    status = main(argv)
    out, err = capsys.readouterr()
    assert status == 0, err
    return out, err


def test_loop_spectrum_json_has_the_contract_keys(capsys):
    out, _ = run(
        ["loop", "spectrum", *BEAM_LOOP, "--gain", "1", "--param", "d=0", "--json"], capsys
    )
    payload = json.loads(out)
    for key in ("spectral_abscissa", "converged", "plant_abscissa", "error_abscissa", "warnings"):
        assert key in payload
    assert payload["converged"] is True
    # separation: the loop is as slow as the slower block (here the controlled plant)
    assert payload["spectral_abscissa"] == pytest.approx(payload["plant_abscissa"], abs=1e-10)
    assert payload["error_abscissa"] < payload["plant_abscissa"] < 0
    assert payload["model"] == "euler-bernoulli"
    assert payload["origin"][0] == "plant"


def test_loop_spectrum_text_is_the_reports_str(capsys):
    out, _ = run(["loop", "spectrum", *BEAM_LOOP, "--count", "2"], capsys)
    lines = out.splitlines()
    assert lines[0].startswith("model: euler-bernoulli   loop: u3 = -K ŷ3, K = [[1]]")
    assert lines[1].startswith("loop spectral abscissa: ")
    assert lines[2].startswith("controlled plant (u_a = -K y_a): ")
    assert lines[3].startswith("observer error system: ")


def test_loop_classify_reports_the_three_verdicts(capsys):
    argv = ["loop", "classify", "euler-bernoulli", "--actuate", "4", "--sensors", "2"]
    out, _ = run([*argv, "--json"], capsys)
    payload = json.loads(out)
    assert (payload["plant_verdict"], payload["error_verdict"], payload["verdict"]) == (
        "exponential",
        "exponential",
        "exponential",
    )
    assert payload["plant"]["sensors"] == []
    assert payload["feedback"] == [["1"]]
    text, _ = run(argv, capsys)
    assert text.splitlines()[-1].startswith("loop: exponential: both converge exponentially")
    # the sensors as the classify command names them, not C_m's entries as strings (issue 28)
    error_line = next(line for line in text.splitlines() if line.startswith("observer error"))
    assert error_line == "observer error system (sensors y2, L = diag(1)): exponential"


def test_loop_simulate_writes_csv_and_a_figure_and_refuses_to_overwrite(tmp_path, capsys):
    target, figure = tmp_path / "loop.csv", tmp_path / "loop.png"
    argv = [
        "loop",
        "simulate",
        *BEAM_LOOP,
        "--x0",
        "x1: 0, x2: z - 0.9",
        "--t-end",
        "1",
        "--samples",
        "11",
        "--resolution",
        "12",
        "-o",
        str(target),
        "--plot",
        str(figure),
    ]
    run(argv, capsys)
    rows = list(csv.reader(io.StringIO(target.read_text())))
    assert rows[0][:4] == ["t", "H", "H_hat", "H_err"]
    assert rows[0][-6:] == ["w_tip", "w_hat_tip", "u1", "u2", "u3", "u4"]
    assert len(rows) == 12
    assert figure.stat().st_size > 0
    assert main(argv) == 2  # both files exist now: nothing is overwritten without --force
    assert "exists; pass --force" in capsys.readouterr().err
    out, _ = run([*argv[:-4], "--json"], capsys)
    assert json.loads(out)["actuated"] == [3]


def test_loop_tune_prints_both_gains(capsys):
    untuned = ["euler-bernoulli", "--actuate", "3", "--sensors", "4"]  # K is what is tuned
    out, _ = run(
        ["loop", "tune", *untuned, "--tune", "feedback", "--starts", "1", "--json"], capsys
    )
    payload = json.loads(out)
    assert payload["tuned"] == "feedback"
    assert payload["gain"] == [[1.0]]
    assert payload["spectral_abscissa"] == pytest.approx(payload["plant_abscissa"], abs=1e-8)
    assert payload["plant_abscissa"] < -1.0  # K = 1 gives -0.7207 (the spectrum test)
