"""[disturbances] and [performance]: reading, the energy identity with eᵀBw, round trips."""

from __future__ import annotations

import pytest
import sympy
from bad_inputs import beam_with

from phdesign.cli import main
from phdesign.core.errors import ExpressionError, ModelError
from phdesign.io import model_from_dict, model_from_toml, model_to_toml
from phdesign.models import load_builtin
from phdesign.symbolic.disturbances import Disturbances, power_balance
from phdesign.symbolic.expressions import Z
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.performance import parse_performance_output
from phdesign.symbolic.traces import trace_symbol

rho = sympy.Symbol("rho", real=True)


def damped_wave(**extra):
    """The string of PIETOOLS' damped-tip example: u(0) = 0, u_z(1) = -k u_t(1)."""
    return BCPHS.define(
        name="damped-tip wave",
        interval=(0, 1),
        order=1,
        P={1: [[0, 1], [1, 0]]},
        H=[["1/rho", 0], [0, "T"]],
        parameters={"rho": 1, "T": 1, "k": 0.5},
        inputs=["e1(0)", "e2(1)"],
        feedback={"inputs": [2], "gain": [["k"]]},
        **extra,
    )


def beam_file(**changes):
    return beam_with(
        disturbances={"B": [["sin(pi*z)"], ["z**2/d"]]},
        ports__unknown=[3],
        performance={"outputs": ["w(1)", "integral(z*x2)", "e2'(0)", "integral(e1/2) - d*e1(1)"]},
        **changes,
    )


def test_performance_outputs_are_read_exactly():
    # each weight is read off the text: integral(z*e2) is ∫ z e2 dz, i.e. c = (0, z)
    out = parse_performance_output(
        "integral(z*e2) - 3*integral(rho*x1/2) + 2*e2(0) - e1(1)",
        (0, 1),
        1,
        2,
        ["rho"],
    )
    assert out.effort_weights == (0, Z)
    assert out.state_weights == (-3 * rho / 2, 0)
    assert sympy.expand(out.traces - (2 * trace_symbol(2, 0, "a") - trace_symbol(1, 0, "b"))) == 0
    assert out.points == ()
    beam = load_builtin("euler-bernoulli")
    tip = parse_performance_output(
        "w(1) + integral(e1)", beam.interval, 2, 2, ["d"], fields=("w",)
    )
    assert tip.points == (("w", 1, 1),)
    assert tip.effort_weights == (1, 0)
    slope = parse_performance_output("e2'(0)", beam.interval, 2, 2)
    assert slope.traces == trace_symbol(2, 1, "a")
    assert not slope.has_integral


def test_define_holds_disturbances_and_performance():
    wave = damped_wave(
        disturbances={"B": [[1], [0]], "unknown": [1]}, performance=["integral(e1)", "e1(1)"]
    )
    assert wave.disturbances == Disturbances(sympy.ImmutableMatrix([[1], [0]]), (1,))
    assert [p.text for p in wave.performance] == ["integral(e1)", "e1(1)"]
    text = str(wave)
    assert "disturbances: dx/dt = ... + B w, w in R^1, B = [[1], [0]]" in text
    assert "performance z1 = integral(e1)" in text
    # the input closed by the damper cannot be a disturbance: it is not an external input
    with pytest.raises(ModelError, match=r"ports.unknown\[1\] = 2 is closed by \[feedback\]"):
        damped_wave(disturbances={"unknown": [2]})
    with pytest.raises(ExpressionError, match="the model defines no displacement"):
        damped_wave(performance=["w(1)"])


def test_round_trip_through_toml_is_exact():
    model = model_from_dict(beam_file())
    again = model_from_toml(model_to_toml(model))
    assert again == model
    assert (
        sympy.ImmutableMatrix([[sympy.sin(sympy.pi * Z)], [Z**2 / sympy.Symbol("d", real=True)]])
        == again.disturbances.B
    )
    assert again.disturbances.unknown == (3,)
    assert [p.text for p in again.performance] == [p.text for p in model.performance]
    # a model without the sections writes none of them
    assert "[disturbances]" not in model_to_toml(load_builtin("wave"))


def generic_efforts(order: int, size: int):
    """Efforts of degree 2N with symbolic coefficients: independent traces at both ends."""
    return [
        sum(sympy.Symbol(f"c{i}_{m}") * Z**m for m in range(2 * order + 1)) for i in range(size)
    ]


@pytest.mark.parametrize(
    ("model", "B"),
    [
        ("wave", [[1], ["z"]]),  # inputs at both ends
        ("euler-bernoulli", [["1 + z**3", 1], ["z**2/2", 0]]),  # P0 = -d: dissipation
        ("timoshenko", [[0], [1], [0], ["z"]]),
    ],
)
def test_energy_identity_gains_the_disturbance_power_exactly(model, B):
    """∫ eᵀ ∂t x dz = ½∫eᵀ(P0 + P0ᵀ)e dz + uᵀy + ∫ eᵀ B w dz (module docstring).

    For efforts of degree 2N with symbolic coefficients (every trace independent) and
    symbolic disturbance values w, the two sides agree exactly: integration by parts of
    DESIGN.md with the supplied power ∫ eᵀBw on both sides.
    """
    base = load_builtin(model)
    q = len(B[0])
    with_b = BCPHS.define(
        name=base.name,
        interval=base.interval,
        order=base.order,
        P=dict(enumerate(base.P)),
        H=base.H,
        parameters={str(s): v for s, v in base.parameters},
        inputs=base.inputs,
        outputs=base.outputs,
        disturbances={"B": B},
    )
    w = sympy.symbols(f"w1:{q + 1}", real=True)
    rate, balance = power_balance(with_b, generic_efforts(base.order, base.size), w)
    assert sympy.expand(rate - balance) == 0
    # and the supplied power is really there: without it the balance misses ∫ eᵀ B w
    _, bare = power_balance(base, generic_efforts(base.order, base.size), w)
    assert sympy.expand(rate - bare) != 0


def test_show_prints_the_sections(tmp_path, capsys):
    path = tmp_path / "beam.toml"
    path.write_text(model_to_toml(model_from_dict(beam_file())))
    assert main(["show", str(path)]) == 0
    out = capsys.readouterr().out
    assert "disturbances: dx/dt = ... + B w, w in R^1, B = [[sin(pi*z)], [z**2/d]]" in out
    assert "unknown inputs (boundary disturbances): u3" in out
    assert "performance z4 = integral(e1/2) - d*e1(1)" in out
