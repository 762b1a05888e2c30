r"""The discretization of a coupled model: the boundary systems' states appended.

A method discretizes the PDE with all its ports open,
:math:`E\dot{\hat e} = (J - R)\hat e + B u`, :math:`y = B^\top\hat e + Du`.  The model's
``[feedback]`` closes some ports with :math:`u_f = -K_f y_f`; each boundary system
(:mod:`phdesign.numeric.boundary`) joins ports :math:`p` with
:math:`u_p = -K y_p + F e_c` and :math:`E_c \dot e_c = (J_c - R_c) e_c - F^\top y_p +
B_c w`.  The static parts close as in :func:`~.feedback.close_ports` (their symmetric
parts go into R); the dynamic parts append the states :math:`e_c` and couple them through
the joined ports' input columns :math:`B_p`:

.. math::

    \begin{pmatrix} E & 0 \\ 0 & E_c \end{pmatrix}
    \begin{pmatrix} \dot{\hat e} \\ \dot e_c \end{pmatrix} =
    \left[\begin{pmatrix} J' & B_p F \\ -F^\top B_p^\top & J_c \end{pmatrix}
    - \begin{pmatrix} R' & 0 \\ 0 & R_c \end{pmatrix}\right]
    \begin{pmatrix} \hat e \\ e_c \end{pmatrix}
    + \begin{pmatrix} B_r & 0 \\ 0 & B_c \end{pmatrix}
    \begin{pmatrix} u_r \\ w \end{pmatrix} .

The off-diagonal block is skew, so the result is again a
:class:`~phdesign.numeric.discretization.phs.DiscretePHS` (its invariants are checked when it
is built) whose energy :math:`\tfrac12\hat e^\top E\hat e + \sum H_c` obeys
:math:`\dot H = -\hat e^\top R\hat e - e_c^\top R_c e_c + u_r^\top y_r + w^\top z_c` to
round-off.  The appended coordinates are zero in every field basis (they are no part of
the PDE's state); a projected initial state appends :math:`e_c(0) = Q_c x_c(0)` of a
:class:`~phdesign.numeric.boundary_start.CoupledInitialState` (at rest otherwise);
``info["boundary_states"]`` says where they are (``(first index, count)``) and
``info["boundary_labels"]`` what they are.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
from scipy.linalg import block_diag

from phdesign.numeric.boundary import NumericBoundary
from phdesign.numeric.boundary_start import boundary_efforts
from phdesign.numeric.discretization.feedback import close_ports
from phdesign.numeric.discretization.phs import DiscretePHS

__all__ = ["boundary_series", "close_and_couple"]


def close_and_couple(d: DiscretePHS) -> DiscretePHS:
    """Close the model's ``[feedback]`` and join its boundary systems (module docstring).

    A discretization whose ports are already closed (fewer than ``N n``) is returned
    unchanged.
    """
    nm = d.model
    if d.n_ports < nm.order * nm.size or (nm.feedback is None and not nm.boundary):
        return d
    closed = [] if nm.feedback is None else [int(c) for c in nm.feedback.closed]
    gains = [] if nm.feedback is None else [np.asarray(nm.feedback.gain, dtype=float)]
    for b in nm.boundary:
        closed += list(b.joined)
        gains.append(b.K)
    static = close_ports(d, closed, block_diag(*gains))
    if not nm.boundary:
        return static
    return _append(d, static)


def _append(d: DiscretePHS, static: DiscretePHS) -> DiscretePHS:
    nm = d.model
    n = static.dim
    E = block_diag(static.E, *(b.E for b in nm.boundary))
    J = block_diag(static.J, *(b.J for b in nm.boundary))
    R = block_diag(static.R, *(b.R for b in nm.boundary))
    B = block_diag(static.B, *(b.B for b in nm.boundary))
    D = block_diag(static.D, np.zeros((B.shape[1] - static.n_ports,) * 2))
    offset = n
    for b in nm.boundary:
        coupling = d.B[:, list(b.joined)] @ b.F
        J[:n, offset : offset + b.size] += coupling
        J[offset : offset + b.size, :n] -= coupling.T
        offset += b.size
    extra = E.shape[0] - n
    labels = tuple(label for b in nm.boundary for label in b.state_labels)
    info = {**static.info, "boundary_states": (n, extra), "boundary_labels": labels}
    return replace(
        static,
        E=E,
        J=J,
        R=R,
        B=B,
        D=D,
        effort_basis=_padded(static.effort_basis, extra),
        project=_projected(static.project, nm.boundary),
        displacement_basis=None
        if static.displacement_basis is None
        else _padded(static.displacement_basis, extra),
        field_basis=None if static.field_basis is None else _fields(static.field_basis, extra),
        info=info,
    )


def _padded(
    basis: Callable[[np.ndarray], np.ndarray], extra: int
) -> Callable[[np.ndarray], np.ndarray]:
    """Return the same basis with ``extra`` zero columns for the boundary states (last axis)."""

    def padded(z: np.ndarray) -> np.ndarray:
        values = np.asarray(basis(z))
        zeros = np.zeros((*values.shape[:-1], extra))
        return np.concatenate([values, zeros], axis=-1)

    return padded


def _projected(
    project: Callable[[Callable[[np.ndarray], np.ndarray]], np.ndarray],
    boundaries: tuple[NumericBoundary, ...],
) -> Callable[[Callable[[np.ndarray], np.ndarray]], np.ndarray]:
    def projected(x0: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        return np.concatenate([np.asarray(project(x0)), boundary_efforts(boundaries, x0)])

    return projected


def _fields(
    field_basis: Callable[[Any], Callable[[np.ndarray], np.ndarray]], extra: int
) -> Callable[[Any], Callable[[np.ndarray], np.ndarray]]:
    def fields(spec: Any) -> Callable[[np.ndarray], np.ndarray]:
        return _padded(field_basis(spec), extra)

    return fields


def boundary_series(
    d: DiscretePHS,
    states: np.ndarray,
    states_hat: np.ndarray | None = None,
    d_hat: DiscretePHS | None = None,
) -> dict[str, Any]:
    r"""Return the boundary states of a run, as the fields of a simulation result.

    ``x_c`` = :math:`x_c(t) = E_c e_c(t)` (the model's own states: a mass's momentum) from
    the states X ``(nt, dim)`` on ``d``, ``x_c_hat`` likewise for the observer's on
    ``d_hat`` (default ``d``; None when the observer's coordinates are not a
    discretization's, as a reduced observer's), and ``boundary_labels``.  Empty for a
    model without boundary systems: the result's defaults stand.
    """
    if "boundary_states" not in d.info:
        return {}

    def series(disc: DiscretePHS, X: np.ndarray | None) -> np.ndarray | None:
        if X is None or "boundary_states" not in disc.info or X.shape[1] != disc.dim:
            return None
        first, count = disc.info["boundary_states"]
        block = slice(first, first + count)
        return np.asarray(X[:, block] @ disc.E[block, block].T)

    return {
        "boundary_labels": tuple(d.info["boundary_labels"]),
        "x_c": series(d, states),
        "x_c_hat": series(d if d_hat is None else d_hat, states_hat),
    }
