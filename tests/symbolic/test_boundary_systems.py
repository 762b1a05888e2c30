"""Boundary systems (issue 26): the model, its exact checks, the model file and ``show``."""

from __future__ import annotations

import pytest
import sympy

from phdesign.cli import main
from phdesign.core.errors import ModelError
from phdesign.io import model_from_toml, model_to_toml
from phdesign.models import builtin_toml, load_builtin
from phdesign.symbolic.boundary_systems import coupling
from phdesign.symbolic.expressions import parameter_symbol
from phdesign.symbolic.model import BCPHS

COUPLED = ("string-tip-mass", "beam-tip-body", "flexible-arm", "string-motor")


def string_with(**system):
    """The unit string with velocity ports at both ends and one boundary system."""
    return BCPHS.define(
        name="string",
        interval=(0, 1),
        order=1,
        P={1: [[0, 1], [1, 0]]},
        H=[["1/rho", 0], [0, "T"]],
        parameters={"rho": 1, "T": 1, "m": 2, "c": "1/2", "k": 3},
        inputs=["e1(0)", "e1(1)"],
        outputs=["-e2(0)", "e2(1)"],
        boundary_systems=[system],
    )


MASS = {"name": "mass", "ports": [2], "J": [[0]], "R": [["c"]], "Q": [["1/m"]], "G": [[-1]]}


@pytest.mark.parametrize("name", COUPLED)
def test_builtin_coupled_models_round_trip_and_keep_their_parameter_names(name):
    model = load_builtin(name)
    assert model_from_toml(model_to_toml(model)) == model
    assert model_from_toml(builtin_toml(name)) == model
    assert any("energy identity" in c and c.endswith("exact") for c in model.checks)
    assert set(model.unit_map) >= set(model.parameter_names)


def test_fixed_parameter_names_of_the_issue():
    assert load_builtin("string-tip-mass").parameter_names == ("rho", "T", "m", "c")
    assert load_builtin("beam-tip-body").parameter_names == ("rho", "EI", "d", "M", "J", "c")


def test_gyrator_coupling_solved_exactly():
    # Gyrator S = [[0, -I], [I, 0]]: u_p = -y_c = -(G^T e_c + D u_c), u_c = y_p, so
    # u_p = -D y_p - G^T e_c: K = D, F = -G^T, and the boundary system sees G y_p.
    model = string_with(**MASS, D=[["k"]])
    c = coupling(model.boundary_systems[0])
    k = parameter_symbol("k")
    assert sympy.ImmutableMatrix([[k]]) == c.K
    assert c.to_pde == sympy.ImmutableMatrix([[1]])
    assert c.from_pde == sympy.ImmutableMatrix([[-1]])
    assert model.n_ports == 1
    assert [str(u) for u in model.external_inputs] == ["e1(a)"]


def test_general_skew_interconnection_and_its_static_part():
    # S = [[s, -1], [1, 0]] (s = 0 is the gyrator): u_p = s y_p - y_c, so K = -s + D
    # (hand-solved: u_p = s y_p - (G^T e_c + D y_p)); S skew needs s = 0 on the diagonal.
    with pytest.raises(ModelError, match=r"interconnection must be skew.*S \+ S\^T = \[\[2, 0\]"):
        string_with(**MASS, interconnection=[[1, -1], [1, 0]])
    model = string_with(**MASS, interconnection=[[0, -2], [2, 0]])
    c = coupling(model.boundary_systems[0])
    assert c.to_pde == sympy.ImmutableMatrix([[2]])
    assert c.from_pde == sympy.ImmutableMatrix([[-2]])


def test_feedthrough_with_an_algebraic_loop_is_refused():
    # S_cc != 0 feeds y_c = G^T e_c + D u_c back into u_c: u_c = ... + S_cc D u_c
    loop = [[0, 0, -1, 0], [0, 0, 0, -1], [1, 0, 0, 1], [0, 1, -1, 0]]
    system = {"name": "m", "ports": [1, 2], "J": [[0]], "R": [[0]], "Q": [[1]], "G": [[1, 1]]}
    with pytest.raises(ModelError, match=r"'m': a feedthrough D .* algebraic loop"):
        string_with(**system, D=[[1, 0], [0, 1]], interconnection=loop)
    # without D the same S is fine: G S_cc G^T = 0 here (one state), J_eff = J
    assert coupling(string_with(**system, interconnection=loop).boundary_systems[0]).J_eff == (
        sympy.ImmutableMatrix([[0]])
    )


def test_the_energy_identity_is_stated_and_checked():
    model = load_builtin("beam-tip-body")
    text = str(model)
    assert (
        "boundary system body: x_c = (body momentum, body angular momentum) joined to u3, u4"
        in text
    )
    assert (
        "dH_tot/dt = d/dt (H + H_body) = 1/2 int e^T (P0 + P0^T) e dz - e_c^T R_c e_c (body)"
        in text
    )
    assert "check: boundary system 'body' energy identity" in text


def test_show_prints_the_boundary_system_and_writes_it_back(capsys, tmp_path):
    assert main(["show", "string-tip-mass"]) == 0
    out = capsys.readouterr().out
    assert "boundary system mass: x_c = (mass momentum) joined to u2" in out
    assert "external inputs -> outputs: force -> mass velocity" in out
    assert main(["show", "string-tip-mass", "--toml"]) == 0
    text = capsys.readouterr().out
    assert "[[boundary_systems]]" in text
    assert model_from_toml(text) == load_builtin("string-tip-mass")


def test_boundary_system_labels_must_be_distinct():
    with pytest.raises(ModelError, match=r"the labels momentum are used twice"):
        BCPHS.define(
            name="s",
            interval=(0, 1),
            order=1,
            P={1: [[0, 1], [1, 0]]},
            H=[[1, 0], [0, 1]],
            inputs=["e1(0)", "e1(1)"],
            outputs=["-e2(0)", "e2(1)"],
            state_names=["momentum", "strain"],
            boundary_systems=[{**MASS, "R": [[1]], "Q": [[1]], "states": ["momentum"]}],
        )
