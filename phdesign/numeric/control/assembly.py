r"""The observer-based loop, assembled: plant, observer and feedback as one LTI system.

With the discretization :math:`E\dot{\hat e} = (J - R)\hat e + B u`,
:math:`y = B^\top \hat e + D u` (:mod:`phdesign.numeric.discretization.registry`), the observer is
the
same system with :math:`\hat u = u + C_m^\top L (y_m - \hat y_m)`; plant and observer
together are :func:`~phdesign.numeric.time.simulation.coupled_system`,
:math:`E_2 \dot X = A_2 X + B_2 u` with :math:`X = (\hat e, \hat e_{obs})`, and the
observer output is :math:`\hat y = C_{\hat y} X + D u` with :math:`C_{\hat y} =
(D\Gamma B^\top,\ B^\top - D\Gamma B^\top)`, :math:`\Gamma = (I + GD)^{-1}G`,
:math:`G = C_m^\top L C_m` (solve :math:`\hat u - u = G(y - \hat y)` for
:math:`\hat u`).  The controller closes

.. math::

    u = -S_a^\top K S_a\, (C_f X + D u) + S_r^\top v, \qquad
    C_f = C_{\hat y}\ (\text{estimate}) \text{ or } (B^\top\ 0)\ (\text{measured}),

:math:`S_a`, :math:`S_r` the selections of the actuated and of the other inputs, so with
:math:`K_a = S_a^\top K S_a` and :math:`M = (I + K_a D)^{-1}`,

.. math::

    u = F X + P v, \quad F = -M K_a C_f, \quad P = M S_r^\top, \qquad
    E_2 \dot X = (A_2 + B_2 F) X + B_2 P v .

Both loops with the feedthrough D are solved by
:meth:`~phdesign.numeric.discretization.phs.DiscretePHS.close`, the one place that does:
the observer's with G (its gain is Γ, and :math:`\hat y = y - \tilde y`, :math:`\tilde y =
(I - D\Gamma) B^\top \tilde e`), the controller's with :math:`K_a` (gain :math:`M K_a`, and
:math:`M = I - M K_a D`).

This is the assembled loop in the original coordinates :math:`(\hat e, \hat e_{obs})`.
In :math:`Z = T X = (\hat e, \tilde e)`, :math:`T = \left[\begin{smallmatrix} I & 0 \\
I & -I \end{smallmatrix}\right] = T^{-1}` (and :math:`T E_2 T = E_2`), it is
block upper-triangular: the error block is the error system
:math:`E\dot{\tilde e} = (J - R - B\Gamma B^\top)\tilde e`, the plant block the plant
closed by :math:`u_a = -K y_a` (:mod:`phdesign.symbolic.control` derives it); the lower-left
block vanishes to round-off, and :attr:`LoopSystem.triangular_residual` says by how much.

:func:`phdesign.numeric.control.spectrum.loop_spectrum` refines the assembled pencil with
the refinement of :mod:`phdesign.numeric.spectrum.converged` (its eigen stage, drift rule and
choice
of the pair) and reports it beside the converged spectra of the two blocks;
:func:`loop_statespace` exports the loop to python-control.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from phdesign.core.errors import LoopError, check_shape
from phdesign.numeric.discretization.invariants import require_definite
from phdesign.numeric.discretization.registry import DiscretePHS, feedback_matrix
from phdesign.numeric.time.simulation import coupled_system

__all__ = [
    "LoopSystem",
    "NumericLoop",
    "assemble",
    "loop_statespace",
]


@dataclass(frozen=True)
class NumericLoop:
    r"""The loop's numbers: which ports are actuated, K, the sensors and L.

    Parameters
    ----------
    actuated : tuple of int
        0-based indices into the discretization's (external) ports.
    K : ndarray (k, k)
        Feedback gain, :math:`K + K^\top \succ 0`.
    C_m, L : ndarray
        Sensors (``q x m``) and observer gain (``q x q``).
    source : {"estimate", "measured"}
        Feed back :math:`\hat y_a` or the measured :math:`y_a`.
    """

    actuated: tuple[int, ...]
    K: np.ndarray = field(compare=False)
    C_m: np.ndarray = field(compare=False)
    L: np.ndarray = field(compare=False)
    source: str = "estimate"

    def selection(self, m: int) -> np.ndarray:
        """:math:`S_a` (``k x m``): the actuated rows of the identity."""
        return np.eye(m)[list(self.actuated)]

    def check(self, m: int) -> None:
        """Check shapes and indices against ``m`` ports (the library's last guard)."""
        k = len(self.actuated)
        if k == 0 or len(set(self.actuated)) != k or not all(0 <= a < m for a in self.actuated):
            raise LoopError(f"actuated ports must be distinct indices in 0..{m - 1}")
        K = np.asarray(self.K, dtype=float)
        check_shape("feedback gain K", K, (k, k))
        # the loop's stability rests on sym(K) > 0 (Le Gorrec, Zwart, Maschke 2005), which
        # the symbolic reader checks exactly; a NumericLoop built by hand is checked here
        require_definite("K + K^T", K + K.T, LoopError)
        if self.source not in ("estimate", "measured"):
            raise LoopError(f"source must be 'estimate' or 'measured'; found {self.source!r}")
        if self.source == "measured":  # y_a = F y_m: the unit rows lie in the rows of C_m
            C = np.atleast_2d(np.asarray(self.C_m, dtype=float))
            rank = np.linalg.matrix_rank(C)
            for a in self.actuated:
                if np.linalg.matrix_rank(np.vstack([C, np.eye(m)[a]])) != rank:
                    raise LoopError(
                        f"feedback source measured: y{a + 1} (collocated with the actuated "
                        f"u{a + 1}) is not measured by these sensors"
                    )


@dataclass(frozen=True)
class LoopSystem:
    r"""The assembled loop :math:`E_2\dot X = A X + B v` and its output maps (module docstring).

    ``X = (ê, ê_obs)``; ``u = C_u X + D_u v``, ``y = C_y X + D_y v``,
    ``ŷ = C_yhat X + D_yhat v``; ``v`` are the inputs in :attr:`others`.
    """

    discrete: DiscretePHS = field(repr=False)
    loop: NumericLoop
    E: np.ndarray = field(repr=False)
    A: np.ndarray = field(repr=False)
    B: np.ndarray = field(repr=False)
    C_u: np.ndarray = field(repr=False)
    D_u: np.ndarray = field(repr=False)
    C_y: np.ndarray = field(repr=False)
    D_y: np.ndarray = field(repr=False)
    C_yhat: np.ndarray = field(repr=False)
    D_yhat: np.ndarray = field(repr=False)
    others: tuple[int, ...] = ()

    @property
    def dim(self) -> int:
        """Number of states of the discretized plant (the loop has twice as many)."""
        return self.discrete.dim

    def error_coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """Return ``(A_Z, B_Z)`` in ``Z = (ê, ẽ)``: block upper-triangular (module docstring)."""
        n = self.dim
        T = np.block([[np.eye(n), np.zeros((n, n))], [np.eye(n), -np.eye(n)]])
        return T @ self.A @ T, T @ self.B

    @property
    def triangular_residual(self) -> float:
        """Largest entry of the lower-left block of ``A_Z`` relative to ``max |A_Z|``."""
        A_Z, _ = self.error_coordinates()
        n = self.dim
        return float(np.max(np.abs(A_Z[n:, :n])) / max(np.max(np.abs(A_Z)), 1e-300))

    def blocks(self) -> tuple[np.ndarray, np.ndarray]:
        """Right-hand matrices of the controlled plant and of the error system (pencil E)."""
        A_Z, _ = self.error_coordinates()
        n = self.dim
        return A_Z[:n, :n], A_Z[n:, n:]


def assemble(d: DiscretePHS, loop: NumericLoop) -> LoopSystem:
    """Assemble plant, observer and feedback of ``loop`` on the discretization ``d``.

    Raises
    ------
    LoopError
        If an index or a shape does not fit ``d``.
    NumericError
        If the feedthrough makes the loop ill-posed (I + K_a D singular:
        :meth:`~phdesign.numeric.discretization.phs.DiscretePHS.close`).

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> from phdesign.numeric.discretization.registry import discretize
    >>> d = discretize(to_numeric(load_builtin("euler-bernoulli")), "galerkin", 10)
    >>> tip_torque = NumericLoop((2,), np.eye(1), np.array([[0, 0, 0, 1.0]]), np.eye(1))
    >>> system = assemble(d, tip_torque)
    >>> system.A.shape, system.others, system.triangular_residual < 1e-14
    ((44, 44), (0, 1, 3), True)
    """
    m, n = d.n_ports, d.dim
    loop.check(m)
    G = feedback_matrix(loop.C_m, loop.L, m)  # checks C_m, L shapes and L + Lᵀ ≻ 0
    E2, A2, B2 = coupled_system(d, G)
    # ŷ = y − ỹ with ỹ = C ẽ the error system's output and ẽ = ê − ê_obs
    error_output = d.close(G).C
    C_yhat = np.hstack([d.B.T - error_output, error_output])
    C_y = np.hstack([d.B.T, np.zeros((m, n))])
    S_a = loop.selection(m)
    others = tuple(j for j in range(m) if j not in set(loop.actuated))
    S_r_T = np.eye(m)[:, list(others)]
    K_a = S_a.T @ np.asarray(loop.K, dtype=float) @ S_a
    C_f = C_yhat if loop.source == "estimate" else C_y
    # u = −K_a (C_f X + D u) + S_rᵀ v is the loop u = v' − K_a y' that close() solves
    G_a = d.close(K_a).gain  # M K_a, M = (I + K_a D)⁻¹
    F = -G_a @ C_f
    P = S_r_T - G_a @ d.D @ S_r_T  # M = I - M K_a D
    return LoopSystem(
        discrete=d,
        loop=loop,
        E=E2,
        A=A2 + B2 @ F,
        B=B2 @ P,
        C_u=F,
        D_u=P,
        C_y=C_y + d.D @ F,
        D_y=d.D @ P,
        C_yhat=C_yhat + d.D @ F,
        D_yhat=d.D @ P,
        others=others,
    )


def loop_statespace(system: LoopSystem, name: str = "loop") -> Any:
    """Return the assembled loop as ``control.StateSpace`` with named signals.

    States ``e1[j]…`` (plant) then ``hat_e1[j]…`` (observer), as
    :func:`phdesign.numeric.statespace.state_labels`; inputs the free plant inputs ``v``
    (``u<i>`` for the inputs not actuated); outputs ``y1…`` (plant), ``y_hat1…``
    (observer) and ``u1…`` (the inputs the plant receives, actuated ones included).
    """
    import control

    from phdesign.numeric.statespace import state_labels

    d = system.discrete
    m = d.n_ports
    A = np.linalg.solve(system.E, system.A)
    B = np.linalg.solve(system.E, system.B)
    C = np.vstack([system.C_y, system.C_yhat, system.C_u])
    D = np.vstack([system.D_y, system.D_yhat, system.D_u])
    return control.ss(
        A,
        B,
        C,
        D,
        inputs=[f"u{j + 1}" for j in system.others],
        outputs=[f"y{i + 1}" for i in range(m)]
        + [f"y_hat{i + 1}" for i in range(m)]
        + [f"u{i + 1}" for i in range(m)],
        states=state_labels(d) + state_labels(d, "hat_"),
        name=name,
    )
