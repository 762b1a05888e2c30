"""Outputs derived from the inputs (outputs = "conjugate").

The derivation's claims (phdesign.symbolic.conjugate): the derived outputs pass the three
identities; any other conjugate outputs differ by y' = y + S u with S skew; the derived
ones have the least Frobenius norm (Y Uᵀ symmetric).  The shipped outputs of every
built-in model have Y Uᵀ = 0, so they must be the derived ones exactly: there is no sign
left to choose, W_C Σ W_Bᵀ = +I fixes it.
"""

from __future__ import annotations

import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from phdesign.core.errors import PortError
from phdesign.io import model_from_toml, model_to_toml
from phdesign.models import builtin_names, load_builtin
from phdesign.symbolic.conjugate import conjugate_outputs
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.ports import coefficient_matrix, derive_ports, q_matrix, trace_vector
from phdesign.symbolic.printing import format_expression


@pytest.mark.parametrize("name", builtin_names())
def test_derived_outputs_of_every_built_in_model_are_the_shipped_ones(name):
    model = load_builtin(name)

    def same(a, b):
        return all(sympy.expand(x - y) == 0 for x, y in zip(a, b, strict=True))

    derived = conjugate_outputs(
        model.P, model.order, model.inputs, model.interval, model.parameter_defaults
    )
    assert same(derived, model.outputs)
    twin = BCPHS.define(
        name=name,
        interval=model.interval,
        order=model.order,
        P=dict(enumerate(model.P)),
        H=model.H,
        parameters={s.name: v for s, v in model.parameters},
        inputs=list(model.inputs),
        outputs="conjugate",
    )
    assert twin.derived_outputs
    assert same(twin.outputs, model.outputs)
    assert all(value == 0 for value in derive_ports(twin).identities.values())


def test_derived_outputs_are_printed_in_the_users_trace_notation():
    beam = BCPHS.define(
        name="beam",
        interval=(0, 2),
        order=2,
        P={2: [[0, -1], [1, 0]]},
        H=[[1, 0], [0, "EI"]],
        parameters={"EI": 2},
        inputs=["e1(0)", "e1'(0)", "e2(2)", "e2'(2)"],
    )
    shown = [format_expression(y, beam.interval) for y in beam.outputs]
    assert shown == ["e2'(0)", "-e2(0)", "e1'(2)", "-e1(2)"]  # the paper's y, eq. (InputBeam)
    assert model_to_toml(beam).count('outputs = "conjugate"') == 1
    assert model_from_toml(model_to_toml(beam)) == beam


@st.composite
def mixed_inputs(draw):
    r"""The wave's inputs mixed by a unimodular M: u = M (e1(0), e2(1)), plus their conjugates.

    y = M⁻ᵀ(-e2(0), e1(1)) + S u with a random skew S: conjugate outputs that are not the
    least-norm ones unless S = 0.
    """
    a, b = draw(st.integers(-2, 2)), draw(st.integers(-2, 2))
    M = sympy.Matrix([[1, a], [0, 1]]) * sympy.Matrix([[1, 0], [b, 1]])
    s = draw(st.integers(-3, 3))
    return M, sympy.Matrix([[0, s], [-s, 0]])


@settings(max_examples=15, deadline=None)
@given(mixed_inputs())
def test_conjugate_outputs_are_unique_up_to_a_skew_feedthrough_and_least_norm(case):
    M, S = case
    interval = (0, 1)
    v = sympy.Matrix(trace_vector(1, 2))
    base_u = sympy.Matrix([v[3], v[1]])  # e1(a), e2(b): the wave's inputs
    base_y = sympy.Matrix([-v[2], v[0]])  # -e2(a), e1(b)
    u = M * base_u
    y_other = M.inv().T * base_y + S * u
    P = [sympy.zeros(2), sympy.Matrix([[0, 1], [1, 0]])]
    derived = sympy.Matrix(conjugate_outputs(P, 1, list(u), interval, {}))
    U = coefficient_matrix(list(u), 1, 2, "u")
    Y = coefficient_matrix(list(derived), 1, 2, "y")
    Y_other = coefficient_matrix(list(y_other), 1, 2, "y")
    # the identities, in trace coordinates: Π = diag(Q, -Q), Y Π⁻¹ Uᵀ = I, Y Π⁻¹ Yᵀ = 0
    Q = q_matrix(P, 1)
    Pi_inv = sympy.diag(Q, -Q).inv()
    assert Y * Pi_inv * U.T == sympy.eye(2)
    assert Y * Pi_inv * Y.T == sympy.zeros(2)
    # the other conjugate outputs differ by a skew feedthrough ...
    D = (Y_other - Y) * U.T * (U * U.T).inv()
    assert (Y_other - Y) == D * U
    assert sympy.zeros(2) == D + D.T
    # ... and the derived ones have Y Uᵀ symmetric, hence the least norm
    assert Y * U.T == (Y * U.T).T
    assert sum(x**2 for x in Y) <= sum(x**2 for x in Y_other)


def test_inadmissible_inputs_are_named_instead_of_blaming_the_outputs():
    """The issue's string with an impedance end: e2(2) + c e1(2) carries power by itself.

    With Q = P1 = [[0, 1], [1, 0]] the power at b is e1 e2, so for u2 = e2 + c e1 the
    entry (2, 2) of W_B Σ W_Bᵀ = U Π⁻¹ Uᵀ is 2c.
    """
    string = {
        "name": "string",
        "interval": (0, 2),
        "order": 1,
        "P": {1: [[0, 1], [1, 0]]},
        "H": [[1, 0], [0, 1]],
        "parameters": {"c": 1},
    }
    for outputs in ("conjugate", ["-e2(0)", "e1(2)"]):
        with pytest.raises(PortError) as info:
            BCPHS.define(**string, inputs=["e1(0)", "e2(2) + c*e1(2)"], outputs=outputs)
        message = str(info.value)
        assert (
            "inputs[2] = c*e1(2) + e2(2) carries power by itself (entry (2, 2) = 2*c)" in message
        )
        assert "[feedback]" in message
        assert "outputs must be" not in message
    with pytest.raises(
        PortError, match=r"inputs\[1\] = e1\(0\) and inputs\[2\] = e2\(0\) exchange"
    ):
        BCPHS.define(**string, inputs=["e1(0)", "e2(0)"])
    with pytest.raises(PortError, match="the inputs are linearly dependent"):
        BCPHS.define(**string, inputs=["e1(0)", "2*e1(0)"])
