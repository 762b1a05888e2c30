"""The verdict on observers of models with boundary systems (issue 26): what is proved, by what."""

from __future__ import annotations

import json

import pytest
from string_models import string_with_maxwell_end

from phdesign.cli import main
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.symbolic.classify import classify
from phdesign.symbolic.coupled_classify import ASYMPTOTIC, EXPONENTIAL
from phdesign.symbolic.observer import sensor_matrix
from phdesign.symbolic.search import search_sensors


@pytest.mark.parametrize("sensors", [[], [1], [2], [1, 2]])
def test_tip_mass_string_is_never_exponential(sensors):
    # Damped only through the mass (D_c = 0): not strictly input passive, and known not to be
    # exponentially stable (its high modes see the mass as a wall); the spectrum agrees
    # (test_boundary_dynamics). Every sensor set is asymptotic by the imaginary-axis test:
    # R_c = c > 0 forces e_c = 0, then the mass's equation forces y_2 = 0 and u_2 = 0 at z = 1.
    model = load_builtin("string-tip-mass")
    result = classify(
        model, sensor_matrix(sensors, 2) if sensors else [], [1] * len(sensors) or None
    )
    assert result.verdict == "asymptotic"
    exponential, asymptotic = result.results
    assert exponential.theorem == EXPONENTIAL
    assert not exponential.holds
    assert "'mass' is not strictly input passive" in exponential.reason
    assert asymptotic.theorem == ASYMPTOTIC
    assert asymptotic.holds
    assert "exponential" not in result.verdict
    assert "verdict: asymptotic" in str(result)


def test_all_sensor_sets_of_the_tip_mass_string():
    found = search_sensors(load_builtin("string-tip-mass"), gain=1)
    assert found.minimal == {"exponential": (), "asymptotic": ((1,), (2,)), "inconclusive": ()}


def test_strictly_input_passive_end_gives_exponential_and_the_spectrum_agrees():
    # The static part is the damper e2(1) = -d e1(1): Proposition 3.2 holds for the plant
    # itself (no sensors) with kappa* = d/(1 + d^2) (LHS d e1(1)^2, RHS e1(1)^2 + e2(1)^2).
    model = string_with_maxwell_end(d=1)
    result = classify(model, [], None)
    assert result.verdict == "exponential"
    assert result.best.theorem == EXPONENTIAL
    assert result.best.kappa == pytest.approx(0.5, abs=1e-12)
    report = spectrum(to_numeric(model))
    assert report.converged
    assert not report.no_decay
    assert report.spectral_abscissa < -1e-3


def test_undamped_hub_is_inconclusive_and_says_why():
    result = classify(load_builtin("flexible-arm"), [], None)
    assert result.verdict == "inconclusive"
    assert "traces at both ends free" in result.results[1].reason
    assert "stated for N = 1" not in result.results[0].reason  # the arm is N = 1
    assert "'hub' is not strictly input passive" in result.results[0].reason


def test_beam_with_tip_body_exponential_theorem_does_not_apply():
    result = classify(load_builtin("beam-tip-body"), [], None)
    assert not result.results[0].applicable
    assert result.results[0].reason == "stated for N = 1 (N = 2)"


def test_motor_resistance_makes_the_driven_string_asymptotic():
    # R_c = diag(Rw, 0): i = 0; the winding's own equation is then lambda-free, kt w = 0,
    # so the rotor rests, y_1 = 0 and u_1 = 0 at z = 0: zero Cauchy data.
    assert classify(load_builtin("string-motor"), [], None).verdict == "asymptotic"


def test_classify_json_keeps_the_contract(capsys):
    status = main(["classify", "string-tip-mass", "--sensors", "2", "--gain", "2", "--json"])
    assert status == 0
    data = json.loads(capsys.readouterr().out)
    assert {
        "model",
        "order",
        "size",
        "sensors",
        "gain",
        "partitioned",
        "results",
        "verdict",
    } <= set(data)
    assert data["verdict"] == "asymptotic"
    assert data["boundary_systems"] == ["mass"]
    assert data["results"][0]["holds"] is False
    assert data["results"][1]["holds"] is True


def test_symbolic_gains_on_coupled_models():
    # The asymptotic test does not involve L (sym(L) > 0 only turns y~_m^T sym(L) y~_m = 0
    # into C_m y~ = 0), so the tip-mass string is asymptotic for every positive l1, as at
    # the numeric gains below; never exponential.
    tip = load_builtin("string-tip-mass")
    symbolic = classify(tip, sensor_matrix([2], 2), "symbolic")
    assert symbolic.verdict == "asymptotic"
    assert symbolic.results[1].reason.endswith("(for all positive gains)")
    assert symbolic.to_dict()["gain"] == [["l1"]]
    for l1 in (0.3, 3):
        assert classify(tip, sensor_matrix([2], 2), [l1]).verdict == "asymptotic"
    found = search_sensors(tip, gain="symbolic")
    assert found.minimal == {"exponential": (), "asymptotic": ((1,), (2,)), "inconclusive": ()}
    assert "depends on L" not in str(found)  # the asymptotic theorem has no κ*
    # The Maxwell end with the sensor y1 = -e2(0): the static part has the injection
    # e1(0) = l1 e2(0), so -u~^T y~ >= l1 e2(0)^2 and ||e~(0)||^2 = (1 + l1^2) e2(0)^2:
    # Proposition 3.2 variant 1 with kappa* = l1/(l1^2 + 1) for every l1 > 0 (by hand)
    result = classify(string_with_maxwell_end(d=1), sensor_matrix([1], 1), "symbolic")
    assert result.verdict == "exponential"
    assert result.best.name == "RLMZ"
    assert "variant 1 (κ* = l1/(l1**2 + 1); holds for all positive l1)" in result.best.reason
