r"""Closing inputs with boundary feedback: the closed plant's ports and the error's boundary.

A model's ``[feedback]`` (:mod:`phdesign.symbolic.feedback`) closes the inputs
:math:`u_c` with :math:`u_c = -K y_c`, :math:`K + K^\top \succeq 0`, and leaves the other
inputs :math:`u_r` as the plant's external inputs; :func:`close_inputs` closes more of
them (a damper, or a controller's :math:`u_{act} = -K y_{act}`).  Over the trace vector
:math:`v` (:mod:`phdesign.symbolic.ports`), with :math:`u = U v`, :math:`y = Y v` split
into rows :math:`c` and :math:`r`, the closed plant is the same PDE with

* the homogeneous boundary condition :math:`(U_c + K Y_c)\, v = 0`,
* the external input :math:`u_r = U_r v` and output :math:`y_r = Y_r v`.

In boundary port variables (:math:`W_B`, :math:`W_C` of the open plant, which satisfy
the three identities of the paper) the closed plant has the boundary operator and output

.. math::

    W_B' = \begin{pmatrix} W_{B,c} + K W_{C,c} \\ W_{B,r} \end{pmatrix}, \qquad
    W_C' = W_{C,r},

and the identities of the open plant become (direct expansion, using
:math:`W_B\Sigma W_B^\top = 0`, :math:`W_C\Sigma W_C^\top = 0`,
:math:`W_C\Sigma W_B^\top = I`)

.. math::

    W_B' \Sigma W_B'^\top = \begin{pmatrix} K + K^\top & 0 \\ 0 & 0 \end{pmatrix}
    \succeq 0, \qquad
    W_C' \Sigma W_B'^\top = \begin{pmatrix} 0 & I \end{pmatrix}, \qquad
    W_C' \Sigma W_C'^\top = 0 .

The first is the dissipative boundary of Le Gorrec, Zwart and Maschke (*Dirac structures
and boundary control systems associated with skew-symmetric differential operators*, SIAM
J. Control Optim. 44(5), 1864-1892, 2005): for the skew-symmetric operator
:math:`\sum_k P_k \partial_z^k \mathcal H` of any order N with a full-rank boundary
operator, :math:`u_r = 0` gives a contraction semigroup iff
:math:`W_B'\Sigma W_B'^\top \succeq 0` (a dissipative :math:`P_0`,
:math:`P_0 + P_0^\top \preceq 0`, keeps it one); the other two say that :math:`y_r` is still
power conjugate to :math:`u_r` and blind to the closed condition.  On the admissible
traces the power is :math:`u^\top y = u_r^\top y_r + u_c^\top y_c`, so the energy balance
of the closed plant is

.. math::

    \dot H = \tfrac12 \int_a^b e^\top (P_0 + P_0^\top) e\, dz
             - y_c^\top \operatorname{sym}(K)\, y_c + u_r^\top y_r .

:class:`ClosedPorts` exposes these matrices, checked exactly when the model is built.

The observer copies the closed plant (its own boundary condition :math:`\hat u_c = -K
\hat y_c`) and corrects the external inputs, :math:`\hat u_r = u_r + C_m^\top L (y_m -
\hat y_m)` with :math:`y_m = C_m y_r`.  The error :math:`\tilde x = x - \hat x` then
satisfies, over all :math:`Nn` open ports, :math:`\tilde u = -G \tilde y` with

.. math::

    G = E_c^\top K E_c + E_r^\top C_m^\top L C_m E_r ,
    \qquad
    \dot{\tilde H} \le -\tilde y_c^\top \operatorname{sym}(K) \tilde y_c
                      - \tfrac12 \tilde y_m^\top (L + L^\top) \tilde y_m ,

(:math:`E_c`, :math:`E_r` the selections of the closed and external rows), so the
left-hand side of every proposition is
:math:`\tfrac12 \tilde y_m^\top (L + L^\top)\tilde y_m + \tilde y_c^\top
\operatorname{sym}(K)\tilde y_c`: the plant's own dampers are part of the error
system's boundary.  :func:`error_dissipation` returns :math:`G` and a factorization of
that quadratic form for :mod:`phdesign.symbolic.certificate`.

Examples
--------
>>> from phdesign.models import load_builtin
>>> string = load_builtin("wave-damper")     # u2 = -k y2: e2(1) = -k e1(1)
>>> closed = closed_ports(string)
>>> closed.boundary_conditions()
('e1(1)*k + e2(1) = 0',)
>>> closed.identities["WB_Sigma_WBt_minus_dissipation"]
0
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import sympy

from phdesign.core.errors import ModelError, PortError
from phdesign.core.text import html_table
from phdesign.symbolic.definition import parse_matrix
from phdesign.symbolic.expressions import canonical, vanishes
from phdesign.symbolic.feedback import Feedback, external_indices
from phdesign.symbolic.ports import derive_ports, sigma_matrix
from phdesign.symbolic.printing import format_expression
from phdesign.symbolic.system import PortedSystem

if TYPE_CHECKING:  # pragma: no cover - typing only
    from phdesign.symbolic.model import BCPHS

__all__ = [
    "CLOSED_IDENTITY_NAMES",
    "ClosedPorts",
    "close_inputs",
    "closed_ports",
    "error_dissipation",
    "plant_feedback",
    "psd_factor",
]

#: Keys of :attr:`ClosedPorts.identities`.
CLOSED_IDENTITY_NAMES = (
    "WB_Sigma_WBt_minus_dissipation",
    "WC_Sigma_WBt_minus_E",
    "WC_Sigma_WCt",
)


def _require_model(model: object) -> None:
    """Refuse what is not a model (the model module sits above this one: no BCPHS here)."""
    if not isinstance(model, PortedSystem):
        raise ModelError(f"model must be a BCPHS; found {type(model).__name__} {model!r}")


def close_inputs(model: BCPHS, inputs: Sequence[int], gain: Any) -> BCPHS:
    r"""Close external inputs of ``model`` with :math:`u_c = -K y_c`; return the new model.

    The reusable entry point for any static collocated boundary feedback (a damper in the
    model file, or a controller's :math:`u_{act} = -K y_{act}`).  ``inputs`` are 1-based
    indices into the model's *external* inputs (:attr:`BCPHS.external_inputs`); when the
    model already has a feedback the two are combined, block-diagonally.

    Parameters
    ----------
    model : BCPHS
    inputs : sequence of int
        Which external inputs to close.
    gain : matrix
        :math:`K` (numbers or expressions in the model's parameters), with
        :math:`K + K^\top \succeq 0` (checked, with the other conditions, on the new model).

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> damped = close_inputs(load_builtin("wave"), [2], [["1/2"]])
    >>> damped.feedback.inputs, damped.n_ports
    ((2,), 1)
    """
    _require_model(model)
    nn = model.order * model.size
    joined = {j for bs in model.boundary_systems for j in bs.joined}
    external = [j for j in external_indices(nn, model.feedback) if j not in joined]
    picked = list(inputs)
    for position, index in enumerate(picked, start=1):
        if isinstance(index, bool) or not isinstance(index, int):
            raise ModelError(f"inputs[{position}] must be a 1-based index; found {index!r}")
        if not 1 <= index <= len(external):
            raise ModelError(
                f"inputs[{position}] = {index} is not an external input of the model; "
                f"expected an index in 1..{len(external)}"
            )
    K_new = parse_matrix(gain, "feedback gain K", model.parameter_names)
    new_inputs = tuple(external[i - 1] + 1 for i in picked)
    if model.feedback is None:
        feedback = Feedback(new_inputs, K_new)
    else:
        old = model.feedback
        K = sympy.diag(old.gain, K_new) if K_new.shape[0] else old.gain
        feedback = Feedback(old.inputs + new_inputs, sympy.ImmutableMatrix(K))
    return replace(model, feedback=feedback)


@dataclass(frozen=True)
class ClosedPorts:
    r"""The port structure of a plant with boundary feedback (module docstring).

    Attributes
    ----------
    closed, external : tuple of int
        0-based indices of the closed and of the external open ports.
    gain : sympy.ImmutableMatrix
        :math:`K`.
    boundary : sympy.ImmutableMatrix
        :math:`U_c + K Y_c` (``c x 2Nn``): the closed boundary condition is
        ``boundary * v = 0``.
    U, Y : sympy.ImmutableMatrix
        :math:`U_r`, :math:`Y_r`: external inputs and outputs over the traces.
    W_B, W_C : sympy.ImmutableMatrix
        :math:`W_B'` (``Nn x 2Nn``, closed rows first) and :math:`W_C' = W_{C,r}`.
    dissipation : sympy.ImmutableMatrix
        :math:`\operatorname{diag}(K + K^\top, 0)`, the value of
        :math:`W_B'\Sigma W_B'^\top`.
    identities : dict
        Largest absolute residual of each identity, keyed by :data:`CLOSED_IDENTITY_NAMES`.
    interval : tuple
        The model's interval (to print traces).
    trace_vector : tuple of sympy.Symbol
        ``v = (phi(b); phi(a))``.
    """

    closed: tuple[int, ...]
    external: tuple[int, ...]
    gain: sympy.ImmutableMatrix
    boundary: sympy.ImmutableMatrix
    U: sympy.ImmutableMatrix
    Y: sympy.ImmutableMatrix
    W_B: sympy.ImmutableMatrix
    W_C: sympy.ImmutableMatrix
    dissipation: sympy.ImmutableMatrix
    identities: dict[str, sympy.Expr]
    interval: tuple[sympy.Expr, sympy.Expr]
    trace_vector: tuple[sympy.Symbol, ...]

    def boundary_conditions(self) -> tuple[str, ...]:
        """Return the closed boundary conditions in trace notation (``e1(1)*k + e2(1) = 0``)."""
        v = sympy.Matrix(self.trace_vector)
        return tuple(
            f"{format_expression(canonical((self.boundary[i, :] * v)[0]), self.interval)} = 0"
            for i in range(self.boundary.rows)
        )

    def __repr__(self) -> str:
        """Short form: which inputs are closed, the gain and the identities' residuals."""
        worst = max((abs(float(v)) for v in self.identities.values()), default=0.0)
        return (
            f"ClosedPorts(closed={[i + 1 for i in self.closed]}, gain={self.gain.tolist()}, "
            f"max residual={worst:g})"
        )[:300]

    def __str__(self) -> str:
        """Return the text ``phdesign ports`` prints for the closed plant."""
        return "\n".join(
            [
                f"feedback u_c = -K y_c on inputs {[i + 1 for i in self.closed]}, K = "
                f"{self.gain.tolist()}: boundary conditions "
                + ", ".join(self.boundary_conditions()),
                "closed plant W_B' (closed rows first) =",
                sympy.pretty(self.W_B),
                *(f"max |{key}| = {float(value):g}" for key, value in self.identities.items()),
            ]
        )

    def _repr_html_(self) -> str:
        rows = (
            ("closed inputs", [i + 1 for i in self.closed]),
            ("gain K", self.gain.tolist()),
            ("boundary conditions", "; ".join(self.boundary_conditions())),
            *self.identities.items(),
        )
        return html_table((), rows, "closed plant")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (exact entries as strings)."""
        return {
            "closed_inputs": [i + 1 for i in self.closed],
            "external_inputs": [i + 1 for i in self.external],
            "gain": [[str(x) for x in row] for row in self.gain.tolist()],
            "boundary_conditions": list(self.boundary_conditions()),
            "W_B": [[str(x) for x in row] for row in self.W_B.tolist()],
            "W_C": [[str(x) for x in row] for row in self.W_C.tolist()],
            "identities": {k: str(v) for k, v in self.identities.items()},
        }


def _selection(indices: Sequence[int], n: int) -> sympy.ImmutableMatrix:
    return sympy.ImmutableMatrix(len(indices), n, lambda r, c: 1 if c == indices[r] else 0)


@lru_cache(maxsize=128)
def closed_ports(model: BCPHS) -> ClosedPorts:
    """Derive and check the ports of ``model`` closed by its ``[feedback]``.

    Raises
    ------
    ModelError
        If the model has no feedback.
    PortError
        If a closed-plant identity fails (it cannot when the open identities hold: the
        check guards the derivation).
    """
    _require_model(model)
    if model.feedback is None:
        raise ModelError(f"model {model.name!r} has no [feedback] section")
    N, n = model.order, model.size
    nn = N * n
    ports = derive_ports(model)
    fb = model.feedback
    closed = fb.closed
    external = external_indices(nn, fb)
    E_c, E_r = _selection(closed, nn), _selection(external, nn)
    K = fb.gain
    boundary = (E_c * ports.U + K * E_c * ports.Y).applyfunc(canonical)
    W_B = sympy.Matrix.vstack(E_c * ports.W_B + K * E_c * ports.W_C, E_r * ports.W_B)
    W_C = E_r * ports.W_C
    Sigma = sigma_matrix(nn)
    c, r = len(closed), len(external)
    dissipation = sympy.diag(K + K.T, sympy.zeros(r, r)) if c else sympy.zeros(nn, nn)
    select_external = sympy.Matrix.hstack(sympy.zeros(r, c), sympy.eye(r))
    residuals = {
        "WB_Sigma_WBt_minus_dissipation": W_B * Sigma * W_B.T - dissipation,
        "WC_Sigma_WBt_minus_E": W_C * Sigma * W_B.T - select_external,
        "WC_Sigma_WCt": W_C * Sigma * W_C.T,
    }
    defaults = model.parameter_defaults
    identities: dict[str, sympy.Expr] = {}
    for key in CLOSED_IDENTITY_NAMES:
        residual = residuals[key].applyfunc(canonical)
        values = [abs(x.xreplace(defaults)) for x in residual]
        identities[key] = max(values, key=float) if values else sympy.Integer(0)
        if not all(vanishes(x) for x in residual):
            raise PortError(f"closed-plant identity {key} fails: residual {residual.tolist()}")
    return ClosedPorts(
        closed=closed,
        external=external,
        gain=K,
        boundary=sympy.ImmutableMatrix(boundary),
        U=sympy.ImmutableMatrix(E_r * ports.U),
        Y=sympy.ImmutableMatrix(E_r * ports.Y),
        W_B=sympy.ImmutableMatrix(W_B.applyfunc(canonical)),
        W_C=sympy.ImmutableMatrix(W_C.applyfunc(canonical)),
        dissipation=sympy.ImmutableMatrix(dissipation),
        identities=identities,
        interval=model.interval,
        trace_vector=ports.trace_vector,
    )


def plant_feedback(model: BCPHS) -> tuple[tuple[int, ...], sympy.ImmutableMatrix] | None:
    """Return ``(closed 0-based indices, K at the parameter defaults)``, or ``None``."""
    if model.feedback is None:
        return None
    K = model.feedback.gain.xreplace(model.parameter_defaults)
    return model.feedback.closed, sympy.ImmutableMatrix(K)


def psd_factor(S: sympy.MatrixBase) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
    r"""Factor a symmetric :math:`S \succeq 0` as :math:`S = W^\top D W`, exactly.

    :math:`W` (``r x c``) has full row rank :math:`r = \operatorname{rank} S` and
    :math:`D \succ 0`.  With :math:`R` a basis of the range of :math:`S` (columns),
    :math:`W = R^\top` and :math:`D = (R^\top R)^{-1} R^\top S R (R^\top R)^{-1}`: then
    :math:`W^\top D W = P S P = S` for the orthogonal projector :math:`P` onto the range.

    Examples
    --------
    >>> W, D = psd_factor(sympy.Matrix([[2, 2], [2, 2]]))
    >>> W.T * D * W
    Matrix([
    [2, 2],
    [2, 2]])
    """
    S = sympy.Matrix(S)
    columns = S.columnspace()
    if not columns:
        return sympy.ImmutableMatrix.zeros(0, S.cols), sympy.ImmutableMatrix.zeros(0, 0)
    R = sympy.Matrix.hstack(*columns)
    gram_inv = (R.T * R).inv()
    D = (gram_inv * R.T * S * R * gram_inv).applyfunc(canonical)
    return sympy.ImmutableMatrix(R.T), sympy.ImmutableMatrix(D)


def error_dissipation(
    nn: int,
    C_m: sympy.MatrixBase,
    L: sympy.MatrixBase,
    feedback: tuple[Sequence[int], sympy.MatrixBase] | None,
) -> tuple[sympy.ImmutableMatrix, sympy.ImmutableMatrix, sympy.ImmutableMatrix]:
    r"""Boundary gain and dissipation of the observer error system (module docstring).

    Parameters
    ----------
    nn : int
        :math:`Nn`, the number of open ports.
    C_m, L : sympy matrix
        Sensors over the external outputs and their gain.
    feedback : (closed indices, K) or None
        The plant's own feedback (0-based indices into the open ports).

    Returns
    -------
    G : sympy.ImmutableMatrix
        ``Nn x Nn``: the error boundary condition is :math:`\tilde u = -G\tilde y`.
    C_d, L_d : sympy.ImmutableMatrix
        A factorization of the left-hand side of the propositions,
        :math:`\tfrac12 (C_d\tilde y)^\top (L_d + L_d^\top)(C_d\tilde y) =
        \tilde y^\top \operatorname{sym}(G)\,\tilde y`, with :math:`C_d` of full row rank
        and :math:`L_d + L_d^\top \succ 0` (for gains with :math:`L + L^\top \succ 0`).
        Without feedback, :math:`C_d = C_m` and :math:`L_d = L`.
    """
    closed, K = ((), sympy.zeros(0, 0)) if feedback is None else feedback
    closed = tuple(closed)
    external = [j for j in range(nn) if j not in set(closed)]
    C_full = sympy.Matrix(C_m) * _selection(external, nn)
    L = sympy.Matrix(L)
    G = C_full.T * L * C_full
    if not closed:
        return sympy.ImmutableMatrix(G), sympy.ImmutableMatrix(C_m), sympy.ImmutableMatrix(L)
    E_c = _selection(closed, nn)
    K = sympy.Matrix(K)
    G = G + E_c.T * K * E_c
    sym_K = (K + K.T) / 2
    W, D = psd_factor(sym_K)
    if W.rows == K.rows:  # K + K^T > 0: keep K itself (the same quadratic form)
        W, D = sympy.ImmutableMatrix(sympy.eye(K.rows)), sympy.ImmutableMatrix(K)
    C_d = sympy.Matrix.vstack(W * E_c, C_full)
    L_d = sympy.diag(D, L) if L.rows else sympy.Matrix(D)
    return sympy.ImmutableMatrix(G), sympy.ImmutableMatrix(C_d), sympy.ImmutableMatrix(L_d)
