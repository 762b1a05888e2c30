"""An observer without sensors: "is my damped plant certified by its own dampers?"

With C_m of no rows the error boundary is ũ_r = 0 and ũ_c = −K ỹ_c (the plant's
``[feedback]``), so every proposition's left-hand side is ỹ_cᵀ sym(K) ỹ_c alone
(``phdesign.symbolic.closing.error_dissipation``).  Expected constants are derived by hand
in each test from the admissible traces of ``beam-tip-damper``: clamped e1(0) = e1'(0) = 0,
u3 = e2(1) = 0, the damper u4 = −k y4 = k e1(1) = e2'(1), so LHS = k e1(1)².
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
import sympy

from phdesign.cli import main
from phdesign.core.errors import ObserverError
from phdesign.design.observer import Observer
from phdesign.models import load_builtin

DAMPED = load_builtin("beam-tip-damper")


@pytest.mark.parametrize("C_m", [np.zeros((0, 3)), [], sympy.zeros(0, 3), np.zeros((0, 0))])
def test_the_damped_beam_is_exponential_without_sensors(C_m):
    # 3.4 variant 4 (x1 = momentum, x2 = curvature): ‖e(1)‖² + e2'(1)² + e1'(0)²
    # = e1(1)² + k² e1(1)² on the traces, so κ* = k/(1 + k²) = 1/2 at the model's k = 1.
    result = Observer(DAMPED, C_m=C_m).classify()
    assert result.verdict == "exponential"
    assert (result.best.proposition, result.best.variant) == ("3.4", 4)
    assert result.best.kappa == sympy.Rational(1, 2)
    # 3.4 variant 3 selects e1'(1), which the damper leaves free (LHS does not see it)
    assert not result.result("3.4", 3).holds
    assert "ẽ1'(1) is left free by the boundary dissipation" in str(result)


def test_the_undamped_beam_without_sensors_is_inconclusive():
    # no [feedback] and no sensors: LHS = 0 while every right-hand side is a sum of traces
    # that are free on ker U, so no variant holds (the propositions say nothing)
    result = Observer(load_builtin("euler-bernoulli"), C_m=[]).classify()
    assert result.verdict == "inconclusive"
    assert all(not r.holds for r in result.results if r.applicable)


def test_the_command_line_classifies_no_sensors(capsys):
    # κ* = k/(1 + k²) = 2/5 at k = 2 (same derivation)
    status = main(["classify", "beam-tip-damper", "--cm", "[]", "--param", "k=2", "--json"])
    out, err = capsys.readouterr()
    assert (status, err) == (0, "")
    data = json.loads(out)
    assert (data["sensors"], data["gain"], data["verdict"]) == ([], [], "exponential")
    held = [(r["proposition"], r["variant"], r["kappa"]) for r in data["results"] if r["holds"]]
    assert held == [("3.4", 4, pytest.approx(0.4, rel=1e-15))]
    assert main(["classify", "beam-tip-damper", "--cm", "[]"]) == 0
    assert "sensors: none" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["classify", "beam-tip-damper", "--cm", "[]", "--gain", "1"], "--gain: no sensors"),
        (["spectrum", "beam-tip-damper", "--cm", "[]"], "--cm: no sensors .* is for classify"),
        (["tune", "beam-tip-damper", "--cm", "[]"], "--cm: no sensors .* is for classify"),
    ],
)
def test_the_command_line_refuses_no_sensors_elsewhere(capsys, argv, message):
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.count("\n") == 1
    assert re.search(message, err), err


@pytest.mark.parametrize(
    ("kwargs", "call", "message"),
    [
        ({"C_m": [], "gain": 1}, None, r"gain: no sensors \(C_m has no rows\) take no gain"),
        ({"C_m": np.zeros((0, 4))}, None, r"expected \(0, 3\) for no sensors but found \(0, 4\)"),
        ({"C_m": []}, "spectrum", r"spectrum needs at least one sensor"),
        ({"C_m": []}, "tune", r"tune needs at least one sensor"),
    ],
)
def test_the_library_refuses_what_no_sensors_cannot_do(kwargs, call, message):
    def build_and_call():
        observer = Observer(DAMPED, **kwargs)
        getattr(observer, call)()

    with pytest.raises(ObserverError, match=message):
        build_and_call()
