"""Strings and coupled strings shared by the spectrum tests, and the honesty of a digits claim.

Also the built-in string in milliseconds (:func:`wave_in_ms`), for the figures' time units.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from phdesign.symbolic.model import BCPHS

SENSOR2 = np.array([[0.0, 1.0]])  # strings: y2 = e1(b), the velocity at the damper end


def wave_in_ms(folder: Path) -> Path:
    """Write a copy of the built-in ``wave`` whose ``[units] t`` is ``"ms"``; return its path."""
    from phdesign.models import builtin_toml

    text = builtin_toml("wave")
    assert 't = "s"' in text  # the copy differs from the original in its time unit only
    path = folder / "wave_ms.toml"
    path.write_text(text.replace('t = "s"', 't = "ms"'), encoding="utf-8")
    return path


def string(T: str, b: str = "1") -> BCPHS:
    """rho u_tt = (T u_z)_z with rho = 1, fixed at 0 (u_t(0) = 0), force input at b."""
    return BCPHS.define(
        name="string",
        interval=[0, b],
        order=1,
        P={1: [[0, 1], [1, 0]]},
        H=[[1, 0], [0, T]],
        inputs=["e1(0)", "e2(b)"],
        outputs=["-e2(0)", "e1(b)"],
    )


# A string whose stiffness grows along it: a z-dependent H (certificates refuse it)
GRADED_STRING = BCPHS.define(
    name="graded string",
    interval=[0, 1],
    order=1,
    P={1: [[0, 1], [1, 0]]},
    H=[[1, 0], [0, "1 + z"]],
    inputs=["e1(0)", "e2(1)"],
    outputs=["-e2(0)", "e1(1)"],
)


# Two strings (speeds 1 and sqrt(2)) coupled by a zero-order skew term between the momentum
# of the first and the strain of the second; the damper acts on the first string only.
COUPLED_STRINGS = BCPHS.define(
    name="two coupled strings",
    interval=[0, 1],
    order=1,
    P={
        0: [[0, 0, 0, -1], [0, 0, 0, 0], [0, 0, 0, 0], [1, 0, 0, 0]],
        1: [[0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 1], [0, 0, 1, 0]],
    },
    H=[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 2]],
    inputs=["e1(0)", "e3(0)", "e2(1)", "e4(1)"],
    outputs=["-e2(0)", "-e4(0)", "e1(1)", "e3(1)"],
)


def string_with_maxwell_end(d=1):
    """A string whose end z = 1 (a force port) carries a spring k in series with a damper r
    and a parallel damper d: x_c = spring elongation, x_c' = -r k x_c + u_c (u_c = the end's
    velocity), y_c = k x_c + d u_c the force; e2(1) = -y_c. Strictly input passive (d > 0)."""
    return BCPHS.define(
        name="string with a Maxwell end",
        interval=(0, 1),
        order=1,
        P={1: [[0, 1], [1, 0]]},
        H=[[1, 0], [0, 1]],
        inputs=["e1(0)", "e2(1)"],
        outputs=["-e2(0)", "e1(1)"],
        parameters={"d": d},
        boundary_systems=[
            {
                "name": "end",
                "ports": [2],
                "J": [[0]],
                "R": [[1]],
                "Q": [[2]],
                "G": [[1]],
                "D": [["d"]],
            }
        ],
    )


def honest(report, exact: float) -> bool:
    """The report's digits claim holds against the exact abscissa.

    Digits are relative to max(rate, |alpha|); reports without a rate measured against 1.
    """
    rate = getattr(report, "rate_scale", 1.0)
    claim = 10.0 ** (-report.digits) * max(rate, abs(report.spectral_abscissa))
    return abs(report.spectral_abscissa - exact) <= claim
