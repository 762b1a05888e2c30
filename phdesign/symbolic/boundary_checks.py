r"""The exact checks of a model's boundary systems, run once when the model is built.

For each boundary system (:mod:`phdesign.symbolic.boundary_systems`): its ports, the
shapes of its matrices, :math:`J_c = -J_c^\top` and :math:`S = -S^\top` exactly,
:math:`Q_c \succ 0`, :math:`R_c \succeq 0` and :math:`D_c + D_c^\top \succeq 0` exactly
(:mod:`phdesign.symbolic.definiteness`, whose failures name the matrix and the failing
minor), and the coupled energy identity, derived with symbols and checked exactly.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import sympy

from phdesign.core.errors import ModelError
from phdesign.symbolic.boundary_systems import BoundarySystem, coupling
from phdesign.symbolic.definiteness import check_definite
from phdesign.symbolic.expressions import Z, canonical, vanishes
from phdesign.symbolic.feedback import check_input_index
from phdesign.symbolic.validation import check_finite, check_symbols

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.symbolic.model import BCPHS

__all__ = ["check_boundary_systems"]

#: Labels a boundary system may not take: what x0, input and disturbance texts already name.
RESERVED_LABEL = re.compile(r"[xeuyw]\d+|z|t")


def check_boundary_systems(model: BCPHS) -> list[str]:
    r"""Validate every boundary system of ``model``; return how each condition was checked.

    Ports: distinct inputs of the model, joined to one system at most and not closed by
    ``[feedback]``; shapes; entries constant in z, in the parameters, finite at the
    defaults; :math:`J_c` and :math:`S` skew exactly; :math:`Q_c \succ 0`,
    :math:`R_c \succeq 0`, :math:`D_c + D_c^\top \succeq 0` exactly
    (:mod:`phdesign.symbolic.definiteness`: a failure names the matrix and the failing
    minor); and the coupled energy identity, derived and checked exactly.

    Raises
    ------
    ModelError
        Naming the boundary system, the matrix and what was found.
    """
    checks: list[str] = []
    taken = dict.fromkeys(model.feedback.inputs if model.feedback else (), "[feedback]")
    names: set[str] = set()
    for bs in model.boundary_systems:
        label = f"boundary system {bs.name!r}"
        if bs.name in names:
            raise ModelError(f"{label} is named twice; expected distinct names")
        names.add(bs.name)
        _check_ports(bs, label, model.order * model.size, taken)
        _check_shapes(bs, label, model.size)
        checks += _check_matrices(bs, label, model)
        checks.append(_check_identity(bs, label))
    labels = [
        x
        for bs in model.boundary_systems
        for x in (*bs.state_labels, *bs.input_labels, *bs.output_labels)
    ]
    repeated = sorted(
        {x for x in labels if labels.count(x) > 1} | (set(labels) & set(model.state_names))
    )
    if repeated:
        raise ModelError(
            f"boundary systems: the labels {', '.join(repeated)} are used twice; expected "
            "distinct state and input names"
        )
    reserved = sorted(x for x in set(labels) if RESERVED_LABEL.fullmatch(x))
    if reserved:
        raise ModelError(
            f"boundary systems: the label {reserved[0]!r} is a name phdesign reads already "
            "(x<i> and e<i> are the field's states and efforts, u<j>, y<j>, w<j> the ports and "
            "disturbances, z and t the variables: an x0 or input text would be ambiguous); "
            "expected another name, such as 'mass momentum'"
        )
    return checks


def _check_ports(bs: BoundarySystem, label: str, n_inputs: int, taken: dict[int, str]) -> None:
    for position, index in enumerate(bs.ports, start=1):
        check_input_index(f"{label} ports[{position}]", index, n_inputs)
        if index in taken:
            raise ModelError(
                f"{label} ports[{position}] = {index} is already closed by {taken[index]}; "
                "expected an input joined to one boundary system or feedback at most"
            )
        taken[index] = label


def _check_shapes(bs: BoundarySystem, label: str, n: int) -> None:
    k, m = bs.size, len(bs.ports)
    expected = {"J": (k, k), "R": (k, k), "Q": (k, k), "G": (k, m), "D": (m, m)}
    expected.update({"interconnection": (2 * m, 2 * m)})
    for key, shape in expected.items():
        matrix = getattr(bs, key)
        if matrix is not None and matrix.shape != shape:
            raise ModelError(
                f"Incompatible dimensions of {label} {key} matrix; expected {shape} but found "
                f"{matrix.shape} (k = {k} states, m = {m} joined ports)"
            )
    if bs.B is not None and bs.B.rows != k:
        raise ModelError(
            f"Incompatible dimensions of {label} B matrix; expected {k} rows (one per state) "
            f"but found {bs.B.shape}"
        )
    r = bs.n_external
    for key, labels, count in (
        ("states", bs.states, k),
        ("inputs", bs.inputs, r),
        ("outputs", bs.outputs, r),
    ):
        if labels and len(labels) != count:
            raise ModelError(f"{label} {key} must hold {count} names; found {len(labels)}")
    del n


def _check_matrices(bs: BoundarySystem, label: str, model: BCPHS) -> list[str]:
    symbols = {s for s, _ in model.parameters}
    defaults = model.parameter_defaults
    for key in ("J", "R", "Q", "G", "D", "B", "interconnection"):
        matrix = getattr(bs, key)
        if matrix is None:
            continue
        check_symbols(matrix, f"{label} {key}", symbols)
        check_finite(matrix, f"{label} {key}", defaults)
    _require_skew(bs.J, f"{label} J", "J_c")
    _require_skew(bs.S, f"{label} interconnection", "S")
    for key, matrix in (("R", bs.R), ("Q", bs.Q)):
        residual = (matrix - matrix.T).applyfunc(canonical)
        if not all(vanishes(x) for x in residual):
            raise ModelError(
                f"{label} {key} must be symmetric; found {key} - {key}^T = {residual.tolist()}"
            )
    m = len(bs.ports)
    if bs.D is not None and any(bs.D) and not bs.S[m:, m:].is_zero_matrix:
        raise ModelError(
            f"{label}: a feedthrough D with an interconnection that feeds y_c back into u_c "
            "(S_cc != 0) is an algebraic loop; expected S_cc = 0 or D = 0"
        )
    D = bs.feedthrough
    checks = []
    for matrix, name, strict in (
        (bs.Q, "Q_c", True),
        (bs.R, "R_c", False),
        (D + D.T, "D_c + D_c^T", False),
    ):
        try:
            how = check_definite(matrix, name, model.interval, defaults, strict=strict)
        except ModelError as error:
            raise ModelError(f"{label} {error}") from None
        checks.append(f"{label} {how}")
    return [*checks, f"{label} J_c and S skew: exact"]


def _require_skew(matrix: sympy.ImmutableMatrix, where: str, symbol: str) -> None:
    residual = (matrix + matrix.T).applyfunc(canonical)
    if not all(vanishes(x) for x in residual):
        raise ModelError(
            f"{where} must be skew ({symbol} = -{symbol}^T: power-preserving); found "
            f"{symbol} + {symbol}^T = {residual.tolist()}"
        )
    if Z in matrix.free_symbols:  # pragma: no cover - check_symbols refuses z first
        raise ModelError(f"{where} must not depend on z")


def _check_identity(bs: BoundarySystem, label: str) -> str:
    r"""Derive the boundary power balance with symbols and check it exactly.

    With free :math:`y_p`, :math:`e_c` and :math:`w`:
    :math:`u_p^\top y_p + e_c^\top \dot x_c = -e_c^\top R_c e_c - u_c^\top D_c u_c + w^\top z_c`.
    """
    m, k, r = len(bs.ports), bs.size, bs.n_external
    y_p = sympy.Matrix(sympy.symbols(f"y_p1:{m + 1}"))
    e_c = sympy.Matrix(sympy.symbols(f"e_c1:{k + 1}"))
    w = sympy.Matrix(sympy.symbols(f"w1:{r + 1}")) if r else sympy.zeros(0, 1)
    c = coupling(bs)
    u_c = c.u_c[0] * y_p + c.u_c[1] * e_c
    u_p = -c.K * y_p + c.to_pde * e_c
    J, R, G, B, D = (sympy.Matrix(x) for x in (bs.J, bs.R, bs.G, bs.external, bs.feedthrough))
    # the two parts' own balances, with the interconnection's u_p and u_c
    x_dot = (J - R) * e_c + G * u_c + B * w
    y_c = G.T * e_c + D * u_c
    power = (u_p.T * y_p + e_c.T * x_dot)[0, 0]
    claimed = (-e_c.T * R * e_c - u_c.T * D * u_c + w.T * B.T * e_c)[0, 0]
    residual = sympy.expand(power - claimed)
    lossless = sympy.expand((u_p.T * y_p + u_c.T * y_c)[0, 0])
    if not (vanishes(residual) and vanishes(lossless)):
        raise ModelError(
            f"{label}: the interconnection is not power-preserving: u_p^T y_p + u_c^T y_c = "
            f"{lossless}; expected 0"
        )
    identity = "u_p^T y_p + dH_c/dt = -e_c^T R_c e_c - u_c^T D_c u_c + w^T z_c"
    return f"{label} energy identity {identity}: exact"
