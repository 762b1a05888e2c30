r"""The dimension of a unit label, exactly, for checking that a field's terms agree.

Units are labels (:mod:`phdesign.symbolic.units`); a label made of unit names, integer
powers and ``*``, ``/``, ``·`` (``"kg*m/s^2"``, ``"N*m²"``, ``"1/m"``, ``"1"``) also has a
dimension: a product of powers of symbols, with the SI derived units N, J, W and Pa
written in the base units kg, m, s (and rad as 1), so that ``"N"`` and ``"kg*m/s^2"`` are the same.
A label phdesign cannot read that way (parentheses, a prefix it does not know such as
``"µm"`` beside ``"m"``) has no dimension here, and nothing is claimed about it.

Examples
--------
>>> dimension("N*m^2") == dimension("kg*m^3/s^2")
True
>>> dimension("1/m") * dimension("m") == 1
True
>>> dimension("(m)") is None
True
"""

from __future__ import annotations

import re
from collections.abc import Mapping

import sympy

__all__ = ["dimension", "term_dimension"]

_FACTOR = re.compile(
    r"\s*(?P<op>[*/·])?\s*(?P<name>[^\W\d_]+|1)(?:\^(?P<exp>-?\d+)|(?P<sup>[²³]))?"
)
_SUPERSCRIPT = {"²": 2, "³": 3}
_SI = {
    "N": "kg*m/s^2",
    "J": "kg*m^2/s^2",
    "W": "kg*m^2/s^3",
    "Pa": "kg/m/s^2",
    "rad": "1",
}


def dimension(text: str | None) -> sympy.Expr | None:
    """Return the dimension of a unit label, or ``None`` when it cannot be read.

    Factors are read left to right: ``a/b*c`` is ``a c / b`` as in the usual writing of
    units (``"kg/m/s^2"`` is kg m⁻¹ s⁻²).
    """
    if text is None:
        return None
    out: sympy.Expr = sympy.Integer(1)
    position, first = 0, True
    text = text.strip()
    while position < len(text):
        match = _FACTOR.match(text, position)
        if match is None or (first and match.group("op")) or (not first and not match.group("op")):
            return None
        name = match.group("name")
        power = int(match.group("exp") or _SUPERSCRIPT.get(match.group("sup") or "", 1))
        if match.group("op") == "/":
            power = -power
        base = sympy.Integer(1) if name == "1" else _base(name)
        out *= base**power
        position, first = match.end(), False
    return out


def _base(name: str) -> sympy.Expr:
    derived = _SI.get(name)
    if derived is not None:
        return dimension(derived)  # type: ignore[return-value,unused-ignore]
    return sympy.Symbol(name, positive=True)


def term_dimension(
    state_unit: str | None,
    z_unit: str | None,
    integrations: int,
    coefficient: sympy.Expr,
    units: Mapping[str, str],
) -> sympy.Expr | None:
    r"""Dimension of :math:`c\,\mathcal I^{k} x_i`: unit(x_i) · unit(z)^k · unit(c).

    ``None`` when a unit it needs is not stated or not readable: the coefficient's is
    known when it is a number, or a product of powers of parameters with stated units.
    """
    state = dimension(state_unit)
    z = dimension(z_unit) if integrations else sympy.Integer(1)
    c = _coefficient_dimension(coefficient, units)
    if state is None or z is None or c is None:
        return None
    return sympy.powsimp(state * z**integrations * c)


def _coefficient_dimension(c: sympy.Expr, units: Mapping[str, str]) -> sympy.Expr | None:
    if c.is_number:
        return sympy.Integer(1)
    out: sympy.Expr = sympy.Integer(1)
    for base, power in c.as_powers_dict().items():
        if base.is_number:
            continue
        if not (isinstance(base, sympy.Symbol) and power.is_Integer):
            return None
        unit = dimension(units.get(base.name))
        if unit is None:
            return None
        out *= unit**power
    return out
