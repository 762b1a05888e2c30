r"""Close ports of a discrete port-Hamiltonian system with a static output feedback.

For :math:`E\dot{\hat e} = (J - R)\hat e + B u`, :math:`y = B^\top \hat e + D u`, split
the ports into closed ones :math:`c` and external ones :math:`r`, and close
:math:`u_c = -K y_c` (:math:`K + K^\top \succeq 0`).  When the feedthrough does not touch
the closed ports (:math:`D_{cc} = D_{cr} = 0`, always so for the Galerkin method), the
closed system is again port-Hamiltonian, exactly:

.. math::

    E\dot{\hat e} = \big(J - B_c \operatorname{skew}(K) B_c^\top\big)\hat e
                  - \big(R + B_c \operatorname{sym}(K) B_c^\top\big)\hat e + B_r u_r,
    \qquad y_r = B_r^\top \hat e + D_{rr} u_r ,

so its energy balance :math:`\dot H_d = -\hat e^\top R \hat e - y_c^\top
\operatorname{sym}(K) y_c + u_r^\top y_r` carries the damper's dissipation in :math:`R`.
This is the discrete counterpart of :mod:`phdesign.symbolic.closing`;
:func:`~phdesign.numeric.discretization.coupled.close_and_couple` applies a model's own
``[feedback]`` (and its boundary systems) to its discretization, and :func:`close_ports` is
the reusable step (a controller's :math:`u = -K y` as well).

Examples
--------
>>> import numpy as np
>>> from phdesign.numeric.bridge import NumericModel, constant_H
>>> from phdesign.numeric.discretization.phs import DiscretePHS
>>> nm = NumericModel("t", (0.0, 1.0), 1, 1, (np.zeros((1, 1)), np.ones((1, 1))),
...                   constant_H([[1.0]]), np.array([[0.0, 1.0]]), np.array([[1.0, 0.0]]))
>>> d = DiscretePHS(nm, "galerkin", 1, np.eye(2), np.zeros((2, 2)), np.zeros((2, 2)),
...                 np.array([[1.0], [0.0]]), np.zeros((1, 1)), lambda z: z, lambda f: f)
>>> close_ports(d, [0], np.array([[2.0]])).R
array([[2., 0.],
       [0., 0.]])
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from phdesign.core.errors import NumericError, check_shape
from phdesign.numeric.bridge import NumericModel
from phdesign.numeric.discretization.phs import DiscretePHS

__all__ = ["close_ports", "open_port_gain"]


def close_ports(d: DiscretePHS, closed: Sequence[int], K: np.ndarray) -> DiscretePHS:
    r"""Close the ports ``closed`` (0-based) of ``d`` with :math:`u_c = -K y_c`.

    Returns the closed :class:`~phdesign.numeric.discretization.phs.DiscretePHS`, whose ports are
    the
    others in order.  ``d.model`` is kept.

    Raises
    ------
    NumericError
        If the feedthrough couples the closed ports (the closed system would not be of
        the form :math:`y = B^\top\hat e + Du`), or an index is out of range.
    """
    picked = [int(c) for c in closed]
    m = d.n_ports
    if len(set(picked)) != len(picked) or not all(0 <= c < m for c in picked):
        raise NumericError(
            f"ports to close must be distinct indices in 0..{m - 1}; found {picked}"
        )
    Km = np.asarray(K, dtype=float)
    check_shape("feedback gain K", Km, (len(picked), len(picked)))
    rest = [j for j in range(m) if j not in set(picked)]
    D = d.D
    if np.any(D[np.ix_(picked, picked)]) or np.any(D[np.ix_(picked, rest)]):
        raise NumericError(
            "this discretization has a feedthrough on the closed ports; close them with "
            "method='galerkin'"
        )
    B_c, B_r = d.B[:, picked], d.B[:, rest]
    sym, skew = 0.5 * (Km + Km.T), 0.5 * (Km - Km.T)
    info = {**d.info, "closed_ports": tuple(picked)}
    return replace(
        d,
        J=d.J - B_c @ skew @ B_c.T,
        R=d.R + B_c @ sym @ B_c.T,
        B=B_r.copy(),
        D=D[np.ix_(rest, rest)].copy(),
        info=info,
    )


def open_port_gain(nm: NumericModel, K: np.ndarray | None) -> np.ndarray:
    """Gain on all N n open ports: the plant's own feedback and ``K`` on the external ones.

    The loop is u = -K_full y on the open ports, so its boundary condition is
    (U + K_full Y) v = 0.  For a model with boundary systems it is the high-frequency
    limit of the coupled boundary condition (the static part of each interconnection).

    Examples
    --------
    >>> from phdesign.models import load_builtin
    >>> from phdesign.numeric.bridge import to_numeric
    >>> open_port_gain(to_numeric(load_builtin("wave-damper")), np.array([[2.0]])).tolist()
    [[2.0, 0.0], [0.0, 0.5]]
    """
    ports = nm.order * nm.size
    full = np.zeros((ports, ports))
    closed: list[int] = []
    if nm.feedback is not None:
        closed = [int(c) for c in nm.feedback.closed]
        full[np.ix_(closed, closed)] = np.asarray(nm.feedback.gain, dtype=float)
    for b in nm.boundary:
        # far above the boundary systems' own frequencies e_c -> 0: only u_p = -K y_p is left
        full[np.ix_(b.joined, b.joined)] = b.K
        closed += list(b.joined)
    if K is not None:
        external = [j for j in range(ports) if j not in closed]
        t = len(external)  # a gain on the boundary systems' own ports acts through e_c only
        full[np.ix_(external, external)] = np.asarray(K, dtype=float)[:t, :t]
    return full
