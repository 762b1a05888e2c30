"""Fields of a model (`[displacement]`, `[fields.<name>]`): reading, checking, writing.

Expected values: the Timoshenko derivation of ``phdesign.symbolic.fields`` redone here
with sympy on arbitrary w(z, t), φ(z, t); messages as the module words them.
"""

from __future__ import annotations

import pytest
import sympy

import phdesign as phd
from phdesign.core.errors import ModelError, ModelFileError
from phdesign.io import model_from_dict, model_from_toml, model_to_dict, model_to_toml
from phdesign.symbolic.fields import Displacement, Field, Term


def test_the_short_form_is_a_one_term_field() -> None:
    assert Displacement(component=2, integrations=2) == Field(terms=(Term(2, 2),))
    beam = phd.load("euler-bernoulli")
    assert beam.displacement == Displacement(2, 2)
    assert beam.displacement.component == 2
    assert beam.displacement.integrations == 2
    assert model_to_dict(beam)["displacement"] == {"component": 2, "integrations": 2}


def test_timoshenko_fields_read_back_exactly() -> None:
    timo = phd.load("timoshenko")
    assert timo.displacement == Field(terms=(Term(1, 1), Term(3, 2)))
    assert dict(timo.fields) == {"rotation": Field(terms=(Term(3, 1),))}
    assert model_from_toml(model_to_toml(timo)) == timo


def test_timoshenko_derivation_exactly() -> None:
    r"""x = (w_z - φ, ρ w_t, φ_z, I_ρ φ_t) solves ∂t x = P1 ∂z(Hx) + P0 Hx iff Timoshenko.

    Rows 1 and 3 hold identically (compatibility); rows 2 and 4 are ρ w_tt =
    ∂z(K(w_z - φ)) and I_ρ φ_tt = ∂z(EI φ_z) + K(w_z - φ).  And the fields read back w
    and φ: ∂z(∫x1 + ∫∫x3) = x1 + ∫x3 = w_z when φ(0) = 0, ∂z ∫x3 = φ_z.
    """
    z, t, s = sympy.symbols("z t s")
    K, rho, EI, Ir = sympy.symbols("K rho EI I_rho", positive=True)
    w, phi = sympy.Function("w")(z, t), sympy.Function("phi")(z, t)
    timo = phd.load("timoshenko")
    values = {
        sym: {"K": K, "rho": rho, "EI": EI, "I_rho": Ir}[sym.name] for sym, _ in timo.parameters
    }
    x = sympy.Matrix([w.diff(z) - phi, rho * w.diff(t), phi.diff(z), Ir * phi.diff(t)])
    e = timo.H.xreplace(values) * x
    residual = x.diff(t) - timo.P[1] * e.diff(z) - timo.P[0] * e
    assert sympy.simplify(residual[0]) == 0
    assert sympy.simplify(residual[2]) == 0
    assert (
        sympy.simplify(residual[1] - (rho * w.diff(t, 2) - (K * (w.diff(z) - phi)).diff(z))) == 0
    )
    eom4 = Ir * phi.diff(t, 2) - (EI * phi.diff(z)).diff(z) - K * (w.diff(z) - phi)
    assert sympy.simplify(residual[3] - eom4) == 0
    # the fields on a clamped beam: take w(0) = φ(0) = 0 and check w and φ come back
    wz, fz = sympy.sin(z) * z, z**2 * sympy.exp(z)  # w(z) and φ(z) with w(0) = φ(0) = 0
    x1, x3 = wz.diff(z) - fz, fz.diff(z)
    rotation = sympy.integrate(x3.subs(z, s), (s, 0, z))
    inner = sympy.integrate(x3.subs(z, s), (s, 0, z))
    deflection = sympy.integrate((x1 + inner).subs(z, s), (s, 0, z))
    assert sympy.simplify(rotation - fz) == 0
    assert sympy.simplify(deflection - wz) == 0


def _timoshenko(**changes: object) -> dict:
    data = model_to_dict(phd.load("timoshenko"))
    data.update(changes)
    return data


@pytest.mark.parametrize(
    ("changes", "exc", "match"),
    [
        (
            {
                "displacement": {
                    "terms": [
                        {"component": 1, "integrations": 2},
                        {"component": 3, "integrations": 2},
                    ]
                }
            },
            ModelError,
            r"displacement: the terms' units disagree: expected m\*\*2 "
            r"\(x1 integrated 2 times\), found m for x3",
        ),
        (
            {"displacement": {"component": 1, "integrations": 2}},
            ModelError,
            r"displacement: units.displacement = 'm': expected its terms in m, found m\*\*2",
        ),
        (
            {"displacement": {"terms": []}},
            ModelFileError,
            r"\[displacement\] terms must be a non-empty list",
        ),
        (
            {"displacement": {"terms": [{"component": 5}]}},
            ModelError,
            r"displacement must name a component in 1..4",
        ),
        (
            {"displacement": {"terms": [{"component": 1, "integrations": 1, "coefficient": "z"}]}},
            ModelFileError,
            "coefficient: the spatial variable z is not allowed",
        ),
        (
            {"displacement": {"terms": [{"component": 1, "power": 1}]}},
            ModelFileError,
            r"\[displacement.terms\[1\]\] must hold component",
        ),
        (
            {"displacement": {"component": 1, "integrations": 1, "start": "c"}},
            ModelFileError,
            "optionally start = 'a' or 'b'",
        ),
        (
            {"displacement": {"component": 1, "integrations": 1, "terms": []}},
            ModelFileError,
            "give the terms only",
        ),
        (
            {
                "fields": {
                    "rotation": {"component": 3, "integrations": 1},
                    "e1": {"component": 1, "integrations": 0},
                }
            },
            ModelError,
            "the name 'e1' is taken",
        ),
        (
            {"fields": {"rotation": {"component": 3, "integrations": 2}}},
            ModelError,
            r"rotation: units.rotation = 'rad': expected its terms in 1, found m",
        ),
        ({"fields": {"rotation": 3}}, ModelFileError, "fields.rotation must be a table"),
    ],
)
def test_bad_fields_are_refused_naming_the_key(changes: dict, exc: type, match: str) -> None:
    with pytest.raises(exc, match=match):
        model_from_dict(_timoshenko(**changes))
