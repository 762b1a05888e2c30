"""Certificates of the observer-based loop: the plant's own classification and separation.

Expected constants are derived by hand in each test (traces on the admissible set, the
left-hand side LHS and the right-hand side RHS of the variant, κ* = inf LHS/RHS); the
loop's verdict follows the cascade argument of ``phdesign.symbolic.control``.
"""

from __future__ import annotations

import json

import pytest
import sympy

from phdesign.core.errors import LoopError, ObserverError
from phdesign.design.loop import Loop
from phdesign.models import load_builtin
from phdesign.symbolic.classify import classify
from phdesign.symbolic.closing import close_inputs
from phdesign.symbolic.control import (
    classify_loop,
    controlled_plant,
    error_output_bounded,
    feedback_gain,
    loop_verdict,
)
from phdesign.symbolic.observer import gain_matrix, sensor_matrix

BEAM = load_builtin("euler-bernoulli")


def no_sensors(model):
    """C_m with zero rows and an empty L: the plant's own classification."""
    return sympy.zeros(0, model.n_ports), sympy.zeros(0, 0)


def test_the_plant_is_classified_with_no_sensors_by_its_own_dissipation():
    # wave-damper, k = 1/2: admissible traces e1(0) = 0, e2(1) = -k e1(1).
    # LHS = k e1(1)², RHS(3.2.2) = e1(1)² + e2(1)² = (1 + k²) e1(1)², so κ* = k/(1 + k²) = 2/5
    string = load_builtin("wave-damper")
    result = classify(string, *no_sensors(string))
    assert result.verdict == "exponential"
    assert result.result("3.2", 2).kappa == sympy.Rational(2, 5)
    assert result.result("3.2", 1).holds is False  # e2(0) = -y1 is not dissipated
    assert result.C_m.shape == (0, 1)
    # the open wave, no sensors and no damper: LHS = 0, nothing holds
    wave = load_builtin("wave")
    open_result = classify(wave, *no_sensors(wave))
    assert open_result.verdict == "inconclusive"
    assert all(not r.holds for r in open_result.results if r.applicable)


def test_the_beam_closed_by_a_tip_shear_damper_has_the_hand_derived_kappa():
    # u4 = -k y4: e2'(1) = k e1(1); clamped e1(0) = e1'(0) = 0; u3 = e2(1) = 0.
    # LHS = k e1(1)². RHS of 3.4.4 with x1 = (x1), x2 = (x2): ‖e(1)‖² + e2'(1)² + e1'(0)²
    # = e1(1)² + k² e1(1)², so κ* = k/(1 + k²): 2/5 at k = 2.
    closed = controlled_plant(BEAM, [4], feedback_gain(2, 1))
    assert closed == close_inputs(BEAM, [4], [[2]])
    result = classify(closed, *no_sensors(closed))
    assert result.verdict == "exponential"
    assert result.best.kappa == sympy.Rational(2, 5)


def test_the_tip_torque_plant_is_not_certified_and_the_witness_names_the_tip_velocity():
    # u3 = -k y3 dissipates only e1'(1)²: the tip velocity e1(1) is free on the admissible
    # traces, and every variant of 3.4 at b selects it (e(b)), so all fail.
    closed = controlled_plant(BEAM, [3], feedback_gain(1, 1))
    result = classify(closed, *no_sensors(closed))
    assert result.verdict == "inconclusive"
    loop = classify_loop(BEAM, [3], feedback_gain(1, 1), sensor_matrix([4], 4), gain_matrix(1, 1))
    text = str(loop)
    assert "3.4.3 fails: e1(1) is left free by the boundary dissipation" in text
    assert loop.to_dict()["plant"]["results"][10]["free"] == ["e1(1)"]  # plant notation
    assert loop.verdict == "inconclusive"


@pytest.mark.parametrize(
    ("plant", "error", "source", "bounded", "verdict"),
    [
        ("exponential", "exponential", "estimate", True, "exponential"),
        ("exponential", "exponential", "estimate", False, "exponential"),  # admissibility
        ("asymptotic", "exponential", "estimate", False, "asymptotic"),
        ("exponential", "asymptotic", "estimate", True, "asymptotic"),
        ("exponential", "asymptotic", "estimate", False, "inconclusive"),
        ("asymptotic", "asymptotic", "estimate", True, "asymptotic"),
        ("inconclusive", "exponential", "estimate", True, "inconclusive"),
        ("exponential", "inconclusive", "estimate", True, "inconclusive"),
        ("exponential", "asymptotic", "measured", False, "asymptotic"),  # decoupled
        ("exponential", "exponential", "measured", False, "exponential"),
    ],
)
def test_the_loop_verdict_follows_the_cascade_argument(plant, error, source, bounded, verdict):
    result, reason = loop_verdict(plant, error, source, bounded)
    assert result == verdict
    assert "unstable" not in reason
    if (plant, error, bounded) == ("exponential", "exponential", False) and source == "estimate":
        assert "admissible output" in reason  # the assumption is stated, not hidden


def test_a_certified_loop_feeds_back_the_estimated_tip_velocity_measuring_the_root_moment():
    # controlled plant u4 = -y4: exponential (above, κ* = 1/2 at k = 1).  Error with y2 alone:
    # exponential by 3.4.2 with the partition (x2, x1), RHS ‖e(0)‖² + e1'(0)² + e2'(1)²,
    # which does not contain ỹ4 = -ẽ1(1): the bound uses the admissibility of ỹ4.
    loop = Loop(BEAM, actuate=4, feedback=1, sensors=[2], gain=1).classify()
    assert (loop.plant.verdict, loop.error.verdict, loop.verdict) == ("exponential",) * 3
    assert loop.bounded is False
    # with y4 itself measured, LHS = l ỹ4² bounds it: no assumption needed
    direct = Loop(BEAM, actuate=4, feedback=1, sensors=[4], gain=1).classify()
    assert direct.bounded is True
    assert "certificate bounds" in direct.reason
    assert error_output_bounded(direct.error, [4])
    payload = json.loads(json.dumps(loop.to_dict()))
    assert payload["plant_verdict"] == "exponential"
    assert payload["verdict"] == "exponential"


def test_measured_feedback_needs_the_collocated_output_among_the_sensors():
    with pytest.raises(LoopError, match=r"y3 = e1'\(1\) .* is not measured by these sensors"):
        Loop(BEAM, actuate=3, sensors=[4], feedback_source="measured")
    # y3 + y4 and y4 measured: y3 is in the row space of C_m
    loop = Loop(
        BEAM, actuate=3, C_m=[[0, 0, 1, 1], [0, 0, 0, 1]], gain=1, feedback_source="measured"
    )
    result = loop.classify()
    assert result.plant.verdict == "inconclusive"
    assert result.verdict == "inconclusive"


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"actuate": 5}, r"actuate: u5 is not an input of the model; expected an index in 1\.\.4"),
        ({"actuate": [3, 3]}, "input u3 is repeated"),
        ({"actuate": []}, "at least one input"),
        ({"actuate": 3, "feedback": -1}, r"K \+ Kᵀ must be positive definite"),
        ({"actuate": 3, "feedback": 0}, r"found minor 1 = 0"),  # K + Kᵀ = 0
        # K + Kᵀ = [[2, 6], [6, 2]]: its second leading minor is 4 - 36 = -32
        ({"actuate": [3, 4], "feedback": [[1, 3], [3, 1]]}, r"found minor 2 = -32"),
        ({"actuate": [3, 4], "feedback": [1, 2, 3]}, "expected 2 diagonal values"),
        ({"actuate": 3, "feedback": [[1, 0]]}, r"expected \(1, 1\)"),
        ({"actuate": 3, "feedback": float("nan")}, "entry 1 must be a finite positive number"),
        ({"actuate": 3, "feedback_outputs": 4}, "y4 = -e1\\(1\\) is not collocated with"),
        ({"actuate": 3, "feedback_source": "model"}, "feedback_source must be one of"),
    ],
)
def test_bad_loops_are_refused_with_a_message_that_names_the_culprit(kwargs, message):
    arguments = {"sensors": [4], **kwargs}
    with pytest.raises(LoopError, match=message):
        Loop(BEAM, **arguments)


def test_a_skew_part_in_K_is_allowed_and_the_observer_checks_stay_its_own():
    # K = [[1, 5], [-5, 1]]: K + Kᵀ = 2I > 0 (power in = -yᵀ K y = -|y|²)
    assert Loop(BEAM, actuate=[3, 4], feedback=[[1, 5], [-5, 1]], sensors=[4]).K[0, 1] == 5
    with pytest.raises(ObserverError, match="L \\+ Lᵀ must be positive definite"):
        Loop(BEAM, actuate=3, sensors=[4], gain=-1)


def test_the_loop_prints_short_and_builds_from_an_observers_parts():
    loop = Loop.from_parts(
        BEAM, sensor_matrix([4], 4), sympy.Matrix([[2]]), actuate=3, parameters={"d": 0}
    )
    assert {str(k): v for k, v in loop.model.parameters}["d"] == 0  # overrides applied
    assert len(repr(loop)) <= 300
    assert "actuate=(3,)" in repr(loop)
    assert "<table>" in loop._repr_html_()
    assert sympy.Matrix([[3]]) == loop.with_gains(feedback=3).K
    assert json.loads(json.dumps(loop.to_dict()))["gain"] == [["2"]]
    result = loop.classify()
    assert len(repr(result)) <= 300
    assert "<table>" in result._repr_html_()
