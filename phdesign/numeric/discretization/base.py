r"""The base of the discretization methods: a registry by name (py-pde's solvers).

A method is a subclass of :class:`Method` that names itself and builds a
:class:`~phdesign.numeric.discretization.phs.DiscretePHS`; defining the class registers
it::

    class Chebyshev(Method, name="chebyshev"):
        @classmethod
        def build(cls, nm, resolution, basis):
            ...  # a DiscretePHS with method="chebyshev"

Its defaults and tolerances (resolutions, basis, caps, the drift and abscissa
tolerances, the bases it accepts) are the entry of the same name in the table of
defaults (:mod:`phdesign.core.defaults`), which the command line reads without loading
the numeric layer; :func:`check_registered` says whether builders and entries agree, and
:func:`phdesign.numeric.discretization.registry.discretize` dispatches by name.

Adding a method is three edits: its module in ``numeric/discretization/`` with the
subclass (and a convergence-rate test beside the others), its
:class:`~phdesign.core.defaults.MethodDefaults` entry in the table, and its class in
the registry's tuple of built-in methods (importing the module registers it).  The
command line's ``--method`` choices, the design objects, the sweep, the loop, the noise
figures and the spectrum read the registry and the table; nothing else changes.
"""

from __future__ import annotations

from typing import Any, ClassVar

from phdesign.core.defaults import Defaults, current
from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.phs import DiscretePHS

__all__ = ["Method", "check_registered"]


class Method:
    """A discretization method, registered by the ``name`` its subclass gives.

    Subclasses implement :meth:`build`; :meth:`from_name` returns the class registered
    under a name, :meth:`unregister` removes one (for a method defined in a test).
    """

    name: ClassVar[str] = ""
    _registry: ClassVar[dict[str, type[Method]]] = {}

    def __init_subclass__(cls, name: str = "", **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if not name:
            return
        if name in Method._registry:
            raise NumericError(
                f"name: a discretization method {name!r} is registered already "
                f"({Method._registry[name].__qualname__}); found {cls.__qualname__} as well"
            )
        cls.name = name
        Method._registry[name] = cls

    @classmethod
    def build(cls, nm: NumericModel, resolution: int, basis: str | None) -> DiscretePHS:
        """Discretize ``nm`` at ``resolution`` (``basis`` checked against the method's)."""
        raise NotImplementedError(f"{cls.__qualname__} does not build a discretization")

    @staticmethod
    def registered() -> tuple[str, ...]:
        """Return the names of the registered methods, in registration order."""
        return tuple(Method._registry)

    @staticmethod
    def from_name(name: str) -> type[Method]:
        """Return the method registered as ``name``, or raise naming the registered ones."""
        try:
            return Method._registry[name]
        except (KeyError, TypeError):
            raise NumericError(
                f"method: no discretization method is registered as {name!r}; expected one of "
                f"{', '.join(map(repr, Method._registry))} (a subclass of Method named {name!r} "
                "registers one)"
            ) from None

    @staticmethod
    def unregister(name: str) -> None:
        """Remove the method registered as ``name`` (a method defined for a test)."""
        Method._registry.pop(name, None)


def check_registered(table: Defaults | None = None) -> None:
    """Raise :class:`NumericError` unless the builders and the table's methods are the same.

    ``table`` defaults to the table in force (:func:`phdesign.core.defaults.current`).
    """
    names = (table or current()).method_names
    if set(names) != set(Method.registered()):
        raise NumericError(
            f"the table of defaults has the methods {names} and the registry builds "
            f"{Method.registered()}; expected the same names (register a Method subclass "
            "for each entry, and an entry for each subclass)"
        )
