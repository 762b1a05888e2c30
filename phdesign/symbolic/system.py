"""What the modules below the model read of one, and how they recognize a model.

A :class:`~phdesign.symbolic.model.BCPHS` validates itself when it is built: it derives
its ports (:mod:`phdesign.symbolic.ports`), its conjugate outputs
(:mod:`phdesign.symbolic.conjugate`) and its closed plant (:mod:`phdesign.symbolic.closing`).
Those modules therefore sit below the model module and cannot import it; they read a model
through :class:`PortedSystem`, the interface that :class:`~phdesign.symbolic.model.BCPHS`
implements, and refuse anything else with :func:`require_model`, as every layer above does.

Examples
--------
>>> require_model("wave")
Traceback (most recent call last):
...
phdesign.core.errors.ArgumentError: model: expected a BCPHS model (phdesign.load('wave')
reads a built-in model or a TOML file); found str 'wave'
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING

import sympy

from phdesign.core.checks import found_text
from phdesign.core.errors import ArgumentError

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.symbolic.closing import ClosedPorts

__all__ = ["PortedSystem", "require_model"]


class PortedSystem(ABC):
    """A validated symbolic BC-PHS as the port derivation and the printouts read it.

    :class:`~phdesign.symbolic.model.BCPHS` is the implementation (its docstring states the
    equations); the attributes are those of the model.
    """

    name: str
    interval: tuple[sympy.Expr, sympy.Expr]
    order: int
    size: int
    P: tuple[sympy.ImmutableMatrix, ...]
    inputs: tuple[sympy.Expr, ...]
    outputs: tuple[sympy.Expr, ...]

    @property
    @abstractmethod
    def parameter_defaults(self) -> dict[sympy.Symbol, sympy.Expr]:
        """The parameters' default values, keyed by symbol."""

    @property
    @abstractmethod
    def closed_ports(self) -> ClosedPorts | None:
        """The ports of the plant closed by its own ``[feedback]``, or ``None`` without one."""


def require_model(value: object, name: str = "model") -> None:
    """Raise :class:`ArgumentError` unless ``value`` is a :class:`~phdesign.BCPHS`."""
    if not isinstance(value, PortedSystem):
        hint = ""
        if isinstance(value, str):
            hint = f" (phdesign.load({value!r}) reads a built-in model or a TOML file)"
        raise ArgumentError(f"{name}: expected a BCPHS model{hint}; found {found_text(value)}")
