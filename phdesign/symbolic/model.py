"""The validated symbolic boundary-controlled port-Hamiltonian system, :class:`BCPHS`.

The class states the equations and the conditions; building one checks them all
(:mod:`phdesign.symbolic.validation`) and derives its boundary port variables
(:mod:`phdesign.symbolic.ports`).  The parts of a definition are read by
:mod:`phdesign.symbolic.definition`, the ``[feedback]`` by :mod:`phdesign.symbolic.feedback`
and :mod:`phdesign.symbolic.closing`; a model prints itself through
:mod:`phdesign.symbolic.display`.

Examples
--------
>>> wave = BCPHS.define(
...     name="string", interval=(0, 1), order=1,
...     P={1: [[0, 1], [1, 0]]}, H=[["1/rho", 0], [0, "T"]],
...     parameters={"rho": 1, "T": 1},
...     inputs=["e1(0)", "e2(1)"], outputs=["-e2(0)", "e1(1)"],
... )
>>> wave.order, wave.size, [str(s) for s, _ in wave.parameters]
(1, 2, ['rho', 'T'])
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any

import sympy

from phdesign.core.errors import ExpressionError, ModelError, ParameterError
from phdesign.core.text import did_you_mean
from phdesign.symbolic import display
from phdesign.symbolic.boundary_checks import check_boundary_systems
from phdesign.symbolic.boundary_systems import (
    BoundarySystem,
    boundary_systems_from_value,
    coupled_indices,
)
from phdesign.symbolic.closing import ClosedPorts, closed_ports
from phdesign.symbolic.definition import (
    Displacement,
    parse_interval,
    parse_matrix,
    parse_P,
    parse_parameters,
    parse_ports,
    parse_units,
)
from phdesign.symbolic.disturbances import Disturbances, disturbances_from_mapping
from phdesign.symbolic.expressions import Z, exact_number, parameter_symbol
from phdesign.symbolic.feedback import Feedback, external_indices, feedback_from_mapping
from phdesign.symbolic.fields import Field
from phdesign.symbolic.performance import PerformanceOutput, parse_performance
from phdesign.symbolic.ports import Ports, derive_ports
from phdesign.symbolic.system import PortedSystem
from phdesign.symbolic.validation import validate

__all__ = ["BCPHS", "Z"]


@dataclass(frozen=True, repr=False)
class BCPHS(PortedSystem):
    r"""A validated symbolic boundary-controlled port-Hamiltonian system (BC-PHS).

    The state :math:`x(z, t) \in \mathbb R^n` on :math:`z \in [a, b]` and the effort
    :math:`e = \mathcal H x` obey

    .. math::

        \partial_t x(z, t) = \sum_{k=0}^{N} P_k\, \partial_z^k \big(\mathcal H(z)\, x(z, t)\big),
        \qquad
        \mathcal E(t) = \tfrac12 \int_a^b x^\top \mathcal H x \, dz ,

    with

    .. math::

        P_k = (-1)^{k+1} P_k^\top \ (k = 1, \dots, N) \text{ constant}, \qquad
        P_N \text{ invertible}, \qquad
        P_0(z) + P_0(z)^\top \preceq 0, \qquad
        \mathcal H(z) = \mathcal H(z)^\top \succeq m I \succ 0 \ \text{on } [a, b].

    The boundary traces :math:`\phi(z) = (e, \partial_z e, \dots, \partial_z^{N-1} e)(z)`
    form :math:`v = (\phi(b); \phi(a)) \in \mathbb R^{2Nn}`; integration by parts gives the
    boundary port variables and the energy balance

    .. math::

        \begin{pmatrix} f_\partial \\ e_\partial \end{pmatrix} = R_{ext} v, \quad
        R_{ext} = \frac{1}{\sqrt 2}\begin{pmatrix} Q & -Q \\ I & I \end{pmatrix}, \quad
        Q_{ij} = (-1)^{i-1} P_{i+j-1}, \qquad
        \dot{\mathcal E} = \tfrac12 \int_a^b e^\top (P_0 + P_0^\top)\, e \, dz
        + u^\top y ,

    (:mod:`phdesign.symbolic.ports`; the paper's :math:`(-1)^{j-1}` has the wrong sign for
    even :math:`k`).  The inputs and outputs are trace expressions (``N n`` each),
    :math:`u = U v = W_B (f_\partial; e_\partial)` and
    :math:`y = Y v = W_C (f_\partial; e_\partial)`; with :math:`W_B = U R_{ext}^{-1}`,
    :math:`W_C = Y R_{ext}^{-1}` of full rank :math:`Nn` and
    :math:`\Sigma = \left(\begin{smallmatrix} 0 & I \\ I & 0 \end{smallmatrix}\right)`
    of size :math:`2Nn`, they satisfy

    .. math::

        W_B \Sigma W_B^\top = 0, \qquad W_C \Sigma W_C^\top = 0, \qquad
        W_C \Sigma W_B^\top = I .

    Only :math:`P_0` and :math:`\mathcal H` may depend on :math:`z` (and all entries on
    the parameters).  A ``[feedback]`` closes inputs with :math:`u_c = -K y_c`,
    :math:`K + K^\top \succeq 0` (:mod:`phdesign.symbolic.feedback`); the others stay the
    external ports.

    Build one with :meth:`define` (from strings and numbers) or from a model file
    with :func:`phdesign.io.read_model`. Construction validates every condition
    (:mod:`phdesign.symbolic.validation`) and raises
    :class:`~phdesign.core.errors.ModelError`,
    :class:`~phdesign.core.errors.ExpressionError`
    or :class:`~phdesign.core.errors.PortError` naming what is wrong; :attr:`checks`
    says how each condition was verified.

    Attributes
    ----------
    name : str
        A human-readable name.
    interval : tuple of sympy.Expr
        Exact endpoints ``(a, b)`` with ``a < b``.
    order : int
        The differential order ``N``.
    size : int
        The number ``n`` of state components.
    P : tuple of sympy.ImmutableMatrix
        ``P_0 .. P_N``, ``n x n`` (entries may hold parameters); only ``P_0`` may depend
        on ``z``.
    H : sympy.ImmutableMatrix
        The energy density :math:`\mathcal H(z)`, in ``z`` and the parameters.
    parameters : tuple of (sympy.Symbol, sympy.Expr)
        Parameters and their exact default values.
    inputs, outputs : tuple of sympy.Expr
        ``N n`` trace expressions each: the ports of the open plant, before any feedback.
    state_names : tuple of str
        One label per state component.
    description : str
        Free text.
    displacement : Displacement or None
        How to recover the displacement :math:`w`, when the model has one: a linear
        combination of state components and their antiderivatives
        (:mod:`phdesign.symbolic.fields`).
    feedback : Feedback or None
        The plant's own boundary feedback :math:`u_c = -K y_c` (``[feedback]``); the
        external ports are then :attr:`external_inputs` and :attr:`external_outputs`.
    units : tuple of (str, str)
        Units stated for parameters, states and ``t``, ``z``, ``energy``, ``displacement``.
    derived_outputs : bool
        The outputs were derived from the inputs (``outputs = "conjugate"``).
    fields : tuple of (str, Field)
        Named performance outputs (``[fields.<name>]``: rotations, strains), in the form
        of the displacement (:mod:`phdesign.symbolic.fields`).
    boundary_systems : tuple of BoundarySystem
        Finite-dimensional port-Hamiltonian systems joined to some inputs by a
        power-preserving interconnection (``[[boundary_systems]]``,
        :mod:`phdesign.symbolic.boundary_systems`); their external inputs follow the
        PDE's in :attr:`n_ports`.
    disturbances : Disturbances or None
        :math:`B(z) w` in the domain and the unknown external inputs
        (:mod:`phdesign.symbolic.disturbances`); the energy identity gains
        :math:`\int_a^b e^\top B w\, dz`.
    performance : tuple of PerformanceOutput
        The outputs a design is judged on (``[performance]``).
    checks : tuple of str
        How each condition was verified (exactly, or at the defaults on a grid).
    """

    name: str
    interval: tuple[sympy.Expr, sympy.Expr]
    order: int
    size: int
    P: tuple[sympy.ImmutableMatrix, ...]
    H: sympy.ImmutableMatrix
    parameters: tuple[tuple[sympy.Symbol, sympy.Expr], ...]
    inputs: tuple[sympy.Expr, ...]
    outputs: tuple[sympy.Expr, ...]
    state_names: tuple[str, ...] = ()
    description: str = ""
    displacement: Displacement | None = None
    feedback: Feedback | None = None
    units: tuple[tuple[str, str], ...] = ()
    derived_outputs: bool = False
    fields: tuple[tuple[str, Field], ...] = ()
    boundary_systems: tuple[BoundarySystem, ...] = ()
    disturbances: Disturbances | None = None
    performance: tuple[PerformanceOutput, ...] = ()
    checks: tuple[str, ...] = field(default=(), compare=False, repr=False)

    def __post_init__(self) -> None:
        if not self.state_names:
            object.__setattr__(self, "state_names", tuple(f"x{i + 1}" for i in range(self.size)))
        checks = validate(self)
        object.__setattr__(self, "checks", (*checks, *check_boundary_systems(self)))

    # ------------------------------------------------------------------ printing
    def __repr__(self) -> str:
        """One line: name, order, size, interval and parameter defaults."""
        return display.model_repr(self)

    def __str__(self) -> str:
        """Return the summary ``phdesign show`` prints (:mod:`phdesign.symbolic.display`)."""
        return display.model_text(self)

    def _repr_html_(self) -> str:
        return display.model_html(self)

    # ------------------------------------------------------------------ construction
    @classmethod
    def define(
        cls,
        *,
        name: str,
        interval: Sequence[object],
        order: int,
        P: Mapping[int, Any] | Sequence[Any],
        H: Any,
        inputs: Sequence[str | sympy.Expr],
        outputs: Sequence[str | sympy.Expr] | str | None = None,
        parameters: Mapping[str, object] | None = None,
        state_names: Sequence[str] = (),
        description: str = "",
        displacement: Displacement | None = None,
        feedback: Feedback | Mapping[str, Any] | None = None,
        units: Mapping[str, str] | None = None,
        fields: Mapping[str, Field] | None = None,
        boundary_systems: Sequence[BoundarySystem | Mapping[str, Any]] | None = None,
        disturbances: Disturbances | Mapping[str, Any] | Any = None,
        performance: Sequence[str | PerformanceOutput] | None = None,
    ) -> BCPHS:
        r"""Build a model from numbers, strings and nested lists.

        Parameters
        ----------
        name : str
            A human-readable name.
        interval : (a, b)
            Numeric endpoints.
        order : int
            The order ``N`` of the differential operator.
        P : mapping {k: matrix} or sequence of matrices
            ``P_k``; omitted ones are zero. Entries are numbers or expression strings
            in the parameters.
        H : matrix
            :math:`\mathcal H(z)`; entries are numbers or strings in ``z`` and the parameters.
        inputs : sequence of str
            Trace expressions, ``N n`` of them.
        outputs : sequence of str, "conjugate" or None, optional
            Trace expressions, ``N n`` of them; ``"conjugate"`` or ``None`` derives the
            power-conjugate outputs of the inputs (:mod:`phdesign.symbolic.conjugate`).
        parameters : mapping {name: default value}, optional
            Parameters that may appear in ``P``, ``H`` and the ports.
        state_names : sequence of str, optional
            Labels of the state components.
        description : str, optional
            Free text.
        displacement : Displacement, optional
            How to recover the displacement :math:`w` (a :class:`~.fields.Field`:
            :math:`w = \sum_j c_j \mathcal I_s^{k_j} x_{i_j}`).
        feedback : Feedback or {"inputs": [...], "gain": [[...]]}, optional
            Close inputs with :math:`u_c = -K y_c`, :math:`K + K^\top \succeq 0`
            (:mod:`phdesign.symbolic.feedback`).
        units : mapping {quantity: unit}, optional
            Units of parameters, states, ``t``, ``z``, ``energy``, ``displacement``
            and the named fields.
        fields : mapping {name: Field}, optional
            Named performance outputs (rotations, strains), read as ``name(z0)``.
        boundary_systems : sequence of BoundarySystem or mappings, optional
            Boundary systems joined to some inputs (keys ``name``, ``ports``, ``J``,
            ``R``, ``Q``, ``G`` and optionally ``D``, ``B``, ``states``, ``inputs``,
            ``interconnection``: :mod:`phdesign.symbolic.boundary_systems`).
        disturbances : Disturbances, {"B": [[...]], "unknown": [j]} or B, optional
            :math:`B(z)`, ``n x q``, and the external inputs (1-based) the observer does
            not know (:mod:`phdesign.symbolic.disturbances`).
        performance : sequence of str, optional
            Outputs such as ``"integral(e1)"``, ``"e1(1)"``, ``"w(1)"``.
        """
        if not isinstance(order, int) or isinstance(order, bool) or order < 1:
            raise ModelError(f"order must be an integer N >= 1; found {order!r}")
        names, defaults = parse_parameters(parameters, order, H)
        endpoints = parse_interval(interval)
        H_matrix = parse_matrix(H, "H", names, allow_z=True)
        size = H_matrix.shape[0]
        P_matrices = parse_P(P, order, size, names)
        ins, outs, derived = parse_ports(inputs, outputs, endpoints, order, size, names)
        return cls(
            name=name,
            interval=endpoints,
            order=order,
            size=size,
            P=P_matrices,
            H=H_matrix,
            parameters=defaults,
            inputs=ins,
            outputs=outs,
            state_names=tuple(state_names),
            description=description,
            displacement=displacement,
            feedback=None if feedback is None else feedback_from_mapping(feedback, names),
            units=parse_units(units),
            derived_outputs=derived,
            fields=_named_fields(fields),
            boundary_systems=boundary_systems_from_value(boundary_systems, names),
            disturbances=None
            if disturbances is None
            else disturbances_from_mapping(disturbances, size, names),
            performance=parse_performance(
                performance,
                endpoints,
                order,
                size,
                names,
                (("w",) if displacement is not None else ()) + tuple(fields or ()),
            ),
        )

    # ------------------------------------------------------------------ views
    @cached_property
    def ports(self) -> Ports:
        """The boundary port structure (:func:`~phdesign.symbolic.ports.derive_ports`), cached."""
        return derive_ports(self)

    @cached_property
    def closed_ports(self) -> ClosedPorts | None:
        """The ports closed by :attr:`feedback` (:func:`~phdesign.symbolic.closing.closed_ports`).

        ``None`` for a model without feedback.
        """
        return None if self.feedback is None else closed_ports(self)

    @property
    def n_ports(self) -> int:
        """Number of external inputs (= outputs).

        ``N n`` less those closed by :attr:`feedback` or joined to a boundary system, and
        then the boundary systems' own external inputs.
        """
        extra = sum(bs.n_external for bs in self.boundary_systems)
        return len(self.external_inputs) + extra

    @property
    def external_inputs(self) -> tuple[sympy.Expr, ...]:
        """The trace inputs left open by :attr:`feedback` and the boundary systems."""
        return tuple(self.inputs[j] for j in self._open_indices)

    @property
    def external_outputs(self) -> tuple[sympy.Expr, ...]:
        """The outputs conjugate to :attr:`external_inputs`."""
        return tuple(self.outputs[j] for j in self._open_indices)

    @property
    def _open_indices(self) -> tuple[int, ...]:
        joined = set(coupled_indices(self))
        kept = external_indices(len(self.inputs), self.feedback)
        return tuple(j for j in kept if j not in joined)

    @property
    def unit_map(self) -> dict[str, str]:
        """The stated units, keyed by quantity."""
        return dict(self.units)

    @property
    def parameter_defaults(self) -> dict[sympy.Symbol, sympy.Expr]:
        """The parameters' default values, keyed by symbol."""
        return dict(self.parameters)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """The parameters' names, in declaration order."""
        return tuple(symbol.name for symbol, _ in self.parameters)

    def with_parameters(self, values: Mapping[str, object]) -> BCPHS:
        """Return the same model with new default values for some parameters.

        Raises
        ------
        ParameterError
            If a name is not a parameter of the model or a value is not a finite number.
        """
        if not isinstance(values, Mapping):
            raise ParameterError(
                f"expected a mapping of parameter names to values; found {values!r}"
            )
        known = self.parameter_names
        updated = dict(self.parameters)
        for name, value in values.items():
            if name not in known:
                raise ParameterError(
                    f"unknown parameter {name!r}{did_you_mean(name, known)}; the model's "
                    f"parameters are {', '.join(known) if known else 'none'}"
                )
            try:
                updated[parameter_symbol(name)] = exact_number(value, f"parameter {name}")
            except ExpressionError as error:
                raise ParameterError(str(error)) from None
        return replace(self, parameters=tuple(updated.items()))


def _named_fields(fields: Mapping[str, Field] | None) -> tuple[tuple[str, Field], ...]:
    """Return the named fields as ``(name, field)`` pairs (checked by the validation)."""
    if fields is None:
        return ()
    if not isinstance(fields, Mapping):
        raise ModelError(
            f"fields must be a mapping {{name: Field}}; found {type(fields).__name__} {fields!r}"
        )
    return tuple(fields.items())
