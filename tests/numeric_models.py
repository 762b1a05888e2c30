"""Models shared by the numeric tests (built through the symbolic layer and the bridge)."""

from __future__ import annotations

import numpy as np

from phdesign.models import builtin_names, load_builtin
from phdesign.numeric.bridge import NumericModel, to_numeric
from phdesign.symbolic.model import BCPHS

BUILTINS = tuple(builtin_names())

# Wave with z-dependent density and stiffness and internal damping (P0 = -0.3 on x1):
# exercises the quadrature mass matrix, lambdified H(z) and R != 0.
VARYING = BCPHS.define(
    name="varying wave",
    interval=[0, 1],
    order=1,
    P={0: [["-c", 0], [0, 0]], 1: [[0, 1], [1, 0]]},
    H=[["1/(1 + z)", 0], [0, "2 + sin(3*z)"]],
    inputs=["e1(0)", "e2(1)"],
    outputs=["-e2(0)", "e1(1)"],
    parameters={"c": "3/10"},
)

# Timoshenko with z-dependent H coupling components inside each staggered group is not
# allowed for FD; the Galerkin method takes any symmetric positive definite H(z).
COUPLED = BCPHS.define(
    name="coupled H",
    interval=[0, 2],
    order=1,
    P={1: [[0, 1], [1, 0]]},
    H=[["2 + z", "1/2"], ["1/2", "1 + z**2"]],
    inputs=["e1(0)", "e2(2)"],
    outputs=["-e2(0)", "e1(2)"],
)


def numeric(name: str, **params: object) -> NumericModel:
    """A built-in model through the bridge."""
    return to_numeric(load_builtin(name), params or None)


PAPER_SENSORS = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])  # y3, y4 (Section IV.C)
TABLE_I = ((0.03, 0.3), (0.1, 1.0), (0.2, 2.0))  # paper, Table I

# Wave with outputs that mix in the inputs (y = y_nat + K u, K skew): the staggered
# grid then has a skew feedthrough D != 0 and scaled inputs (S != I).
FEEDTHROUGH = BCPHS.define(
    name="wave with feedthrough",
    interval=[0, 1],
    order=1,
    P={1: [[0, 1], [1, 0]]},
    H=[[1, 0], [0, 1]],
    inputs=["2*e1(0)", "e2(1)"],
    outputs=["-e2(0)/2 + e2(1)", "e1(1) - 2*e1(0)"],
)


def observer_loop_residual(d, K, states_hat, u, y, y_hat):
    r"""Largest relative residual of the observer's implicit input in a simulated run.

    From the definitions, not from ``close()``: the observer runs on
    :math:`\hat u = u + K (y - \hat y)` (:math:`K = C_m^\top L C_m`) and reports
    :math:`\hat y = B^\top \hat e_{obs} + D \hat u`, so with a feedthrough D ≠ 0 its output
    solves :math:`\hat y = B^\top \hat e_{obs} + D (u + K (y - \hat y))`.
    """
    u = np.zeros_like(y) if u is None else np.asarray(u)
    u_hat = u + (y - y_hat) @ K.T
    residual = y_hat - states_hat @ d.B - u_hat @ d.D.T
    return float(np.max(np.abs(residual)) / np.max(np.abs(y_hat)))
