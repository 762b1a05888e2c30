r"""A model's boundary systems with numbers: what the discretizations append.

The symbolic layer solves the interconnection of each boundary system
(:func:`phdesign.symbolic.boundary_systems.coupling`); with the parameters substituted (by
:mod:`phdesign.numeric.bridge`, the one crossing) it is, in the effort
:math:`e_c = Q_c x_c`,

.. math::

    u_p = -K y_p + F e_c, \qquad
    E_c \dot e_c = (J_c - R_c) e_c - F^\top y_p + B_c w, \qquad z_c = B_c^\top e_c,

with :math:`E_c = Q_c^{-1}`, :math:`H_c = \tfrac12 e_c^\top E_c e_c`; :math:`J_c` here is
the effective :math:`J_c + G_c S_{cc} G_c^\top` (skew) and :math:`K + K^\top \succeq 0`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from phdesign.core.errors import ModelError
from phdesign.numeric.discretization.invariants import (
    require_definite,
    require_semidefinite,
    require_skew,
)

__all__ = ["NumericBoundary", "numeric_boundaries", "scaled_boundaries"]


@dataclass(frozen=True)
class NumericBoundary:
    r"""One boundary system with numbers (module docstring).

    Parameters
    ----------
    name : str
    joined : tuple of int
        0-based indices of the PDE's open ports it is joined to.
    K, F : ndarray
        ``m x m`` and ``m x k``: :math:`u_p = -K y_p + F e_c`.
    E, J, R : ndarray
        ``k x k``: :math:`E_c = Q_c^{-1} \succ 0`, skew :math:`J_c`, :math:`R_c \succeq 0`.
    B : ndarray
        ``k x r``: the external inputs' directions.
    state_labels, input_labels, output_labels : tuple of str
    """

    name: str
    joined: tuple[int, ...]
    K: np.ndarray = field(compare=False)
    F: np.ndarray = field(compare=False)
    E: np.ndarray = field(compare=False)
    J: np.ndarray = field(compare=False)
    R: np.ndarray = field(compare=False)
    B: np.ndarray = field(compare=False)
    state_labels: tuple[str, ...] = ()
    input_labels: tuple[str, ...] = ()
    output_labels: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        """Check the invariants after substitution, to round-off (the error names the system)."""
        label = f"boundary system {self.name!r}"
        require_definite(f"{label} E_c = Q_c^-1", self.E, error=ModelError)
        require_skew(f"{label} J_c", self.J, error=ModelError)
        scale = float(np.max(np.abs(self.J), initial=1.0))
        require_semidefinite(f"{label} R_c", self.R, reference=scale, error=ModelError)
        K = self.K
        require_semidefinite(
            f"{label} K + K^T",
            K + K.T,
            reference=float(np.max(np.abs(K), initial=1.0)),
            error=ModelError,
        )

    @property
    def size(self) -> int:
        """The number of states."""
        return int(self.E.shape[0])

    @property
    def n_external(self) -> int:
        """The number of external inputs."""
        return int(self.B.shape[1])


def numeric_boundaries(
    model: Any,
    matrix: Callable[[str, Any], Any],
    array: Callable[[Any], np.ndarray],
) -> tuple[NumericBoundary, ...]:
    """Return ``model``'s boundary systems with the parameters substituted.

    ``matrix(name, M)`` substitutes and refuses free symbols, ``array`` makes floats (the
    bridge's :class:`~phdesign.numeric.bridge._Substitution`).
    """
    from phdesign.symbolic.boundary_systems import coupling

    out = []
    for bs in getattr(model, "boundary_systems", ()):
        c = coupling(bs)
        label = f"boundary system {bs.name!r}"

        def number(key: str, M: Any, label: str = label) -> np.ndarray:
            if 0 in M.shape:  # no external inputs
                return np.zeros(M.shape)
            return np.atleast_2d(array(matrix(f"{label} {key}", M))).reshape(M.shape)

        Q = number("Q", bs.Q)
        out.append(
            NumericBoundary(
                name=bs.name,
                joined=bs.joined,
                K=number("K", c.K),
                F=number("S_pc G^T", c.to_pde),
                E=np.linalg.inv(Q),
                J=number("J", c.J_eff),
                R=number("R", bs.R),
                B=number("B", bs.external),
                state_labels=bs.state_labels,
                input_labels=bs.input_labels,
                output_labels=bs.output_labels,
            )
        )
    return tuple(out)


def scaled_boundaries(
    boundaries: tuple[NumericBoundary, ...], rate: float
) -> tuple[NumericBoundary, ...]:
    r"""Return the boundary systems of the dimensionless model (time scaled by ``rate``).

    With :math:`u = \sigma u'`, :math:`y = \sigma y'` (:mod:`phdesign.numeric.scales`) and
    :math:`e_c = \sigma e_c'`, :math:`t = t'/\mathrm{rate}`, the equations keep their form
    with :math:`E_c' = \mathrm{rate}\,E_c` and K, F, J, R, B unchanged.
    """
    return tuple(replace(b, E=rate * b.E) for b in boundaries)
