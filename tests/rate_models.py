"""Closed systems for the proved decay rate: exact error systems, and a transport.

Shared by tests/numeric/certified/test_rate.py, test_rate_z.py,
tests/proofcheck/test_rate_check.py and benchmarks/rate.py.  The z-dependent models'
closed forms are derived in tests/numeric/certified/test_rate_z.py.
"""

from __future__ import annotations

from phdesign.numeric.certified.exact_system import ExactClosedSystem, closed_system
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import sensor_matrix

# x_t = x_z on [0, 1]; u y = (e(1)^2 - e(0)^2)/2 is the power, so the ports are admissible
TRANSPORT = BCPHS.define(
    name="transport",
    interval=[0, 1],
    order=1,
    P={1: [[1]]},
    H=[[1]],
    inputs=["e1(1) - e1(0)"],
    outputs=["(e1(1) + e1(0))/2"],
)


def closed(model: BCPHS, sensors: list[int], gain: str) -> ExactClosedSystem:
    """The exact error system of ``model`` with the unit ``sensors`` and one ``gain`` each."""
    gains = [gain] * len(sensors)
    return closed_system(model, sensor_matrix(sensors, model.n_ports), gains)


# rho = T = 1 with a force input at each end: u = (e2(0), e2(1)), y = (-e1(0), e1(1)),
# u y = e1(1) e2(1) - e1(0) e2(0), the power; sensors y1, y2 put a damper at each end
STRING_TWO_ENDS = BCPHS.define(
    name="string with a force input at each end",
    interval=[0, 1],
    order=1,
    P={1: [[0, 1], [1, 0]]},
    H=[[1, 0], [0, 1]],
    inputs=["e2(0)", "e2(1)"],
    outputs=["-e1(0)", "e1(1)"],
)

# z-dependent coefficients (the proof of phdesign.numeric.certified.rate_poly)
STRING_PORTS = {"inputs": ["e1(0)", "e2(1)"], "outputs": ["-e2(0)", "e1(1)"]}


def string(name: str, H: list) -> BCPHS:
    """A string fixed at 0 with a force input at 1 (u = e2(1), y = e1(1))."""
    return BCPHS.define(
        name=name, interval=[0, 1], order=1, P={1: [[0, 1], [1, 0]]}, H=H, **STRING_PORTS
    )


SPEED = string("string of speed 1 + z", [["1 + z", 0], [0, "1 + z"]])
DENSITY = string("string of density 1 + z/2", [["1/(1 + z/2)", 0], [0, 1]])
TRANSPORT_SPEED = BCPHS.define(
    name="transport of speed 1 + z",
    interval=[0, 1],
    order=1,
    P={1: [[1]]},
    H=[["1 + z"]],
    inputs=["e1(1) - e1(0)"],
    outputs=["(e1(1) + e1(0))/2"],
)
# x_t = x_z - z x (P0 = -z, H = 1): damping that grows along the interval
DAMPED_TRANSPORT = BCPHS.define(
    name="transport damped by z",
    interval=[0, 1],
    order=1,
    P={1: [[1]], 0: [["-z"]]},
    H=[[1]],
    inputs=["e1(1) - e1(0)"],
    outputs=["(e1(1) + e1(0))/2"],
)
# the Timoshenko beam (phdesign's built-in, parameters 1) with K = EI = 1 + z/2: tapered
TAPERED_TIMOSHENKO = BCPHS.define(
    name="tapered Timoshenko beam",
    interval=[0, 1],
    order=1,
    P={
        0: [[0, 0, 0, -1], [0, 0, 0, 0], [0, 0, 0, 0], [1, 0, 0, 0]],
        1: [[0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 1], [0, 0, 1, 0]],
    },
    H=[["1 + z/2", 0, 0, 0], [0, 1, 0, 0], [0, 0, "1 + z/2", 0], [0, 0, 0, 1]],
    inputs=["e2(0)", "e4(0)", "e1(1)", "e3(1)"],
    outputs=["-e1(0)", "-e3(0)", "e2(1)", "e4(1)"],
)
