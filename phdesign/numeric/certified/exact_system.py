r"""The exact closed system that every certificate starts from.

A certificate is a statement about one linear boundary problem,

.. math::

    \partial_t x = \sum_{k=0}^N P_k \partial_z^k (H x), \qquad
    (U + G Y)\, v = 0, \qquad
    v = (\phi(b); \phi(a)),\ \phi = (e, e', \dots, e^{(N-1)}),\ e = Hx,

with every number exact.  :class:`ExactClosedSystem` holds it: the model's
:math:`P_k`, :math:`H` and interval with the parameters substituted, and the closed
boundary rows :math:`U + GY` over the trace vector of the ports layer.  The closing gain
:math:`G` (:math:`\tilde u = -G\tilde y`) is the one the symbolic layer derives
(:func:`phdesign.symbolic.observer.error_system`, with
:func:`phdesign.symbolic.closing.error_dissipation`):

* the **error system** of an observer: :math:`G = E_c^\top K E_c + E_r^\top C_m^\top L
  C_m E_r`, the observer's injection and the plant's own dampers (``[feedback]``);
* the **plant** with :math:`u = 0` on its external inputs: :math:`G = E_c^\top K E_c`,
  its dampers only.

Numbers stay exact: the symbolic layer reads every float of a model file, a parameter
override or a gain through its shortest decimal text (``0.2`` is :math:`1/5`,
``1/3`` typed as the float ``0.3333333333333333`` is
:math:`3333333333333333/10^{16}`: :func:`phdesign.symbolic.expressions.exact_number`),
so the system certified is the one written down, to the last digit typed.  Entries such
as :math:`\sqrt 2/2` stay algebraic numbers; :attr:`ExactClosedSystem.rational` says
whether every entry is rational.

Unlike :mod:`phdesign.numeric.bridge` (which hands floats to the discretizations), this
crossing keeps sympy's exact numbers: a proof must not start from a rounded model.

Examples
--------
The string with the damper :math:`e_2(1) = -k e_1(1)`, :math:`k = 1/2`, as a plant:

>>> from phdesign.models import load_builtin
>>> system = closed_system(load_builtin("wave-damper"))
>>> system.kind, system.boundary
('plant', Matrix([
[  0, 0, 1, 0],
[1/2, 1, 0, 0]]))
>>> system.dissipation().dissipative
True
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import sympy

from phdesign.core.errors import ModelError, ObserverError
from phdesign.symbolic.closing import error_dissipation, plant_feedback
from phdesign.symbolic.expressions import Z
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import error_system, port_matrices
from phdesign.symbolic.system import require_model

__all__ = ["Dissipation", "ExactClosedSystem", "closed_system"]

#: The two systems a certificate speaks of.
KINDS = ("plant", "error")


@dataclass(frozen=True)
class Dissipation:
    r"""The energy identity's two signs, decided exactly.

    For an eigenpair :math:`(\lambda, x)`, :math:`e = Hx`, integration by parts gives
    (the closing module's energy balance, with :math:`\tilde u = -G\tilde y`)

    .. math::

        \operatorname{Re}\lambda \int_a^b x^* H x\, dz
        = \tfrac12 \int_a^b e^* (P_0 + P_0^\top) e\, dz
          - \tilde y^* \operatorname{sym}(G)\, \tilde y ,

    so :math:`\operatorname{sym}(P_0) \preceq 0` and :math:`\operatorname{sym}(G) \succeq 0`
    give :math:`\operatorname{Re}\lambda \le 0` for every eigenvalue (``dissipative``), and
    both zero give :math:`\operatorname{Re}\lambda = 0` (``conservative``).

    Attributes
    ----------
    boundary, interior : sympy.ImmutableMatrix
        :math:`\operatorname{sym}(G)` and :math:`\operatorname{sym}(P_0)`.
    dissipative, conservative : bool
    """

    boundary: sympy.ImmutableMatrix
    interior: sympy.ImmutableMatrix
    dissipative: bool
    conservative: bool


@dataclass(frozen=True)
class ExactClosedSystem:
    r"""A closed BC-PHS with exact numbers (module docstring).

    Attributes
    ----------
    name : str
        The model's name.
    kind : str
        ``"plant"`` (:math:`u = 0`, the plant's own dampers) or ``"error"`` (the observer's
        error system).
    order, size : int
        :math:`N` and :math:`n`.
    interval : tuple of sympy.Rational
        :math:`(a, b)`.
    P : tuple of sympy.ImmutableMatrix
        :math:`P_0, \dots, P_N` (:math:`P_0` may depend on :data:`z`).
    H : sympy.ImmutableMatrix
        :math:`H` (may depend on :data:`z`).
    U, Y : sympy.ImmutableMatrix
        The open plant's ports over the traces, :math:`u = Uv`, :math:`y = Yv`
        (``Nn x 2Nn``).
    G : sympy.ImmutableMatrix
        The closing gain over the open ports, :math:`\tilde u = -G\tilde y` (``Nn x Nn``).
    C_m, L : sympy.ImmutableMatrix or None
        The observer's sensors and gain (``None`` for the plant).
    z : sympy.Symbol
        The space variable of :attr:`P` and :attr:`H`.
    """

    name: str
    kind: str
    order: int
    size: int
    interval: tuple[sympy.Rational, sympy.Rational]
    P: tuple[sympy.ImmutableMatrix, ...]
    H: sympy.ImmutableMatrix
    U: sympy.ImmutableMatrix
    Y: sympy.ImmutableMatrix
    G: sympy.ImmutableMatrix
    C_m: sympy.ImmutableMatrix | None = None
    L: sympy.ImmutableMatrix | None = None
    z: sympy.Symbol = Z

    @cached_property
    def boundary(self) -> sympy.ImmutableMatrix:
        r"""The closed boundary rows :math:`B = U + GY` (``Nn x 2Nn``): :math:`Bv = 0`."""
        return sympy.ImmutableMatrix(self.U + self.G * self.Y)

    @property
    def boundary_blocks(self) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
        r"""Return :math:`(B_b, B_a)`: :math:`Bv = B_b \phi(b) + B_a \phi(a)`."""
        nn = self.order * self.size
        B = self.boundary
        return sympy.ImmutableMatrix(B[:, :nn]), sympy.ImmutableMatrix(B[:, nn:])

    @property
    def length(self) -> sympy.Rational:
        """:math:`b - a`."""
        return sympy.Rational(self.interval[1] - self.interval[0])

    @property
    def constant(self) -> bool:
        """Whether :math:`H` and every :math:`P_k` are constant (no :data:`z`)."""
        return not any(M.has(self.z) for M in (self.H, *self.P))

    @property
    def rational(self) -> bool:
        """Whether every entry (matrices, interval, boundary rows) is a rational number."""
        matrices = (self.H, *self.P, self.boundary)
        entries = [x for M in matrices for x in M] + list(self.interval)
        return all(isinstance(x, sympy.Rational) for x in entries)

    def dissipation(self) -> Dissipation:
        r"""Decide the signs of the energy identity exactly (:class:`Dissipation`).

        :math:`\operatorname{sym}(G) \succeq 0` and :math:`\operatorname{sym}(P_0) \preceq 0`.
        A :math:`P_0` that depends on z is decided only where it is constant: a z-dependent
        one gives ``dissipative=False`` here (the model's own validation checked it on a
        grid, which is no proof).
        """
        sym_G = sympy.ImmutableMatrix((self.G + self.G.T) / 2)
        sym_P0 = sympy.ImmutableMatrix((self.P[0] + self.P[0].T) / 2)
        boundary_ok = _semidefinite(sym_G)
        interior_ok = not sym_P0.has(self.z) and _semidefinite(-sym_P0)
        conservative = sym_G.is_zero_matrix is True and sym_P0.is_zero_matrix is True
        return Dissipation(sym_G, sym_P0, boundary_ok and interior_ok, conservative)

    def to_dict(self) -> dict[str, Any]:
        """Return the system as exact text (sympy's printer): what a proof file records."""

        def rows(M: sympy.MatrixBase) -> list[list[str]]:
            return [[str(x) for x in M.row(i)] for i in range(M.rows)]

        out: dict[str, Any] = {
            "name": self.name,
            "kind": self.kind,
            "order": self.order,
            "size": self.size,
            "interval": [str(x) for x in self.interval],
            "P": [rows(M) for M in self.P],
            "H": rows(self.H),
            "U": rows(self.U),
            "Y": rows(self.Y),
            "G": rows(self.G),
            "boundary": rows(self.boundary),
        }
        if self.C_m is not None and self.L is not None:
            out["C_m"], out["L"] = rows(self.C_m), rows(self.L)
        return out


def _semidefinite(M: sympy.ImmutableMatrix) -> bool:
    r"""Decide :math:`M \succeq 0` exactly for a symmetric matrix of numbers (sympy decides it)."""
    if M.rows == 0 or M.is_zero_matrix:
        return True
    return bool(M.is_positive_semidefinite)


def closed_system(
    model: BCPHS,
    C_m: Any = None,
    L: Any = None,
    *,
    parameters: dict[str, Any] | None = None,
) -> ExactClosedSystem:
    r"""Return the exact closed plant (no ``C_m``) or the observer's error system.

    Parameters
    ----------
    model : BCPHS
        The model (with its ``[feedback]``, if any).
    C_m, L : optional
        Sensors over the external outputs and their gain, read by
        :func:`phdesign.symbolic.observer.sensors_and_gain` (exact: floats through their
        decimal text).  Without them: the plant with :math:`u = 0`.
    parameters : mapping, optional
        Overrides of the parameter defaults (read exactly by
        :meth:`~phdesign.symbolic.model.BCPHS.with_parameters`).

    Raises
    ------
    ObserverError
        A gain with free symbols (a certificate needs numbers), or malformed sensors.
    ModelError
        A parameter left free in the model's matrices.
    """
    require_model(model)
    model = model.with_parameters(parameters) if parameters else model
    defaults = model.parameter_defaults
    kind = "plant" if C_m is None else "error"
    if kind == "plant" and L is not None:
        raise ObserverError("a gain L needs sensors C_m; give both, or neither for the plant")
    U, Y = port_matrices(model)
    C = [] if C_m is None else C_m
    err = error_system(model.order, model.size, U, Y, C, L, plant_feedback(model))
    if err.L.free_symbols:
        names = ", ".join(sorted(str(s) for s in err.L.free_symbols))
        raise ObserverError(f"a certificate needs a numeric gain; found the symbols {names} in L")
    P = tuple(_exact(M, defaults, f"P{k}", model.name) for k, M in enumerate(model.P))
    H = _exact(model.H, defaults, "H", model.name)
    a, b = model.interval
    if not (isinstance(a, sympy.Rational) and isinstance(b, sympy.Rational)):
        raise ModelError(
            f"a certificate needs a rational interval; found [{a}, {b}] in model {model.name!r}"
        )
    G = error_dissipation(model.order * model.size, err.C_m, err.L, plant_feedback(model))[0]
    return ExactClosedSystem(
        name=model.name,
        kind=kind,
        order=model.order,
        size=model.size,
        interval=(sympy.Rational(a), sympy.Rational(b)),
        P=P,
        H=H,
        U=U,
        Y=Y,
        G=sympy.ImmutableMatrix(G),
        C_m=None if kind == "plant" else err.C_m,
        L=None if kind == "plant" else err.L,
    )


def _exact(
    M: sympy.MatrixBase, defaults: dict[sympy.Symbol, Any], what: str, model: str
) -> sympy.ImmutableMatrix:
    """``M`` with the parameters substituted; a symbol other than z left free is refused."""
    out = sympy.ImmutableMatrix(sympy.Matrix(M).xreplace(defaults))
    free = sorted(str(s) for s in out.free_symbols if s != Z)
    if free:
        raise ModelError(
            f"{what} of model {model!r} keeps the free symbols {', '.join(free)} after the "
            "parameters are substituted; give them values (parameters={...})"
        )
    return out
