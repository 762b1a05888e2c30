r"""Fields of a model read from its state: the displacement and named performance outputs.

A *field* is a linear combination of state components and their antiderivatives,

.. math::

    f(z, t) = \sum_j c_j \, (\mathcal I_s^{k_j} x_{i_j})(z, t), \qquad
    (\mathcal I_s g)(z) = \int_s^z g(r)\, dr,

with :math:`s \in \{a, b\}` the end the integrations start from (``start``), so that every
integration constant is fixed by the field and its first antiderivatives vanishing at
:math:`s` (a clamped end).  A term with :math:`k_j = 0` is the component itself (a
strain).  The coefficients :math:`c_j` are exact numbers or expressions in the parameters.

The model's displacement :math:`w` (``[displacement]``, read as ``w(z0)``) is one field;
``[fields.<name>]`` adds named ones (``rotation(1)``).  For the Euler-Bernoulli beam,
:math:`x_2 = \partial_z^2 w`: ``w`` is one term, two integrations of :math:`x_2`.  For the
Timoshenko beam with :math:`x = (w_z - \phi, \rho w_t, \phi_z, I_\rho \phi_t)`,
:math:`\phi = \mathcal I_a x_3` and :math:`w_z = x_1 + \phi`, so

.. math:: w = \mathcal I_a x_1 + \mathcal I_a^2 x_3, \qquad \phi = \mathcal I_a x_3.

Each term of a field with stated units has the unit of :math:`x_i` times
:math:`z^{k}` times its coefficient's; they must agree with each other and with the
field's stated unit (checked exactly, by :mod:`phdesign.symbolic.dimensions`).

Examples
--------
>>> Displacement(component=2, integrations=2).terms
(Term(component=2, integrations=2, coefficient=1),)
>>> w = Field(terms=(Term(1, 1), Term(3, 2)))
>>> w.component is None, len(w.terms)
(True, 2)
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import sympy

from phdesign.core.errors import ArgumentError, ModelError
from phdesign.symbolic.dimensions import dimension, term_dimension
from phdesign.symbolic.parser import brief

__all__ = ["FIELD_KEYS", "Displacement", "Field", "Term", "check_fields", "field_from_table"]

#: Keys of a field's table: the short form (one term) or ``terms``, and ``start``.
FIELD_KEYS = ("component", "integrations", "coefficient", "terms", "start")
#: Names a field may not take: they read as something else in an expression.
_TAKEN = ("w", "z", "t", "int")
_ONE = sympy.Integer(1)


@dataclass(frozen=True)
class Term:
    r"""One term :math:`c\,\mathcal I_s^{k} x_i` of a field (``component`` i is 1-based)."""

    component: int
    integrations: int = 0
    coefficient: sympy.Expr = _ONE


@dataclass(frozen=True)
class Field:
    r"""A field :math:`\sum_j c_j \mathcal I_s^{k_j} x_{i_j}` (see the module docstring).

    Give either ``component`` and ``integrations`` (one term with coefficient 1, the form
    of the first model files) or ``terms``; ``start`` is ``"a"`` or ``"b"``.  Two fields
    are equal when their terms and start are.
    """

    component: int | None = field(default=None, compare=False)
    integrations: int | None = field(default=None, compare=False)
    terms: tuple[Term, ...] = ()
    start: str = "a"

    def __post_init__(self) -> None:
        if not self.terms and self.component is not None:
            one = Term(self.component, self.integrations)  # type: ignore[arg-type]
            object.__setattr__(self, "terms", (one,))
        elif self.component is None and _is_short(self.terms):
            object.__setattr__(self, "component", self.terms[0].component)
            object.__setattr__(self, "integrations", self.terms[0].integrations)

    @property
    def short(self) -> bool:
        """Whether the field is one term with coefficient 1 (the short form)."""
        return _is_short(self.terms)


#: The model's displacement is a field; the name of the first model files stays.
Displacement = Field


def _is_short(terms: Any) -> bool:
    return (
        isinstance(terms, tuple)
        and len(terms) == 1
        and isinstance(terms[0], Term)
        and terms[0].coefficient == 1
    )


def _integer(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def field_from_table(table: Mapping[str, Any], key: str, parse_coefficient: Any) -> Field:
    """Read a field's table (``[displacement]`` or ``[fields.<name>]``) of a model file.

    ``parse_coefficient(value, what)`` reads a coefficient exactly (numbers, or text in
    the parameters).

    Raises
    ------
    ModelError
        Unknown keys, both forms or neither, or entries of the wrong type; the message
        names ``key`` and what was expected.
    """
    unknown = sorted(set(table) - set(FIELD_KEYS))
    start = table.get("start", "a")
    if unknown or start not in ("a", "b"):
        raise ModelError(
            f"[{key}] must hold component and integrations, or terms, and optionally "
            f"start = 'a' or 'b'; found {dict(table)}"
        )
    if "terms" in table:
        if set(table) - {"terms", "start"}:
            raise ModelError(
                f"[{key}] holds terms and {sorted(set(table) - {'terms'})}: give the terms only"
            )
        items = table["terms"]
        if not isinstance(items, list) or not items:
            raise ModelError(f"[{key}] terms must be a non-empty list of tables; found {items!r}")
        terms = tuple(
            _term(t, f"{key}.terms[{j + 1}]", parse_coefficient) for j, t in enumerate(items)
        )
        return Field(terms=terms, start=start)
    if not all(_integer(table.get(k)) for k in ("component", "integrations")):
        raise ModelError(
            f"[{key}] must hold integers component and integrations; found {dict(table)}"
        )
    term = _term(table, key, parse_coefficient, allowed=FIELD_KEYS)
    return Field(terms=(term,), start=start)


def _term(item: object, key: str, parse_coefficient: Any, allowed: Sequence[str] = ()) -> Term:
    if not isinstance(item, Mapping):
        raise ModelError(f"[{key}] must be a table; found {item!r}")
    extra = sorted(set(item) - {"component", "integrations", "coefficient", *allowed})
    if extra or "component" not in item:
        raise ModelError(
            f"[{key}] must hold component (and optionally integrations, coefficient); "
            f"found {dict(item)}"
        )
    component, integrations = item["component"], item.get("integrations", 0)
    if not (_integer(component) and _integer(integrations)):
        raise ModelError(
            f"[{key}] must hold integers component and integrations; found {dict(item)}"
        )
    coefficient = parse_coefficient(item.get("coefficient", 1), f"{key}.coefficient")
    return Term(component, integrations, coefficient)


def check_fields(
    fields: Sequence[tuple[str, object]],
    size: int,
    parameters: Sequence[sympy.Symbol],
    units: Mapping[str, str],
    state_names: Sequence[str],
) -> None:
    """Refuse a field that is not well-formed: its type, components, names and units.

    ``fields`` pairs a units key with each field (``"displacement"`` for ``w``).

    Raises
    ------
    ArgumentError
        A field or term of the wrong type.
    ModelError
        A component outside 1..n, negative integrations, a coefficient with ``z`` or an
        unknown name, a name taken by something else, or terms whose units disagree.
    """
    for name, f in fields:
        if name != "displacement" and (
            not name.isidentifier() or name in _TAKEN or re.fullmatch(r"[ex][0-9]+", name)
        ):
            raise ModelError(
                f"fields: the name {name!r} is taken or malformed; expected an identifier "
                "other than w, z, t, int, e<i>, x<i>"
            )
        _check_field(f, name, size, set(parameters))
        _check_units(f, name, units, state_names)  # type: ignore[arg-type]


def _check_field(f: object, name: str, size: int, parameters: set[sympy.Symbol]) -> None:
    if not isinstance(f, Field) or not f.terms or f.start not in ("a", "b"):
        raise ArgumentError(
            f"{name} must be a Displacement(component=i, integrations=k) of two integers; "
            f"found {type(f).__name__} {brief(f, 60)} (or a Field(terms=...) of several terms)"
        )
    for term in f.terms:
        if not isinstance(term, Term) or not all(
            type(v) is int for v in (term.component, term.integrations)
        ):
            raise ArgumentError(
                f"{name}: each term must be a Term(component, integrations, coefficient) "
                f"of two integers; found {type(term).__name__} {brief(term, 60)}"
            )
        if not (1 <= term.component <= size) or term.integrations < 0:
            raise ModelError(
                f"{name} must name a component in 1..{size} and integrations >= 0; "
                f"found component {term.component}, integrations {term.integrations}"
            )
        c = term.coefficient
        free = c.free_symbols - parameters if isinstance(c, sympy.Expr) else None
        if free is None or free or not c.is_finite or c == 0:
            raise ModelError(
                f"{name}: the coefficient of x{term.component} must be a nonzero number or "
                f"an expression in the parameters; found {c!r}"
            )


def _check_units(f: Field, name: str, units: Mapping[str, str], states: Sequence[str]) -> None:
    """Every term's unit, where the units are stated, equals the others and the field's."""
    found = []
    for term in f.terms:
        label = states[term.component - 1] if term.component <= len(states) else ""
        state_unit = units.get(label, units.get(f"x{term.component}"))
        unit = term_dimension(
            state_unit, units.get("z"), term.integrations, term.coefficient, units
        )
        if unit is not None:
            found.append((term, unit))
    stated = units.get(name)
    for term, unit in found:
        reference = found[0][1]
        if sympy.simplify(unit - reference) != 0:
            first = found[0][0]
            raise ModelError(
                f"{name}: the terms' units disagree: expected {reference} (x{first.component} "
                f"integrated {first.integrations} times), found {unit} for x{term.component} "
                f"integrated {term.integrations} times"
            )
    if stated is not None and found:
        expected = dimension(stated)
        if expected is not None and sympy.simplify(found[0][1] - expected) != 0:
            raise ModelError(
                f"{name}: units.{name} = {stated!r}: expected its terms in {expected}, "
                f"found {found[0][1]}"
            )
