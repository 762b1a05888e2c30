r"""Named fields in ``simulate``: the Timoshenko beam's rotation φ(z0, t) against closed forms.

The built-in ``timoshenko`` (x = (w_z − φ, ρ w_t, φ_z, I_ρ φ_t), e = Hx, clamped at 0) has
φ(z) = ∫_0^z x3 and w(z) = ∫_0^z x1 + ∫_0^z ∫_0^s x3 (derived in
tests/numeric/discretization/test_fields.py).  Two independent checks:

1. Static tip load P (u = (0, 0, P, 0)): the equilibrium x1 = P/K, x3 = P (1 − z)/EI,
   x2 = x4 = 0 stays put, and by hand φ(z) = P (z − z²/2)/EI, so φ(1) = P/(2EI),
   φ(0.5) = 3P/(8EI), w(1) = P/K + P/(3EI) (the same file's hand formulas).  The
   equilibrium's efforts are of degree ≤ 1, held exactly by the Legendre space, so the
   simulated values agree to round-off (1e-10 allows the exponential's, ~1e-13 observed).
2. Any motion: φ_t(1) = e4(1) = y4 (the model's fourth output, a boundary trace, computed
   from B^T ê and never from the field's row), so φ(1, t) − φ(1, 0) = ∫_0^t y4, and the
   same for the observer (φ̂_t(1) = ŷ4).  The time integral is taken by the trapezoidal
   rule on the output grid; its error is O(h²), and the test fits that rate.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

import phdesign as phd
from phdesign.core.errors import ArgumentError, NumericError

P_TIP = 0.7
VALUES = {"K": 3.0, "EI": 2.0, "rho": 1.5, "I_rho": 0.5}
K, EI = VALUES["K"], VALUES["EI"]


def _observer(resolution: int = 16) -> phd.Observer:
    return phd.Observer(
        phd.load("timoshenko"), sensors=[3, 4], gain=1, parameters=VALUES, resolution=resolution
    )


def test_the_rotation_under_a_static_tip_load_is_the_cantilever_formula() -> None:
    x0 = f"x1: {P_TIP / K!r}, x3: {P_TIP / EI!r}*(1 - z)"  # the equilibrium (docstring)
    run = _observer().simulate(
        x0, u=f"u3: {P_TIP!r}", t_end=2.0, samples=9, at=["rotation(1)", "rotation(0.5)", 1]
    )
    assert run.at == ("rotation(1)", "rotation(0.5)", "w(1)")
    expected = [P_TIP / (2 * EI), 3 * P_TIP / (8 * EI), P_TIP / K + P_TIP / (3 * EI)]
    assert run.at_values == pytest.approx(np.tile(expected, (9, 1)), rel=1e-10, abs=0)
    # the observer starts at rest: every estimate is 0 at t = 0
    assert run.at_values_hat[0] == pytest.approx([0.0, 0.0, 0.0], abs=0)
    csv = run.to_csv().splitlines()
    header = csv[0].split(",")
    assert header[-6:] == [
        "rotation(1)", "rotation(0.5)", "w(1)", "rotation_hat(1)", "rotation_hat(0.5)", "w_hat(1)"
    ]  # fmt: skip
    last = [float(v) for v in csv[-1].split(",")]
    assert last[header.index("rotation(1)")] == pytest.approx(P_TIP / (2 * EI), rel=1e-10)
    data = run.to_dict()
    assert data["at"] == ["rotation(1)", "rotation(0.5)", "w(1)"]
    assert list(data["at_values"]) == header[-6:]


def test_the_rotation_rate_at_the_tip_is_the_output_y4() -> None:
    obs = _observer(24)
    errors = {"plant": [], "observer": []}
    steps = (1000, 2000, 4000)
    for n in steps:
        run = obs.simulate("x4: sin(pi*z/2), x2: z**2", t_end=2.0, samples=n + 1, at="rotation(1)")
        for key, phi, y4 in (
            ("plant", run.at_values[:, 0], run.y[:, 3]),
            ("observer", run.at_values_hat[:, 0], run.y_hat[:, 3]),
        ):
            integral = phi[0] + cumulative_trapezoid(y4, run.t, initial=0.0)
            errors[key].append(float(np.max(np.abs(integral - phi))))
    for key, err in errors.items():
        rate = -np.polyfit(np.log(steps), np.log(err), 1)[0]
        assert 1.9 < rate < 2.1, f"{key}: φ(1) − ∫y4 at rate {rate:.3f}, errors {err}"
    assert errors["plant"][-1] < 1e-6  # and small: the trapezoid's h² (h = 5e-4) times |y4''|


@pytest.mark.parametrize(
    ("at", "exc", "message"),
    [
        ("rotaton(1)", NumericError, r"^at: rotaton\(1\): .*no field 'rotaton' \(did you mean "
         r"'rotation'\?\); its fields are w, rotation$"),
        ("rotation(2)", NumericError, r"^at: displacement point 2 is outside the interval"),
        ("tip", NumericError, r"^at: expected numbers in \[0, 1\] or fields at a point"),
        (True, ArgumentError, r"^at must be a point"),
        ([], ArgumentError, r"^at must be a point"),
        (["rotation(1)", "rotation(1.0)"], NumericError, r"both give the output rotation\(1\)"),
    ],
)  # fmt: skip
def test_bad_point_outputs_are_refused_before_any_work(at, exc, message) -> None:
    with pytest.raises(exc, match=message):
        _observer().simulate("x1: 1", t_end=0.1, samples=2, at=at)
