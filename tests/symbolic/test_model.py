"""Model validation: every condition of the paper's Section II, each failure named."""

from __future__ import annotations

import pytest
import sympy
from bad_inputs import BAD_MODELS, beam_with

from phdesign.core.errors import ModelError, ParameterError, PhdesignError
from phdesign.io import model_from_dict
from phdesign.models import load_builtin
from phdesign.symbolic.model import BCPHS, Z


@pytest.mark.parametrize(("changes", "error", "message"), BAD_MODELS)
def test_bad_models_are_refused_with_a_clear_message(changes, error, message):
    with pytest.raises(error, match=message) as info:
        model_from_dict(beam_with(**changes))
    assert isinstance(info.value, PhdesignError)
    assert isinstance(info.value, ValueError)


def test_there_are_at_least_25_bad_models():
    assert len(BAD_MODELS) >= 25


def test_define_from_code_equals_the_builtin():
    beam = BCPHS.define(
        name="euler-bernoulli",
        description=load_builtin("euler-bernoulli").description,
        interval=(0, 1),
        order=2,
        P={0: [["-d", 0], [0, 0]], 2: [[0, -1], [1, 0]]},
        H=[["1/rho", 0], [0, "EI"]],
        parameters={"rho": 1, "EI": 1, "d": 0.2},
        inputs=["e1(0)", "e1'(0)", "e2(1)", "e2'(1)"],
        outputs=["e2'(0)", "-e2(0)", "e1'(1)", "-e1(1)"],
        state_names=["momentum", "curvature"],
        displacement=load_builtin("euler-bernoulli").displacement,
        units=load_builtin("euler-bernoulli").unit_map,
    )
    assert beam == load_builtin("euler-bernoulli")
    assert dict(beam.parameters)[sympy.Symbol("d", real=True)] == sympy.Rational(1, 5)


def test_z_dependent_H_is_checked_exactly_when_rational_else_on_a_grid():
    def string(H):
        return BCPHS.define(
            name="tapered string",
            interval=(0, 2),
            order=1,
            P={1: [[0, 1], [1, 0]]},
            H=H,
            inputs=["e1(0)", "e2(2)"],
            outputs=["-e2(0)", "e1(2)"],
        )

    rational = string([["1/(1 + z)", 0], [0, "1 + z**2"]])
    assert rational.H[0, 0] == 1 / (1 + Z)
    assert any("exact on [a, b]" in check for check in rational.checks)
    transcendental = string([["2 + sin(z)", 0], [0, "exp(z)"]])
    assert any("grid of 2001 points" in check for check in transcendental.checks)


def test_with_parameters_revalidates_and_refuses_unknown_names():
    beam = load_builtin("euler-bernoulli")
    assert beam.with_parameters({"d": "0.5"}).parameter_defaults[
        sympy.Symbol("d", real=True)
    ] == sympy.Rational(1, 2)
    with pytest.raises(
        ParameterError, match="unknown parameter 'k'; the model's parameters are rho, EI, d"
    ):
        beam.with_parameters({"k": 1})
    with pytest.raises(ParameterError, match="finite number"):
        beam.with_parameters({"d": float("nan")})
    with pytest.raises(ModelError, match="negative semidefinite"):
        beam.with_parameters({"d": -1})
