"""Observer layer: sensors, gains, error boundary condition and admissible traces K."""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from phdesign.cli.design_arguments import parse_gain_text, parse_rows_text, parse_sensors_text
from phdesign.core.errors import ObserverError, PhdesignError
from phdesign.models import load_builtin
from phdesign.symbolic.expressions import vanishes
from phdesign.symbolic.observer import (
    ObserverDesign,
    error_system,
    gain_matrix,
    gain_symbols,
    measurement_matrix,
    port_matrices,
    sensor_matrix,
)
from phdesign.symbolic.ports import trace_index
from phdesign.symbolic.ports import trace_index as ports_trace_index


@pytest.fixture(scope="module")
def beam():
    return load_builtin("euler-bernoulli")


def test_trace_index_agrees_with_ports_layer():
    # the ordering is fixed by the API contract; both layers must use the same one
    for N, n in [(1, 2), (2, 2), (3, 1), (2, 3)]:
        for side in "ab":
            for k in range(N):
                for i in range(1, n + 1):
                    assert trace_index(i, k, side, N, n) == ports_trace_index(i, k, side, N, n)


def test_sensor_matrix_picks_unit_rows():
    C = sensor_matrix([2, 4], 4)
    assert sympy.Matrix([[0, 1, 0, 0], [0, 0, 0, 1]]) == C
    assert sensor_matrix(parse_sensors_text(" 2, 4"), 4) == C  # the CLI's --sensors text
    assert sensor_matrix(np.array([2, 4]), 4) == C  # numpy integers are indices too
    assert sensor_matrix(3, 4) == sensor_matrix([3], 4)  # one sensor


def test_gain_matrix_forms():
    assert gain_matrix([0.1, 1], 2) == sympy.diag(sympy.Rational(1, 10), 1)  # exact decimal
    assert gain_matrix(2, 3) == sympy.diag(2, 2, 2)  # one value reused per sensor
    assert gain_matrix(["1/3"], 1) == sympy.Matrix([[sympy.Rational(1, 3)]])  # text numbers
    assert gain_matrix([[1, 0.5], [0, 1]], 2) == sympy.Matrix([[1, sympy.Rational(1, 2)], [0, 1]])
    assert gain_matrix(np.array([0.5, 2.0]), 2) == sympy.diag(sympy.Rational(1, 2), 2)
    assert gain_matrix(np.eye(2), 2) == sympy.eye(2)
    L = gain_matrix("symbolic", 2)
    assert sympy.diag(*gain_symbols(2)) == L
    assert all(s.is_positive for s in gain_symbols(2))
    # the command line's text reads into the same forms
    assert gain_matrix(parse_gain_text("0.1,1"), 2) == gain_matrix([0.1, 1], 2)
    assert gain_matrix(parse_gain_text("[[1, 0.5], [0, 1]]"), 2) == gain_matrix(
        [[1, 0.5], [0, 1]], 2
    )


def test_measurement_matrix_exact():
    assert measurement_matrix([[0, 0, 1, 0], [0, 0, 0.5, 1]], 4) == sympy.Matrix(
        [[0, 0, 1, 0], [0, 0, sympy.Rational(1, 2), 1]]
    )
    assert measurement_matrix(parse_rows_text("[[0, 1]]", "--cm"), 2) == sympy.Matrix([[0, 1]])


# (callable, args, regex): every path of the sensor/gain checks
BAD_INPUTS = [
    (sensor_matrix, ([5], 4), r"output index 5 is out of range; expected 1\.\.4"),
    (sensor_matrix, ([0], 4), r"output index 0 is out of range"),
    (sensor_matrix, ([3, 3], 4), r"output index 3 is repeated"),
    (sensor_matrix, ([], 4), r"expected at least one output index"),
    (sensor_matrix, ("3,4", 4), r"sensors: expected a list of output indices.*the text '3,4'"),
    (sensor_matrix, ([3.0], 4), r"sensors: expected integer output indices; found 3.0"),
    (parse_sensors_text, ("3,x",), r"expected comma-separated output indices.*'x'"),
    (parse_rows_text, ("[[1,0]", "--cm"), r"--cm: expected a JSON list of rows"),
    (measurement_matrix, ([[1, 0, 0]], 2), r"C_m matrix; expected \(q, 2\).* but found \(1, 3\)"),
    (measurement_matrix, ([[1, 0], [1]], 2), r"row 2 has 1 entries; expected 2"),
    (measurement_matrix, ([[float("nan"), 0]], 2), r"finite number; found nan"),
    (measurement_matrix, ("[[0, 1]]", 2), r"C_m: expected a matrix .*found str"),
    (measurement_matrix, ([[0, 0]], 2), r"full row rank.*expected rank 1 but found 0"),
    (gain_matrix, ([1, 2, 3], 2), r"expected 2 diagonal values \(one per sensor\).* found 3"),
    (gain_matrix, (["nan"], 2), r"entry 1 must be a finite positive number; found 'nan'"),
    (gain_matrix, ([[1, 0], [0, 1], [0, 0]], 2), r"L matrix; expected \(2, 2\).*found \(3, 2\)"),
    (gain_matrix, ("0.1,1", 2), r"gain: .*found the text '0.1,1' \(write gain=\[0.1, 1\]"),
    (gain_matrix, ([1], 0), r"q \(the number of sensors\) must be a positive integer; found 0"),
    (gain_matrix, ({"l": 1}, 1), r"gain: expected a number, a list of numbers, a matrix"),
    (parse_rows_text, ("[[1,0]", "--gain"), r"--gain: expected a JSON list of rows"),
]


@pytest.mark.parametrize(("function", "args", "message"), BAD_INPUTS)
def test_bad_sensor_and_gain_input(function, args, message):
    with pytest.raises(ObserverError, match=message):
        function(*args)


BAD_DESIGNS = [
    # (C_m, L, regex)
    (
        sympy.Matrix([[1, 0, 0, 0], [2, 0, 0, 0]]),
        sympy.eye(2),
        r"full row rank.*expected rank 2 but found 1",
    ),
    (
        sympy.Matrix([[1, 0, 0]]),
        sympy.eye(1),
        r"C_m matrix; expected \(q, 4\).* but found \(1, 3\)",
    ),
    # no sensors ([] or a (0, 4) C_m) is the plant's own classification (issue 16; since
    # issue 28 also [], tests/design/test_observer_no_sensors.py) and takes no gain
    ([], sympy.eye(1), r"gain: no sensors \(C_m has no rows\) take no gain"),
    (np.zeros((0, 3)), sympy.eye(0), r"expected \(0, 4\) for no sensors but found \(0, 3\)"),
    (sympy.zeros(5, 4), sympy.eye(5), r"1 <= q <= 4"),
    (sensor_matrix([3, 4], 4), sympy.eye(3), r"L matrix; expected \(2, 2\).* but found \(3, 3\)"),
    (sensor_matrix([3, 4], 4), sympy.diag(1, -1), r"positive definite.*minor 2 = -4"),
    # L + L^T = [[2, 3], [3, 2]] is indefinite although the diagonal is positive
    (sensor_matrix([3, 4], 4), sympy.Matrix([[1, 3], [0, 1]]), r"minor 2 = -5"),
    (sensor_matrix([3, 4], 4), sympy.Matrix([[1, 0], [0, float("nan")]]), r"finite"),
    (
        sensor_matrix([3, 4], 4),
        sympy.Matrix([[sympy.Symbol("k"), 0], [0, 1]]),
        r"symbolic L must be diagonal with positive entries",
    ),
    (
        np.array([[0.0, 0.0, 1.0, 0.0]]),
        np.array([[np.inf]]),
        r"L\[1\]\[1\] must be a finite number; found inf",
    ),
]


@pytest.mark.parametrize(("C_m", "L", "message"), BAD_DESIGNS)
def test_bad_designs(beam, C_m, L, message):
    with pytest.raises(ObserverError, match=message) as info:
        ObserverDesign(beam, C_m, L)
    assert isinstance(info.value, PhdesignError)
    assert isinstance(info.value, ValueError)


def test_numpy_inputs_are_read_exactly(beam):
    design = ObserverDesign(beam, np.array([[0, 0, 1, 0]]), np.array([[0.1]]))
    assert sympy.Matrix([[sympy.Rational(1, 10)]]) == design.L


def test_beam_error_boundary_condition(beam):
    # Paper §IV-D with L = diag(l1, l2): the error inputs are
    # ũ = -C_mᵀ L C_m ỹ = (0, 0, -l1 ỹ3, -l2 ỹ4) with ỹ3 = e1'(1), ỹ4 = -e1(1):
    # e1(0) = 0, e1'(0) = 0, e2(1) = -l1 e1'(1), e2'(1) = l2 e1(1).
    l1, l2 = gain_symbols(2)
    es = ObserverDesign(beam, sensor_matrix([3, 4], 4), gain_matrix("symbolic", 2)).error_system()
    v = sympy.Matrix(sympy.symbols("v0:8"))
    idx = {
        name: trace_index(i, k, s, 2, 2)
        for name, (i, k, s) in {
            "e1(1)": (1, 0, "b"),
            "e2(1)": (2, 0, "b"),
            "e1'(1)": (1, 1, "b"),
            "e2'(1)": (2, 1, "b"),
            "e1(0)": (1, 0, "a"),
            "e1'(0)": (1, 1, "a"),
        }.items()
    }
    expected = [
        v[idx["e1(0)"]],
        v[idx["e1'(0)"]],
        v[idx["e2(1)"]] + l1 * v[idx["e1'(1)"]],
        v[idx["e2'(1)"]] - l2 * v[idx["e1(1)"]],
    ]
    got = es.boundary_matrix * v
    assert all(sympy.expand(g - e) == 0 for g, e in zip(got, expected, strict=True))


@pytest.mark.parametrize("name", ["wave", "timoshenko", "euler-bernoulli", "airy"])
def test_admissible_traces_have_dimension_Nn(name):
    model = load_builtin(name)
    nn = model.order * model.size
    es = ObserverDesign(model, sensor_matrix([1], nn), gain_matrix("3/2", 1)).error_system()
    assert es.K.shape == (2 * nn, nn)
    assert es.K.rank() == nn  # dim K = Nn
    assert all(vanishes(x) for x in es.boundary_matrix * es.K)  # K solves the error BC
    # Y K = I: the basis is parametrized by the error output ỹ
    assert sympy.eye(nn) == es.Y * es.K


def test_port_matrices_substitute_parameters(beam):
    U, Y = port_matrices(beam)
    assert not U.free_symbols
    assert not Y.free_symbols
    assert error_system(2, 2, U, Y, sensor_matrix([4], 4), sympy.eye(1)).K.shape == (8, 4)


def test_singular_port_stack_is_an_observer_error():
    # U = Y: each alone has full rank, but (U; Y) is singular (not power conjugates)
    U = sympy.Matrix([[1, 0, 0, 0], [0, 1, 0, 0]])
    with pytest.raises(ObserverError, match=r"\(U; Y\) is singular.*dimension Nn = 2"):
        error_system(1, 2, U, U, sensor_matrix([1], 2), sympy.eye(1))
