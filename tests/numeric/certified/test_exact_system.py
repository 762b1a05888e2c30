"""The exact closed system: the boundary rows and gains the certificates start from.

Every expected matrix is derived by hand from the ports of the contract (DESIGN.md):
v = (φ(b); φ(a)), for the string φ = (e1, e2), inputs u = (e1(0), e2(1)),
outputs y = (-e2(0), e1(1)); so u = U v with U = [[0,0,1,0],[0,1,0,0]] and
Y = [[0,0,0,-1],[1,0,0,0]].
"""

from __future__ import annotations

import pytest
import sympy
from string_models import GRADED_STRING, string

from phdesign.core.errors import ObserverError, ParameterError
from phdesign.models import load_builtin
from phdesign.numeric.certified.exact_system import closed_system
from phdesign.symbolic.model import BCPHS

R = sympy.Rational


def test_string_with_the_observer_damper_is_the_damped_string():
    # sensor y2 = e1(1), gain k: ũ = -C_mᵀ k C_m ỹ gives ũ1 = e1(0) = 0 and
    # ũ2 = e2(1) = -k e1(1): rows (0,0,1,0) and (k,1,0,0).
    system = closed_system(load_builtin("wave"), [[0, 1]], [R(1, 2)])
    assert system.kind == "error"
    assert system.boundary == sympy.Matrix([[0, 0, 1, 0], [R(1, 2), 1, 0, 0]])
    assert sympy.Matrix([[0, 0], [0, R(1, 2)]]) == system.G
    assert system.interval == (0, 1)
    assert system.length == 1
    assert system.constant
    assert system.rational


def test_plant_dampers_are_part_of_the_plant_and_of_the_error_system():
    # wave-damper closes u2 = -k y2 with k = 1/2: the plant alone is the damped string;
    # measuring its remaining output y1 = -e2(0) with gain 3 adds ũ1 = e1(0) = 3·(-e2(0))·(-1)
    # i.e. G = diag(3, 1/2) over the open ports (the external port is the first).
    plant = closed_system(load_builtin("wave-damper"))
    assert plant.kind == "plant"
    assert plant.C_m is None
    assert plant.boundary == sympy.Matrix([[0, 0, 1, 0], [R(1, 2), 1, 0, 0]])
    err = closed_system(load_builtin("wave-damper"), [[1]], [3])
    assert sympy.Matrix([[3, 0], [0, R(1, 2)]]) == err.G
    # row 1: e1(0) + 3·(-e2(0)) = 0
    assert err.boundary.row(0) == sympy.Matrix([[0, 0, 1, -3]])


def test_floats_become_the_rationals_of_their_decimal_text():
    # the beam's d = 0.2 in its file is 1/5; an override d = 0.3 is 3/10; the gain 0.1 is 1/10
    system = closed_system(
        load_builtin("euler-bernoulli"),
        [[0, 0, 1, 0], [0, 0, 0, 1]],
        [0.1, 1],
        parameters={"d": 0.3},
    )
    assert system.P[0] == sympy.Matrix([[-R(3, 10), 0], [0, 0]])
    assert sympy.diag(R(1, 10), 1) == system.L
    assert closed_system(load_builtin("euler-bernoulli")).P[0][0, 0] == -R(1, 5)


def test_dissipation_is_decided_exactly():
    # wave with u = 0: sym(G) = 0 and P0 = 0: conservative (Re λ = 0 for every eigenvalue)
    wave = closed_system(load_builtin("wave")).dissipation()
    assert wave.dissipative
    assert wave.conservative
    # the beam's error system: sym(P0) = diag(-1/5, 0) ⪯ 0 and sym(G) = diag(0,0,1/10,1) ⪰ 0
    beam = closed_system(load_builtin("euler-bernoulli"), [[0, 0, 1, 0]], [R(1, 10)])
    d = beam.dissipation()
    assert d.dissipative
    assert not d.conservative
    assert d.interior == sympy.diag(-R(1, 5), 0)


def test_a_skew_gain_is_conservative_but_not_dissipative_only_if_its_symmetric_part_is_not_psd():
    # L + Lᵀ > 0 is required of the observer, so sym(G) = C_mᵀ sym(L) C_m ⪰ 0 always;
    # a non-symmetric L with a positive symmetric part stays dissipative
    system = closed_system(load_builtin("wave"), [[1, 0], [0, 1]], [[1, 2], [-2, 1]])
    assert system.dissipation().dissipative
    assert system.dissipation().boundary == sympy.eye(2)


def test_z_dependent_coefficients_are_kept_exact_and_flagged():
    model = GRADED_STRING
    system = closed_system(model)
    assert not system.constant
    assert system.H[1, 1] == 1 + system.z


def test_an_irrational_entry_is_exact_but_not_rational():
    # airy's third input (e1'(0) + e1'(1))/sqrt(2) puts sqrt(2)/2 in the boundary rows
    system = closed_system(load_builtin("airy"))
    assert not system.rational
    assert sympy.sqrt(2) / 2 in list(system.boundary)


def test_exact_text_of_the_system():
    d = closed_system(string("2"), [[0, 1]], [1]).to_dict()
    assert d["H"] == [["1", "0"], ["0", "2"]]
    assert d["boundary"] == [["0", "0", "1", "0"], ["1", "1", "0", "0"]]
    assert d["L"] == [["1"]]
    assert d["kind"] == "error"


@pytest.mark.parametrize(
    ("args", "kwargs", "exc", "pattern"),
    [
        ((None, [1]), {}, ObserverError, "a gain L needs sensors C_m"),
        (([[0, 1]], "symbolic"), {}, ObserverError, "needs a numeric gain; found the symbols"),
        (([[0, 1, 0]], [1]), {}, ObserverError, "C_m"),
    ],
)
def test_bad_designs_are_refused(args, kwargs, exc, pattern):
    with pytest.raises(exc, match=pattern):
        closed_system(load_builtin("wave"), *args, **kwargs)


def test_parameters_are_substituted_exactly_and_a_bad_value_is_refused():
    model = BCPHS.define(
        name="free",
        interval=[0, 1],
        order=1,
        P={1: [[0, 1], [1, 0]]},
        H=[[1, 0], [0, "c"]],
        inputs=["e1(0)", "e2(1)"],
        outputs=["-e2(0)", "e1(1)"],
        parameters={"c": 2},
    )
    assert closed_system(model).H[1, 1] == 2
    assert closed_system(model, parameters={"c": 0.25}).H[1, 1] == R(1, 4)
    with pytest.raises(ParameterError, match="parameter c"):
        closed_system(model, parameters={"c": "x"})
