"""Models with disturbances and their hand-derived closed forms, shared by the tests.

The damped-tip string of PIETOOLS' library (ρ = T = 1, fixed at 0, a damper k at the tip,
a uniform force w, z = ∫₀¹ u_t dz): its transfer function, H∞ norm and H₂ norm; and the
paper's beam under a uniform load with its tip deflection judged.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar

from phdesign.io import model_from_dict, model_to_dict
from phdesign.models import load_builtin
from phdesign.symbolic.model import BCPHS


def damped_tip_wave(k: float, **changes):
    """PIETOOLS' damped-tip string: ρ = T = 1, u(0) = 0, u_z(1) = -k u_t(1), force w."""
    definition = {
        "name": "damped-tip wave",
        "interval": (0, 1),
        "order": 1,
        "P": {1: [[0, 1], [1, 0]]},
        "H": [[1, 0], [0, 1]],
        "parameters": {"k": k},
        "inputs": ["e1(0)", "e2(1)"],
        "feedback": {"inputs": [2], "gain": [["k"]]},
        "disturbances": {"B": [[1], [0]]},
        "performance": ["integral(e1)"],
    }
    return BCPHS.define(**{**definition, **changes})


def beam_under_load():
    """The paper's beam (d = 0.2) under a uniform load f(t), its tip deflection judged."""
    data = model_to_dict(load_builtin("euler-bernoulli"))
    data["disturbances"] = {"B": [[1], [0]]}
    data["performance"] = {"outputs": ["w(1)"]}
    return model_from_dict(data)


def wave_transfer(s: complex, k: float) -> complex:
    r"""G(s) = Z(s)/W(s), z = ∫₀¹ u_t dz, derived by hand (Laplace in t, zero state).

    s²U = U'' + W on (0, 1), U(0) = 0, U'(1) = -k s U(1).  U = W/s² + A cosh(sz) +
    C sinh(sz); U(0) = 0 gives A = -W/s²; the tip condition gives
    C = (W/s²)(k cosh s + sinh s - k)/(cosh s + k sinh s).  Then
    Z = s ∫₀¹ U dz = W/s - W sinh(s)/s² + C (cosh s - 1).
    """
    ch, sh = np.cosh(s), np.sinh(s)
    return 1 / s - sh / s**2 + (k * ch + sh - k) * (ch - 1) / (s**2 * (ch + k * sh))


def wave_hinf(k: float) -> tuple[float, float]:
    """sup_ω |G(iω)|: a grid over [0, 40], then Brent on the best bracket (to 1e-12 in ω)."""
    w = np.linspace(1e-6, 40.0, 40001)
    g = np.abs(wave_transfer(1j * w, k))
    i = int(np.argmax(g))
    found = minimize_scalar(
        lambda x: -abs(wave_transfer(1j * x, k)),
        bounds=(w[max(i - 1, 0)], w[i + 1]),
        method="bounded",
        options={"xatol": 1e-12},
    )
    return -float(found.fun), float(found.x)


def wave_h2_squared(k: float) -> float:
    r"""‖G‖₂² = ∫₀^∞ g(t)² dt from d'Alembert (derived by hand).

    The impulse w = δ starts the string with u_t = 1, u_z = 0.  The Riemann invariants
    α = u_t + u_z (moving left) and β = u_t - u_z (moving right) are 1 at t = 0; the
    fixed end reflects β = -α, the damper α = r β with r = (1 - k)/(1 + k).  So the
    boundary signals a(τ) = α(0, τ), b(τ) = β(1, τ) are constant on unit intervals:
    a_0 = b_0 = 1, a_j = r b_(j-1), b_j = -a_(j-1).  With c_j = (a_j + b_j)/2,
    g(j + s) = ½∫_t^(t+1) (a + b) dτ = (1 - s) c_j + s c_(j+1), so
    ∫_j^(j+1) g² = (c_j² + c_j c_(j+1) + c_(j+1)²)/3, and c_(j+2) = -r c_j makes the
    sum geometric: (T_0 + T_1)/(1 - r²).
    """
    r = (1 - k) / (1 + k)
    c = [1.0, (r - 1) / 2, -r]
    terms = [(c[j] ** 2 + c[j] * c[j + 1] + c[j + 1] ** 2) / 3 for j in (0, 1)]
    return sum(terms) / (1 - r**2)


def string_under_force(c: float):
    """The built-in string with ρ = T = c (inputs e1(0), e2(1)) under a uniform force w1.

    ∫₀¹ e1 dz is judged.  With sensor y2 = e1(1) and gain k the estimation error is the
    damped-tip string: dividing by c, u_tt = u_zz + w/c and u_z(1) = -(k/c) u_t(1), so its
    norms are those of the unit string with damper k/c, divided by c.
    """
    data = model_to_dict(load_builtin("wave"))
    data["parameters"] = {"rho": c, "T": c}
    data["disturbances"] = {"B": [[1], [0]]}
    data["performance"] = {"outputs": ["integral(e1)"]}
    return model_from_dict(data)


def string_with_unknown_tip_force(performance: list[str]):
    """The unit string (inputs e1(0), e2(1)) whose tip stress u2 is an unknown input."""
    return BCPHS.define(
        name="string with an unknown tip force",
        interval=(0, 1),
        order=1,
        P={1: [[0, 1], [1, 0]]},
        H=[[1, 0], [0, 1]],
        inputs=["e1(0)", "e2(1)"],
        disturbances={"unknown": [2]},
        performance=performance,
    )
