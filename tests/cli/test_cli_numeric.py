"""The numeric commands: spectrum, simulate, tune (JSON contract and bad input)."""

from __future__ import annotations

import csv
import io
import json
import math

import pytest

from phdesign.cli import main


def run(capsys, *argv):
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_spectrum_json_contract_wave_damper(capsys):
    status, out, _ = run(capsys, "spectrum", "wave", "--sensors", "2", "--gain", "0.5", "--json")
    assert status == 0
    data = json.loads(out)
    assert {"spectral_abscissa", "rightmost", "converged"} <= set(data)
    assert data["converged"] is True
    # 1/2 ln(1/3), the exact damped-wave abscissa (DESIGN.md)
    assert abs(data["spectral_abscissa"] - 0.5 * math.log(1 / 3)) < 1e-8
    assert all(len(z) == 2 for z in data["rightmost"])


def test_spectrum_extinction_prints_no_number(capsys):
    status, out, _ = run(capsys, "spectrum", "wave", "--sensors", "2", "--gain", "1")
    assert status == 0
    assert "unbounded below" in out
    status, out, _ = run(capsys, "spectrum", "wave", "--sensors", "2", "--gain", "1", "--json")
    data = json.loads(out)
    assert data["spectral_abscissa"] is None
    assert data["unbounded_below"] is True


def test_spectrum_plant_with_param_override(capsys):
    status, out, _ = run(capsys, "spectrum", "euler-bernoulli", "--param", "d=0.5", "--json")
    assert status == 0
    assert abs(json.loads(out)["spectral_abscissa"] + 0.25) < 1e-10  # -d/2


def test_simulate_csv_and_json(capsys, tmp_path):
    argv = [
        "simulate",
        "euler-bernoulli",
        "--sensors",
        "3,4",
        "--gain",
        "0.1,1",
        "--x0",
        "x1: 0, x2: z - 0.9",
        "--t-end",
        "0.5",
        "--samples",
        "6",
        "--resolution",
        "12",
    ]
    status, out, _ = run(capsys, *argv)
    assert status == 0
    rows = list(csv.reader(io.StringIO(out)))
    assert rows[0][:4] == ["t", "H", "H_hat", "H_err"]
    assert len(rows) == 7
    target = tmp_path / "sim.json"
    status, out, _ = run(capsys, *argv, "--json", "--output", str(target))
    assert status == 0
    assert out == ""
    data = json.loads(target.read_text())
    assert abs(data["H"][0] - 0.73 / 6) < 1e-12  # H(0) = 1/2 int (z - 0.9)^2
    status, _, err = run(capsys, *argv, "--json", "--output", str(target))
    assert status == 2
    assert "exists" in err


@pytest.mark.slow
def test_simulate_plot(capsys, tmp_path):
    target = tmp_path / "sim.png"
    status, _, _ = run(
        capsys,
        "simulate",
        "euler-bernoulli",
        "--sensors",
        "3,4",
        "--gain",
        "0.1,1",
        "--x0",
        "x2: z - 0.9",
        "--t-end",
        "1",
        "--samples",
        "51",
        "--resolution",
        "12",
        "--plot",
        str(target),
    )
    assert status == 0
    assert target.stat().st_size > 1000


def test_tune_json_contract(capsys):
    status, out, _ = run(capsys, "tune", "wave", "--sensors", "2", "--starts", "1", "--json")
    assert status == 0
    data = json.loads(out)
    assert {"gain", "spectral_abscissa"} <= set(data)
    assert data["gain"][0][0] > 0


def test_modes_table_and_json(capsys):
    # the wave plant (u = 0): ω_m = (m + ½)π, undamped (DESIGN.md)
    status, out, _ = run(capsys, "modes", "wave", "--count", "2")
    assert status == 0
    assert "ω_n [rad/s]" in out
    assert "1.5707963" in out
    assert "4.712389" in out
    status, out, _ = run(capsys, "modes", "wave", "--sensors", "2", "--gain", "0.5", "--json")
    data = json.loads(out)
    assert data["units"]["frequency"] == "Hz"
    assert len(data["modes"]) == 6
    first = data["modes"][0]
    # ½ ln(1/3) + iπ/2: ζ = −Re λ / |λ|
    lam = complex(0.5 * math.log(1 / 3), math.pi / 2)
    assert abs(first["damping_ratio"] + lam.real / abs(lam)) < 1e-9
    assert first["block"] == "error"


def test_modes_bad_count_is_one_line(capsys):
    status, _, err = run(capsys, "modes", "wave", "--count", "0")
    assert status == 2
    assert err.count("\n") == 1
    assert "--count" in err
