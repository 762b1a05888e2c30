"""Closed systems for the proved decay rate: exact data as the prover reads them, and a transport.

Shared by tests/numeric/certified/test_rate.py, tests/proofcheck/test_rate_check.py and
benchmarks/rate.py.
"""

from __future__ import annotations

from phdesign.numeric.certified.rate_problem import RateProblem, rate_problem
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.observer import ObserverDesign, gain_matrix, sensor_matrix

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


def closed(model: BCPHS, sensors: list[int], gain: str) -> RateProblem:
    """The exact closed error system of ``model`` with ``sensors`` and ``gain``."""
    design = ObserverDesign(
        model, sensor_matrix(sensors, model.n_ports), gain_matrix(gain, len(sensors))
    )
    err = design.error_system()
    defaults = model.parameter_defaults
    return rate_problem(
        name=model.name,
        order=model.order,
        interval=model.interval,
        H=model.H.xreplace(defaults),
        P=tuple(P.xreplace(defaults) for P in model.P),
        boundary=err.boundary_matrix,
        kernel=err.K,
    )
