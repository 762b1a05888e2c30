r"""Physical units a model file states (``[units]``), for plot labels and JSON.

phdesign does no unit algebra: a unit is text that the model's author vouches for.  It
may be given for

* a parameter (``rho = "kg/m"``),
* a state component, by its label or ``x<i>`` (``momentum = "kg/s"``),
* the reserved quantities ``t`` (time), ``z`` (position), ``energy`` (the Hamiltonian
  :math:`H = \tfrac12\int x^\top \mathcal H x\,dz`) and ``displacement`` (the field
  :math:`w` of ``[displacement]``), and each named field of ``[fields.<name>]`` by its
  name (:mod:`phdesign.symbolic.fields`).

A model that states no unit for a quantity gets plain labels ("time t", not "time t [s]"):
phdesign never claims a unit nobody gave.  Unit text is short and plain: letters (any
script, e.g. ``µ``, ``Ω``), digits, spaces and ``. * / ^ ( ) - · ² ³ ⁻ ¹ °``, at most
:data:`MAX_UNIT_LENGTH` characters, so that it prints safely in a terminal, a CSV header
and a matplotlib label (no ``$`` or ``\``: no mathtext).

Examples
--------
>>> check_units({"t": "s", "rho": "kg/m"}, parameters=("rho",), states=("x1", "x2"))
(('t', 's'), ('rho', 'kg/m'))
>>> with_unit("time t", dict([("t", "s")]), "t")
'time t [s]'
>>> with_unit("time t", {}, "t")
'time t'
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

from phdesign.core.errors import ModelError

__all__ = ["MAX_UNIT_LENGTH", "RESERVED_QUANTITIES", "check_units", "with_unit"]

#: Quantities that are not parameters or states but may carry a unit.
RESERVED_QUANTITIES = ("t", "z", "energy", "displacement")
#: Longest unit text accepted.
MAX_UNIT_LENGTH = 32

_UNIT = re.compile(r"[^\W_]|[0-9 .*/^()\-·²³⁻¹°]", re.UNICODE)


def check_units(
    units: Mapping[str, object] | Sequence[tuple[str, object]],
    parameters: Sequence[str],
    states: Sequence[str],
    fields: Sequence[str] = (),
) -> tuple[tuple[str, str], ...]:
    """Validate ``units`` and return them as a tuple of ``(key, unit)`` pairs, in order.

    Raises
    ------
    ModelError
        If a key is not a parameter, a state (label or ``x<i>``), a named field
        (``fields``, from ``[fields.<name>]``) or a reserved quantity,
        names a state twice, or a unit is not short plain text.
    """
    items = list(units.items()) if isinstance(units, Mapping) else list(units)
    known_states = {name: i for i, name in enumerate(states)}
    known_states.update({f"x{i + 1}": i for i in range(len(states))})
    seen_states: dict[int, str] = {}
    out = []
    for key, unit in items:
        if not isinstance(key, str):
            raise ModelError(f"units: key {key!r} must be text")
        if key in known_states:
            state = known_states[key]
            if state in seen_states:
                raise ModelError(
                    f"units: {key!r} and {seen_states[state]!r} name the same state; "
                    "give its unit once"
                )
            seen_states[state] = key
        elif key not in parameters and key not in RESERVED_QUANTITIES and key not in fields:
            expected = ", ".join([*RESERVED_QUANTITIES, *fields, *parameters, *states])
            raise ModelError(
                f"units: unknown quantity {key!r}; expected one of {expected} "
                "(a parameter, a state or a reserved quantity)"
            )
        if not isinstance(unit, str):
            raise ModelError(
                f"units.{key} must be text such as 'kg/m'; found {type(unit).__name__} {unit!r}"
            )
        text = unit.strip()
        if not text or len(text) > MAX_UNIT_LENGTH or not all(_UNIT.match(ch) for ch in text):
            raise ModelError(
                f"units.{key} = {unit!r} is malformed; expected a unit such as 'kg/m' or "
                f"'N*m^2' (letters, digits, spaces and . * / ^ ( ) -, at most "
                f"{MAX_UNIT_LENGTH} characters)"
            )
        out.append((key, text))
    return tuple(out)


def with_unit(label: str, units: Mapping[str, str], key: str) -> str:
    """Append ``[unit]`` to ``label`` when ``units`` states one for ``key``."""
    unit = units.get(key)
    return f"{label} [{unit}]" if unit else label
