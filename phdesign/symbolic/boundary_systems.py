r"""Boundary systems: finite-dimensional port-Hamiltonian systems joined to the PDE's ports.

A boundary system (a tip mass, a rigid hub, a spring, a DC motor) is

.. math::

    \dot x_c = (J_c - R_c) Q_c x_c + G_c u_c + B_c w, \qquad
    y_c = G_c^\top Q_c x_c + D_c u_c, \qquad z_c = B_c^\top Q_c x_c, \qquad
    H_c = \tfrac12 x_c^\top Q_c x_c,

with :math:`J_c = -J_c^\top`, :math:`R_c = R_c^\top \succeq 0`,
:math:`Q_c = Q_c^\top \succ 0` and :math:`D_c + D_c^\top \succeq 0` (entries: numbers or
expressions in the model's parameters).  Its coupling port :math:`(u_c, y_c)` is joined to
``m`` of the PDE's inputs :math:`u_p` (``ports``, 1-based into ``[ports].inputs``) and their
conjugate outputs :math:`y_p` by a power-preserving interconnection: the gyrator
:math:`u_p = -y_c`, :math:`u_c = y_p`, or a skew matrix :math:`S = -S^\top`,

.. math::

    \begin{pmatrix} u_p \\ u_c \end{pmatrix} = S \begin{pmatrix} y_p \\ y_c \end{pmatrix},
    \qquad u_p^\top y_p + u_c^\top y_c = 0 ;

the gyrator is :math:`S = \left(\begin{smallmatrix} 0 & -I \\ I & 0
\end{smallmatrix}\right)`.  Its own inputs :math:`w` (a force on the mass, a motor's
voltage) and their conjugate outputs :math:`z_c` join the coupled system's external ports.
Solving the interconnection (with :math:`S_{cc} D_c = 0`, so that it has no algebraic loop)
gives, with :math:`e_c = Q_c x_c`,

.. math::

    u_c = S_{cp} y_p + S_{cc} G_c^\top e_c, \qquad
    u_p = -K y_p + S_{pc} G_c^\top e_c, \qquad K = -(S_{pp} + S_{pc} D_c S_{cp}),

so :math:`K + K^\top = S_{cp}^\top (D_c + D_c^\top) S_{cp} \succeq 0` and the coupled system
is again a boundary-controlled port-Hamiltonian system with energy
:math:`\mathcal E + H_c` and

.. math::

    \frac{d}{dt}(\mathcal E + H_c) = \tfrac12 \int_a^b e^\top (P_0 + P_0^\top) e\,dz
    - e_c^\top R_c e_c - u_c^\top D_c u_c - y_f^\top K_f y_f + u_{ext}^\top y_{ext},

the last terms the ``[feedback]`` dampers and the remaining external ports.  The boundary
part of this identity, :math:`u_p^\top y_p + \dot H_c = -e_c^\top R_c e_c - u_c^\top D_c
u_c + w^\top z_c`, is derived and checked exactly when the model is built
(:func:`phdesign.symbolic.boundary_checks.check_boundary_systems`).

Examples
--------
A tip mass ``m`` with a damper ``c`` on a string's velocity port (x_c = momentum):

>>> mass = boundary_system_from_mapping(
...     {"name": "mass", "ports": [2], "J": [[0]], "R": [["c"]], "Q": [["1/m"]],
...      "G": [[-1]], "B": [[1]]}, ["m", "c"])
>>> mass.size, mass.joined, mass.n_external
(1, (1,), 1)
>>> coupling(mass).K, coupling(mass).to_pde
(Matrix([[0]]), Matrix([[1]]))
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import sympy

from phdesign.core.errors import ModelError
from phdesign.symbolic.definition import parse_matrix
from phdesign.symbolic.expressions import canonical
from phdesign.symbolic.printing import format_expression

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.symbolic.model import BCPHS

__all__ = [
    "KEYS",
    "BoundarySystem",
    "Coupling",
    "boundary_system_from_mapping",
    "boundary_system_to_dict",
    "boundary_systems_from_value",
    "close_boundary_inputs",
    "coupled_indices",
    "coupling",
    "external_input_labels",
    "split_actuated",
]

#: The keys of one ``[[boundary_systems]]`` table (and of the mapping ``define`` reads).
KEYS = (
    "name",
    "ports",
    "states",
    "J",
    "R",
    "Q",
    "G",
    "D",
    "B",
    "inputs",
    "outputs",
    "interconnection",
)
_REQUIRED = ("ports", "J", "R", "Q", "G")


@dataclass(frozen=True)
class BoundarySystem:
    r"""One boundary system :math:`\dot x_c = (J_c - R_c) Q_c x_c + G_c u_c + B_c w`.

    Parameters
    ----------
    name : str
        A label (``"mass"``), unique in the model; its states and external ports are
        named after it.
    ports : tuple of int
        1-based indices into the model's ``[ports].inputs`` joined to the coupling port
        (with their conjugate outputs).
    J, R, Q : sympy.ImmutableMatrix
        :math:`J_c` (skew), :math:`R_c \succeq 0`, :math:`Q_c \succ 0`, ``k x k``.
    G : sympy.ImmutableMatrix
        :math:`G_c`, ``k x m`` (``m = len(ports)``).
    D : sympy.ImmutableMatrix or None
        :math:`D_c`, ``m x m`` with :math:`D_c + D_c^\top \succeq 0`; None: zero.
    B : sympy.ImmutableMatrix or None
        :math:`B_c`, ``k x r``: the directions of the external inputs w; None: none.
    interconnection : sympy.ImmutableMatrix or None
        :math:`S`, ``2m x 2m``, skew; None: the gyrator.
    states : tuple of str
        Labels of the ``k`` states (default ``<name>.x1`` ...).
    inputs : tuple of str
        Labels of the ``r`` external inputs (default ``<name>.w1`` ...).
    outputs : tuple of str
        Labels of their conjugate outputs :math:`z_c` (default ``<name>.z1`` ...).
    """

    name: str
    ports: tuple[int, ...]
    J: sympy.ImmutableMatrix
    R: sympy.ImmutableMatrix
    Q: sympy.ImmutableMatrix
    G: sympy.ImmutableMatrix
    D: sympy.ImmutableMatrix | None = None
    B: sympy.ImmutableMatrix | None = None
    interconnection: sympy.ImmutableMatrix | None = None
    states: tuple[str, ...] = ()
    inputs: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()

    @property
    def size(self) -> int:
        """The number ``k`` of states."""
        return int(self.Q.shape[0])

    @property
    def joined(self) -> tuple[int, ...]:
        """0-based indices of the PDE inputs joined to the coupling port."""
        return tuple(i - 1 for i in self.ports)

    @property
    def n_external(self) -> int:
        """The number ``r`` of external inputs w."""
        return 0 if self.B is None else int(self.B.shape[1])

    @property
    def state_labels(self) -> tuple[str, ...]:
        """The states' labels: ``states``, or ``<name>.x1`` ..."""
        return self.states or tuple(f"{self.name}.x{i + 1}" for i in range(self.size))

    @property
    def input_labels(self) -> tuple[str, ...]:
        """The external inputs' labels: ``inputs``, or ``<name>.w1`` ..."""
        return self.inputs or tuple(f"{self.name}.w{j + 1}" for j in range(self.n_external))

    @property
    def output_labels(self) -> tuple[str, ...]:
        """The conjugate outputs' labels: ``outputs``, or ``<name>.z1`` ..."""
        return self.outputs or tuple(f"{self.name}.z{j + 1}" for j in range(self.n_external))

    @property
    def feedthrough(self) -> sympy.ImmutableMatrix:
        """:math:`D_c` (zero when not given)."""
        m = len(self.ports)
        return sympy.ImmutableMatrix.zeros(m, m) if self.D is None else self.D

    @property
    def external(self) -> sympy.ImmutableMatrix:
        """:math:`B_c` (``k x 0`` when not given)."""
        return sympy.ImmutableMatrix.zeros(self.size, 0) if self.B is None else self.B

    @property
    def S(self) -> sympy.ImmutableMatrix:
        """The interconnection matrix (the gyrator when none was given)."""
        if self.interconnection is not None:
            return self.interconnection
        m = len(self.ports)
        eye, zero = sympy.eye(m), sympy.zeros(m, m)
        return sympy.ImmutableMatrix(sympy.BlockMatrix([[zero, -eye], [eye, zero]]).as_explicit())


@dataclass(frozen=True)
class Coupling:
    r"""The interconnection solved: what the PDE and the boundary system see of each other.

    .. math::

        u_p = -K y_p + F e_c, \qquad
        Q_c^{-1} \dot e_c = (J_{eff} - R_c) e_c + G_c S_{cp} y_p + B_c w,

    with ``to_pde`` :math:`F = S_{pc} G_c^\top`, ``from_pde`` :math:`G_c S_{cp} = -F^\top`,
    ``J_eff`` :math:`= J_c + G_c S_{cc} G_c^\top` (skew) and ``u_c`` the map
    :math:`(y_p, e_c) \mapsto u_c`.
    """

    K: sympy.ImmutableMatrix
    to_pde: sympy.ImmutableMatrix
    from_pde: sympy.ImmutableMatrix
    J_eff: sympy.ImmutableMatrix
    u_c: tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]


def coupling(bs: BoundarySystem) -> Coupling:
    """Solve the interconnection of ``bs`` (module docstring; needs :math:`S_{cc} D_c = 0`)."""
    m = len(bs.ports)
    S = sympy.Matrix(bs.S)
    S_pp, S_pc, S_cp, S_cc = S[:m, :m], S[:m, m:], S[m:, :m], S[m:, m:]
    D, G = sympy.Matrix(bs.feedthrough), sympy.Matrix(bs.G)
    K = -(S_pp + S_pc * D * S_cp)
    return Coupling(
        K=sympy.ImmutableMatrix(K.applyfunc(canonical)),
        to_pde=sympy.ImmutableMatrix(S_pc * G.T),
        from_pde=sympy.ImmutableMatrix(G * S_cp),
        J_eff=sympy.ImmutableMatrix((sympy.Matrix(bs.J) + G * S_cc * G.T).applyfunc(canonical)),
        u_c=(sympy.ImmutableMatrix(S_cp), sympy.ImmutableMatrix(S_cc * G.T)),
    )


def coupled_indices(model: BCPHS) -> tuple[int, ...]:
    """0-based indices of every PDE input joined to a boundary system, in order."""
    return tuple(j for bs in model.boundary_systems for j in bs.joined)


# ---------------------------------------------------------------------- reading
def boundary_system_from_mapping(
    value: BoundarySystem | Mapping[str, Any], parameters: Sequence[str], position: int = 1
) -> BoundarySystem:
    """Read one ``[[boundary_systems]]`` table (or a mapping from code) exactly.

    Raises
    ------
    ModelError
        Naming the boundary system and the key: unknown or missing keys, entries that are
        not numbers or expressions in the parameters, ports that are not 1-based integers.
    """
    if isinstance(value, BoundarySystem):
        return value
    where = f"boundary_systems[{position}]"
    if not isinstance(value, Mapping):
        raise ModelError(f"{where} must be a table; found {type(value).__name__} {value!r}")
    unknown = sorted(set(map(str, value)) - set(KEYS))
    missing = [key for key in _REQUIRED if key not in value]
    if unknown or missing:
        raise ModelError(
            f"{where}: expected the keys {', '.join(_REQUIRED)} (and optionally name, states, "
            f"D, B, inputs, outputs, interconnection); found unknown {unknown or 'none'}, "
            f"missing {missing or 'none'}"
        )
    name = value.get("name", f"boundary system {position}")
    if not isinstance(name, str) or not name.strip():
        raise ModelError(f"{where}: name must be non-empty text; found {name!r}")
    label = f"boundary system {name!r}"

    def matrix(key: str, square: bool) -> sympy.ImmutableMatrix | None:
        if key not in value:
            return None
        return parse_matrix(value[key], f"{label} {key}", parameters, square=square)

    S = value.get("interconnection", "gyrator")
    return BoundarySystem(
        name=name,
        ports=_indices(value["ports"], f"{label} ports"),
        J=matrix("J", True),
        R=matrix("R", True),
        Q=matrix("Q", True),
        G=matrix("G", False),
        D=matrix("D", True),
        B=matrix("B", False),
        interconnection=None if S == "gyrator" else matrix("interconnection", True),
        states=_labels(value.get("states", ()), f"{label} states"),
        inputs=_labels(value.get("inputs", ()), f"{label} inputs"),
        outputs=_labels(value.get("outputs", ()), f"{label} outputs"),
    )


def boundary_systems_from_value(
    value: Sequence[BoundarySystem | Mapping[str, Any]] | None, parameters: Sequence[str]
) -> tuple[BoundarySystem, ...]:
    """Read ``define``'s ``boundary_systems`` (a list of tables or of :class:`BoundarySystem`)."""
    if value is None:
        return ()
    if isinstance(value, str | Mapping | BoundarySystem) or not isinstance(value, Sequence):
        raise ModelError(
            "boundary_systems must be a list of boundary systems (tables); found "
            f"{type(value).__name__}"
        )
    return tuple(
        boundary_system_from_mapping(v, parameters, i) for i, v in enumerate(value, start=1)
    )


def _indices(value: object, what: str) -> tuple[int, ...]:
    if isinstance(value, str) or not isinstance(value, Sequence) or not value:
        raise ModelError(
            f"{what} must be a non-empty list of 1-based input indices; found {value!r}"
        )
    for index in value:
        if isinstance(index, bool) or not isinstance(index, int):
            raise ModelError(f"{what} must hold 1-based input indices; found {index!r}")
    return tuple(value)


def _labels(value: object, what: str) -> tuple[str, ...]:
    if isinstance(value, str) or not isinstance(value, Sequence):
        raise ModelError(f"{what} must be a list of names; found {value!r}")
    if not all(isinstance(v, str) and v.strip() for v in value):
        raise ModelError(f"{what} must be a list of non-empty names; found {list(value)!r}")
    return tuple(value)


def boundary_system_to_dict(
    bs: BoundarySystem, rows: Callable[[sympy.MatrixBase], list[list[Any]]]
) -> dict[str, Any]:
    """Return the ``[[boundary_systems]]`` table of ``bs`` (``rows`` writes a matrix's entries).

    Optional keys are written only when they were given, so that the table reads back as
    the same boundary system.
    """
    table: dict[str, Any] = {"name": bs.name, "ports": list(bs.ports)}
    if bs.states:
        table["states"] = list(bs.states)
    for key in ("J", "R", "Q", "G", "D", "B"):
        matrix = getattr(bs, key)
        if matrix is not None:
            table[key] = rows(matrix)
    if bs.inputs:
        table["inputs"] = list(bs.inputs)
    if bs.outputs:
        table["outputs"] = list(bs.outputs)
    if bs.interconnection is not None:
        table["interconnection"] = rows(bs.interconnection)
    return table


def external_input_labels(model: BCPHS) -> tuple[str, ...]:
    """Name every external input: the PDE's open traces, then the boundary systems' own."""
    traces = (format_expression(u, model.interval) for u in model.external_inputs)
    return (*traces, *(label for bs in model.boundary_systems for label in bs.input_labels))


def split_actuated(
    model: BCPHS, actuate: Sequence[int], K: sympy.MatrixBase
) -> tuple[list[int], sympy.Matrix, list[int], sympy.Matrix]:
    """Split actuated inputs (1-based external) into the PDE's and the boundary systems' own.

    Returns the trace inputs with their block of K, and the boundary inputs (0-based among
    the boundary systems' inputs) with theirs.

    Raises
    ------
    ModelError
        If K couples an actuated trace input with a boundary system's input.
    """
    t = len(model.external_inputs)
    rows = [i for i, a in enumerate(actuate) if a <= t]
    others = [i for i, a in enumerate(actuate) if a > t]
    K = sympy.Matrix(K)
    if not K.extract(rows, others).is_zero_matrix or not K.extract(others, rows).is_zero_matrix:
        raise ModelError(
            "feedback K couples a trace input with a boundary system's input; expected K "
            "block-diagonal between the two"
        )
    return (
        [actuate[i] for i in rows],
        K.extract(rows, rows),
        [actuate[i] - t - 1 for i in others],
        K.extract(others, others),
    )


def close_boundary_inputs(model: BCPHS, positions: Sequence[int], K: sympy.MatrixBase) -> BCPHS:
    r"""Close boundary systems' own inputs with :math:`w_a = -K z_a`; return the new model.

    ``positions`` are 0-based among all the boundary systems' inputs.  Inside a system
    :math:`\dot x_c = (J_c - R_c)Q_c x_c + \dots + B_a w_a` with :math:`z_a = B_a^	op Q_c x_c`
    the loop gives :math:`J_c - B_a \operatorname{skew}(K) B_a^	op` and
    :math:`R_c + B_a \operatorname{sym}(K) B_a^	op` (a motor's voltage fed back its current:
    more resistance).  K must not couple two systems.
    """
    K = sympy.Matrix(K)
    systems, start = [], 0
    for bs in model.boundary_systems:
        mine = [p - start for p in positions if start <= p < start + bs.n_external]
        rows = [i for i, p in enumerate(positions) if start <= p < start + bs.n_external]
        start += bs.n_external
        if not mine:
            systems.append(bs)
            continue
        other = [i for i in range(len(positions)) if i not in rows]
        if not K.extract(rows, other).is_zero_matrix:
            raise ModelError("feedback K couples the inputs of two boundary systems")
        Ks, B = K.extract(rows, rows), sympy.Matrix(bs.external)
        B_a = B.extract(list(range(bs.size)), mine)
        keep = [j for j in range(bs.n_external) if j not in mine]
        systems.append(
            replace(
                bs,
                J=sympy.ImmutableMatrix(sympy.Matrix(bs.J) - B_a * (Ks - Ks.T) / 2 * B_a.T),
                R=sympy.ImmutableMatrix(sympy.Matrix(bs.R) + B_a * (Ks + Ks.T) / 2 * B_a.T),
                B=sympy.ImmutableMatrix(B.extract(list(range(bs.size)), keep)) if keep else None,
                inputs=tuple(bs.inputs[j] for j in keep) if bs.inputs else (),
                outputs=tuple(bs.outputs[j] for j in keep) if bs.outputs else (),
            )
        )
    return replace(model, boundary_systems=tuple(systems))
