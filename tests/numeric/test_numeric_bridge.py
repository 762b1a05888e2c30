"""The bridge from the symbolic model to the numeric layer."""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from numeric_models import BUILTINS, VARYING

from phdesign.core.errors import ModelError, ParameterError, ShapeError
from phdesign.models import load_builtin
from phdesign.numeric.bridge import (
    NumericModel,
    constant_H,
    gain_to_numeric,
    to_numeric,
    trace_index,
)
from phdesign.symbolic.ports import derive_ports


@pytest.mark.parametrize("name", BUILTINS)
def test_builtins_cross_the_bridge_with_the_contract_ordering(name):
    model = load_builtin(name)
    nm = to_numeric(model)
    N, n = model.order, model.size
    assert nm.U.shape == (N * n, 2 * N * n)
    assert nm.Y.shape == nm.U.shape
    ports = derive_ports(model)
    np.testing.assert_allclose(nm.U, np.array(ports.U.subs(model.parameter_defaults), float))
    assert len(nm.P) == N + 1
    assert nm.H_at(np.linspace(0, 1, 5)).shape == (5, n, n)


def test_trace_index_matches_the_symbolic_layer():
    from phdesign.symbolic import ports

    for N, n in ((1, 2), (2, 2), (3, 1), (1, 4)):
        for i in range(1, n + 1):
            for k in range(N):
                for side in "ab":
                    assert trace_index(i, k, side, N, n) == ports.trace_index(i, k, side, N, n)


def test_parameters_are_substituted_and_overridable():
    model = load_builtin("euler-bernoulli")
    assert to_numeric(model).P[0][0, 0] == -0.2  # d = 0.2 (DESIGN.md)
    assert to_numeric(model, {"d": "1/2"}).P[0][0, 0] == -0.5
    nm = to_numeric(model, {"rho": 4})
    np.testing.assert_allclose(nm.H_at(np.array([0.3]))[0], np.diag([0.25, 1.0]))
    with pytest.raises(ParameterError, match="q"):
        to_numeric(model, {"q": 1})


def test_z_dependent_H_is_lambdified():
    nm = to_numeric(VARYING)
    assert not nm.H_constant
    z = np.array([0.0, 0.5, 1.0])
    np.testing.assert_allclose(nm.H_at(z)[:, 0, 0], 1 / (1 + z))
    np.testing.assert_allclose(nm.H_at(z)[:, 1, 1], 2 + np.sin(3 * z))


def test_leftover_symbols_are_refused_with_their_names():
    l1, l2 = sympy.symbols("l1 l2", positive=True)
    with pytest.raises(ParameterError, match="l1, l2"):
        gain_to_numeric(sympy.Matrix([[l1, 0], [0, l2]]))
    np.testing.assert_allclose(gain_to_numeric(sympy.Matrix([[sympy.Rational(1, 10)]])), [[0.1]])


def test_numeric_model_checks_shapes():
    P = (np.zeros((2, 2)), np.eye(2))
    U = np.zeros((2, 4))
    with pytest.raises(ShapeError, match="P1"):
        NumericModel("x", (0, 1), 1, 2, (P[0], np.eye(3)), constant_H(np.eye(2)), U, U)
    with pytest.raises(ShapeError, match="U"):
        NumericModel("x", (0, 1), 1, 2, P, constant_H(np.eye(2)), np.zeros((2, 3)), U)
    with pytest.raises(ModelError, match="a < b"):
        NumericModel("x", (1, 0), 1, 2, P, constant_H(np.eye(2)), U, U)
    with pytest.raises(ModelError, match="expected 2 matrices"):
        NumericModel("x", (0, 1), 1, 2, P[:1], constant_H(np.eye(2)), U, U)
