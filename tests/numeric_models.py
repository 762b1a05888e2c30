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
