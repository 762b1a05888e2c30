"""The noise commands: ``noise``, ``tradeoff``, ``tune --max-rms``, ``simulate --noise-intensity``.

Expected numbers come from the damped wave's closed forms (sensor y2, gain k, output
∫₀¹ x2 dz, unit intensity; derived in tests/numeric/noise/test_noise.py): spectral abscissa
½ ln|(1−k)/(1+k)| (DESIGN's exact check) and error variance k/2.
"""

from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import replace

import numpy as np
import pytest
from numeric_models import PAPER_SENSORS, numeric

from phdesign.cli import main
from phdesign.models import load_builtin
from phdesign.numeric.noise.figures import noise
from phdesign.numeric.noise.settle import settle
from phdesign.numeric.noise.tradeoff import tradeoff
from phdesign.numeric.noise.tuning import tune_noise

WAVE = ("wave", "--sensors", "2", "--integral", "x2: 1")


def run(capsys, *argv):
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def strict(text: str):
    """Parse JSON refusing NaN and Infinity."""

    def refuse(name):
        raise AssertionError(f"non-strict JSON constant {name}")

    return json.loads(text, parse_constant=refuse)


def alpha(k: float) -> float:
    return 0.5 * math.log(abs((1 - k) / (1 + k)))


def test_noise_json_contract_and_text_is_the_report(capsys, tmp_path):
    argv = ["noise", "euler-bernoulli", "--sensors", "3,4", "--gain", "0.1,1", "--at", "1"]
    status, out, _ = run(capsys, *argv, "--intensity", "0.01,0.04", "--json")
    assert status == 0
    data = strict(out)
    keys = {"model", "sensors", "gain", "intensity", "performance", "l2_gain", "error_energy"}
    assert keys | {"resolutions", "warnings"} <= set(data)
    (tip,) = data["performance"]
    assert {"name", "variance", "rms", "converged", "digits"} <= set(tip)
    assert tip["name"] == "w(1)"
    assert tip["converged"] is True
    assert tip["rms"] == pytest.approx(math.sqrt(tip["variance"]))
    assert {"value", "frequency", "converged", "digits", "diverges"} <= set(data["l2_gain"])
    energy = data["error_energy"]
    assert energy["diverges"] is True
    assert energy["value"] is None
    assert len(energy["values"]) == len(data["resolutions"]) >= 3
    picture = tmp_path / "noise.png"
    status, text, _ = run(capsys, *argv, "--intensity", "0.01,0.04", "--plot", str(picture))
    assert picture.stat().st_size > 0
    report = noise(
        numeric("euler-bernoulli"),
        PAPER_SENSORS,
        np.diag([0.1, 1.0]),
        intensity=[0.01, 0.04],
        performance=["w(1)"],
    )
    assert text == str(report) + "\n"  # the CLI prints the library's text
    assert len(repr(report)) <= 300
    assert "<table>" in report._repr_html_()


def test_tradeoff_ray_matches_the_wave_closed_forms(capsys, tmp_path):
    """Along k = 0.5, 2, 8: decay −α and rms √(k/2); k = 2 decays exactly as fast as
    k = 0.5 (½ ln 3 both) with more noise, and k = 8 slower still: both dominated."""
    table = tmp_path / "wave.csv"
    figure = tmp_path / "wave.png"
    status, out, err = run(
        capsys,
        "tradeoff",
        *WAVE,
        "--scales",
        "0.5:8:3",
        "--csv",
        "-o",
        str(table),
        "--plot",
        str(figure),
    )
    assert status == 0, err
    assert out == ""
    assert figure.stat().st_size > 0
    rows = list(csv.DictReader(io.StringIO(table.read_text())))
    ks = [float(r["l1"]) for r in rows]
    assert ks == pytest.approx([0.5, 2.0, 8.0])
    for row, k in zip(rows, ks, strict=True):
        assert float(row["rms int(x2: 1)"]) == pytest.approx(math.sqrt(k / 2), rel=1e-9)
        assert float(row["decay_rate"]) == pytest.approx(-alpha(k), rel=1e-8)
    assert [r["pareto"] for r in rows] == ["True", "False", "False"]


def test_tradeoff_grid_library_and_printing():
    wave = load_builtin("wave")
    result = tradeoff(
        numeric("wave"),
        np.array([[0.0, 1.0]]),
        grid=[[0.2, 0.5]],
        performance=["x2: 1"],
        model=wave,
    )
    assert [p.pareto for p in result.points] == [True, True]  # faster costs more noise
    data = json.loads(json.dumps(result.to_dict(), allow_nan=False))
    assert data["pareto"] == [0, 1]
    assert "Pareto" in str(result)
    assert len(repr(result)) <= 300
    assert "<table>" in result._repr_html_()
    assert result.plot() is not None


def test_tune_max_rms_on_the_wave_meets_the_closed_form(capsys):
    """min α subject to √(k/2) <= 0.5: α decreases in k up to the matched damper, so the
    constraint is active, k* = 2 R² = 0.5 and α* = ½ ln(1/3)."""
    status, out, err = run(capsys, "tune", *WAVE, "--max-rms", "0.5", "--json")
    assert status == 0, err
    data = strict(out)
    assert data["gain"][0][0] == pytest.approx(0.5, rel=1e-3)
    assert data["spectral_abscissa"] == pytest.approx(alpha(0.5), abs=1e-3)
    assert data["feasible"] is True
    assert data["rms"] <= 0.5 * (1 + 1e-6)


@pytest.mark.slow
def test_tune_min_decay_on_the_wave_meets_the_closed_form():
    """min √(k/2) subject to α <= −a: α(k) <= −a exactly when k >= tanh a."""
    a = 0.3
    res = tune_noise(
        numeric("wave"),
        np.array([[0.0, 1.0]]),
        objective="rms",
        min_decay=a,
        performance=["x2: 1"],
        model=load_builtin("wave"),
    )
    assert res.feasible
    assert res.gain[0, 0] == pytest.approx(math.tanh(a), rel=1e-3)
    assert res.rms == pytest.approx(math.sqrt(math.tanh(a) / 2), rel=1e-3)
    assert len(repr(res)) <= 300
    assert "constraint met: True" in str(res)


def test_stochastic_simulation_is_seeded_and_exact_in_time(capsys):
    base = ["simulate", "euler-bernoulli", "--sensors", "3,4", "--gain", "0.1,1"]
    args = [*base, "--t-end", "1", "--samples", "11", "--resolution", "12"]
    noisy = [*args, "--noise-intensity", "0.01,0.04", "--input-noise", "0,0,0,0.1"]
    status, first, err = run(capsys, *noisy, "--seed", "5")
    assert status == 0, err
    assert run(capsys, *noisy, "--seed", "5")[1] == first  # same seed, same path
    assert run(capsys, *noisy, "--seed", "6")[1] != first
    status, out, _ = run(capsys, *noisy, "--seed", "5", "--json")
    data = strict(out)
    assert data["seed"] == 5
    assert "sensor intensity 0.01, 0.04" in data["noise"]
    assert data["H_err"][0] == 0.0  # plant and observer start equal (both zero)
    assert data["H_err"][-1] > 0.0  # and the noise drives them apart
    quiet = run(capsys, *args)[1]  # zero intensities give the deterministic run
    zero = run(capsys, *args, "--noise-intensity", "0", "--seed", "1")[1]
    assert zero == quiet


def test_a_noise_tuning_cut_short_by_its_iteration_limit_says_so():
    # two gains, maxiter 1: Nelder-Mead gets 2 steps, cannot settle, and the result must
    # not pass for an optimum
    res = tune_noise(
        numeric("wave"),
        np.eye(2),
        objective="rms",
        min_decay=0.3,
        performance=["x2: 1"],
        model=load_builtin("wave"),
        maxiter=1,
    )
    assert any("stopped at its iteration limit (2 steps)" in w for w in res.warnings)


def test_a_figure_that_did_not_converge_prints_its_agreeing_digits_and_star_means_one_thing():
    # 0.60941 and 0.60950 agree to -log10(9e-5 / 0.6095) = 3.83 digits: 4 are printed
    var = settle("int(x2: 1)", [0.60941, 0.60950], [20, 30], 1e-6)
    assert var.approximate() == "≈ 0.6095, 3.8 digits, not converged"
    assert str(var).startswith("int(x2: 1) ≈ 0.6095, 3.8 digits, not converged")
    result = tradeoff(
        numeric("wave"), np.array([[0.0, 1.0]]), grid=[[0.2, 0.5]], performance=["x2: 1"]
    )
    point = result.points[0]
    unsettled = replace(point, noise=replace(point.noise, performance=(var,)))
    text = str(replace(result, points=(unsettled, result.points[1])))
    rows = [line for line in text.splitlines() if line.startswith("  [") or "diag" in line]
    assert "0.7807*" in rows[0]  # rms = sqrt(0.6095): as many digits as the variance
    assert rows[0].endswith("yes")  # Pareto is a word, so that * has one meaning
    assert "*" not in rows[1]
    assert "(*: did not converge, shown to the digits that agree" in text
    assert "Var[int(x2: 1)~] ≈ 0.6095, 3.8 digits, not converged   rms ≈ 0.7807" in str(
        unsettled.noise
    )
