r"""The boundary observer and its error system.

The observer copies the plant and corrects its input with the measured outputs,

.. math::

    \hat u = u + C_m^\top L\, (y_m - \hat y_m), \qquad y_m = C_m y,
    \qquad L + L^\top \succ 0 ,

so the error :math:`\tilde x = x - \hat x` is the same BC-PHS with the boundary condition

.. math::

    \tilde u = -C_m^\top L C_m \tilde y
    \quad\Longleftrightarrow\quad
    (U + C_m^\top L C_m Y)\, v = 0 ,

where :math:`u = U v`, :math:`y = Y v` over the trace vector :math:`v` (ports layer).
The admissible traces form :math:`\mathcal K = \ker(U + C_m^\top L C_m Y)`.
Because :math:`T = \begin{pmatrix} U \\ Y \end{pmatrix}` is invertible (the port
identities make :math:`(W_B; W_C)` invertible), :math:`\mathcal K` has the explicit basis

.. math::

    K = T^{-1} \begin{pmatrix} -C_m^\top L C_m \\ I \end{pmatrix}
    \qquad (v = K \tilde y),

parametrized by the error output :math:`\tilde y` itself, for every gain: no rank
decision on :math:`L` is involved, so a symbolic gain cannot hide a generic-rank
answer here.  :math:`\dim \mathcal K = Nn` is still checked.

A plant with its own boundary feedback :math:`u_c = -K y_c` (``[feedback]``,
:mod:`phdesign.symbolic.feedback`) is observed through its external outputs: ``C_m``
picks among them, and the error boundary condition over all :math:`Nn` open ports is
:math:`\tilde u = -G\tilde y` with :math:`G = E_c^\top K E_c + E_r^\top C_m^\top L C_m
E_r`, whose symmetric part (the plant's dampers and the observer's injection) is the
left-hand side of every proposition.

Sensors and gains are read and validated in one place, :mod:`phdesign.symbolic.sensors`
(:func:`sensor_matrix`, :func:`measurement_matrix`, :func:`gain_matrix`), re-exported
here.

Examples
--------
The string with the damper of the observer at its right end: with
:math:`v = (e_1(1), e_2(1), e_1(0), e_2(0))`, inputs :math:`u = (e_1(0), e_2(1))`,
outputs :math:`y = (-e_2(0), e_1(1))`, the sensor :math:`y_2` and :math:`L = 1/2`, the
error boundary condition is :math:`e_1(0) = 0` and :math:`e_2(1) = -\tfrac12 e_1(1)`:

>>> from phdesign.models import load_builtin
>>> wave = load_builtin("wave")
>>> U, Y = port_matrices(wave)
>>> err = error_system(wave.order, wave.size, U, Y, sensor_matrix([2], 2), gain_matrix("1/2", 1))
>>> err.boundary_matrix
Matrix([
[  0, 0, 1, 0],
[1/2, 1, 0, 0]])
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import sympy
from sympy.polys.matrices import DomainMatrix
from sympy.polys.matrices.exceptions import DMNonInvertibleMatrixError

from phdesign.core.errors import ObserverError
from phdesign.symbolic.closing import error_dissipation, plant_feedback
from phdesign.symbolic.expressions import vanishes
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.sensors import (
    caller_matrix,
    diagonal_values,
    gain_matrix,
    gain_symbols,
    measurement_matrix,
    no_sensors,
    observer_sensors,
    parse_sensor_indices,
    sensor_matrix,
    sensors_and_gain,
)
from phdesign.symbolic.system import require_model

__all__ = [
    "ErrorSystem",
    "ObserverDesign",
    "diagonal_values",
    "error_system",
    "gain_matrix",
    "gain_symbols",
    "measurement_matrix",
    "no_sensors",
    "observer_sensors",
    "parse_sensor_indices",
    "port_inverse",
    "port_matrices",
    "sensor_matrix",
    "sensors_and_gain",
]


# --------------------------------------------------------------------------- design
def port_matrices(model: BCPHS) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
    r"""Return :math:`(U, Y)` of ``model`` with the parameter defaults substituted.

    The classification lives in trace coordinates: only :math:`U` and :math:`Y`
    enter it (not :math:`\mathcal H`, and :math:`P_k` only through Assumption 3.1).
    """
    ports = model.ports
    defaults = model.parameter_defaults
    U, Y = (sympy.ImmutableMatrix(M.xreplace(defaults)) for M in (ports.U, ports.Y))
    return U, Y


def port_inverse(model: BCPHS) -> sympy.ImmutableMatrix:
    r"""Return :math:`T^{-1}` for :math:`T = (U; Y)` at the parameter defaults (exact).

    Column :math:`j` of :math:`T^{-1}` is the trace vector :math:`v` whose inputs and
    outputs are all zero but the :math:`j`-th of :math:`(u; y)`; the port identities make
    :math:`T` invertible, so the traces of the error system are :math:`v = T^{-1}(\tilde u;
    \tilde y)`.

    Raises
    ------
    ObserverError
        If :math:`T` is singular (the outputs are not the power conjugates of the inputs).

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> port_inverse(load_builtin("wave"))  # v = (e1(1), e2(1), e1(0), e2(0))
    Matrix([
    [0, 0,  0, 1],
    [0, 1,  0, 0],
    [1, 0,  0, 0],
    [0, 0, -1, 0]])
    """
    require_model(model)
    return _inverse(sympy.ImmutableMatrix(sympy.Matrix.vstack(*port_matrices(model))))


def _inverse(T: sympy.ImmutableMatrix) -> sympy.ImmutableMatrix:
    dm = DomainMatrix.from_Matrix(T).to_field()
    try:
        return sympy.ImmutableMatrix(dm.inv().to_Matrix())
    except DMNonInvertibleMatrixError:
        raise ObserverError(
            "the stacked port matrix (U; Y) is singular, so the admissible traces "
            f"K = ker(U + C_mᵀ L C_m Y) cannot have dimension Nn = {T.rows // 2}; "
            "the outputs must be the power conjugates of the inputs"
        ) from None


@dataclass(frozen=True)
class ErrorSystem:
    r"""The boundary data of the observer error system.

    Attributes
    ----------
    order, size : int
        :math:`N` and :math:`n`.
    U, Y : sympy.ImmutableMatrix
        :math:`u = U v`, :math:`y = Y v` (parameters substituted).
    T_inv : sympy.ImmutableMatrix
        :math:`T^{-1}`, :math:`T = (U; Y)`: the trace vector with inputs ``u`` and
        outputs ``y`` is :math:`v = T^{-1}(u; y)`.
    C_m, L : sympy.ImmutableMatrix
        Sensors and gain.
    boundary_matrix : sympy.ImmutableMatrix
        :math:`U + G Y` (:math:`G = C_m^\top L C_m` without plant feedback), whose kernel
        is :math:`\mathcal K`.
    K : sympy.ImmutableMatrix
        Basis of :math:`\mathcal K`, :math:`2Nn \times Nn`, coordinates :math:`\tilde y`.
    dissipation_C, dissipation_L : sympy.ImmutableMatrix or None
        The left-hand side of the propositions as
        :math:`\tfrac12 (C_d\tilde y)^\top (L_d + L_d^\top) (C_d\tilde y)`
        (:func:`phdesign.symbolic.closing.error_dissipation`); ``None`` means
        :math:`C_d = C_m`, :math:`L_d = L` (no plant feedback).
    """

    order: int
    size: int
    U: sympy.ImmutableMatrix
    Y: sympy.ImmutableMatrix
    T_inv: sympy.ImmutableMatrix
    C_m: sympy.ImmutableMatrix
    L: sympy.ImmutableMatrix
    boundary_matrix: sympy.ImmutableMatrix
    K: sympy.ImmutableMatrix
    dissipation_C: sympy.ImmutableMatrix | None = None
    dissipation_L: sympy.ImmutableMatrix | None = None

    @property
    def dissipation(self) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
        r"""Return :math:`(C_d, L_d)`, the factor of the propositions' left-hand side.

        LHS :math:`= \tfrac12 (C_d\tilde y)^\top(L_d + L_d^\top)(C_d\tilde y)`, with
        :math:`C_d` of full row rank and :math:`L_d + L_d^\top \succ 0`.
        """
        if self.dissipation_C is None or self.dissipation_L is None:
            return self.C_m, self.L
        return self.dissipation_C, self.dissipation_L

    @property
    def lhs_matrix(self) -> sympy.ImmutableMatrix:
        r"""Return :math:`M = C_d^\top \mathrm{sym}(L_d) C_d` (LHS is its quadratic form in ỹ)."""
        C_d, L_d = self.dissipation
        return sympy.ImmutableMatrix(C_d.T * (L_d + L_d.T) / 2 * C_d)


def error_system(
    order: int,
    size: int,
    U: sympy.MatrixBase,
    Y: sympy.MatrixBase,
    C_m: Any,
    L: Any,
    feedback: tuple[tuple[int, ...], sympy.ImmutableMatrix] | None = None,
) -> ErrorSystem:
    r"""Build the error boundary condition and the admissible traces.

    Parameters
    ----------
    order, size : int
        :math:`N` and :math:`n`.
    U, Y : sympy matrix
        The open plant's ports over the traces (``Nn x 2Nn``).
    C_m, L
        Sensors over the external outputs and their gain, read by
        :func:`measurement_matrix` and :func:`gain_matrix`.
    feedback : (closed 0-based indices, K), optional
        The plant's own boundary feedback (:func:`~phdesign.symbolic.closing.plant_feedback`).

    Raises
    ------
    ObserverError
        If ``C_m`` or ``L`` is malformed, or :math:`\dim \mathcal K \ne Nn`.
    """
    nn = order * size
    C_m, L = sensors_and_gain(C_m, L, nn - (0 if feedback is None else len(feedback[0])))
    U = caller_matrix(U, "U")
    Y = caller_matrix(Y, "Y")
    T_inv = _inverse(sympy.ImmutableMatrix(sympy.Matrix.vstack(U, Y)))
    G, C_d, L_d = error_dissipation(nn, C_m, L, feedback)
    boundary = sympy.ImmutableMatrix(U + G * Y)
    K = sympy.ImmutableMatrix(T_inv * sympy.Matrix.vstack(-G, sympy.eye(nn)))
    # dim K = Nn: K has Nn columns and its lower part through Y is the identity
    # (Y K = I), so the columns are independent; K solves the boundary condition.
    residuals = [*(boundary * K), *(Y * K - sympy.eye(nn))]
    if not all(vanishes(x) for x in residuals):
        raise ObserverError(
            f"the admissible traces K = ker(U + C_mᵀ L C_m Y) must have dimension Nn = {nn}; "
            "the port matrices are inconsistent"
        )
    if feedback is None:
        return ErrorSystem(order, size, U, Y, T_inv, C_m, L, boundary, K)
    return ErrorSystem(order, size, U, Y, T_inv, C_m, L, boundary, K, C_d, L_d)


@dataclass(frozen=True)
class ObserverDesign:
    r"""A sensor set and gain for a model: the observer of the module docstring.

    The symbolic core of :class:`phdesign.Observer`: exact, validated :math:`C_m` and
    :math:`L` and the error system they define.

    Parameters
    ----------
    model : BCPHS
        The plant (with its own boundary feedback, if any).
    C_m : matrix
        ``q x n_ports`` over the model's external outputs, full row rank (read by
        :func:`measurement_matrix`).
    L : number, sequence, matrix or "symbolic"
        Read by :func:`gain_matrix`: :math:`L + L^\top > 0`, or diagonal positive symbols.
    """

    model: BCPHS
    C_m: sympy.ImmutableMatrix
    L: sympy.ImmutableMatrix

    def __post_init__(self) -> None:
        require_model(self.model)
        C_m, L = sensors_and_gain(self.C_m, self.L, self.model.n_ports)
        object.__setattr__(self, "C_m", C_m)
        object.__setattr__(self, "L", L)

    def error_system(self) -> ErrorSystem:
        """Return the :class:`ErrorSystem` of this design."""
        U, Y = port_matrices(self.model)
        return error_system(
            self.model.order, self.model.size, U, Y, self.C_m, self.L, plant_feedback(self.model)
        )
