r"""The observer-based loop with a feedthrough D ≠ 0 meets its defining equations.

FEEDTHROUGH on staggered finite differences has a skew D ≠ 0: the observer's input
:math:`\hat u = u + K_o (y - \hat y)` (:math:`K_o = C_m^\top L C_m`) and the controller's
:math:`u_a = -K \hat y_a` are both implicit (:math:`y = B^\top \hat e + D u`,
:math:`\hat y = B^\top \hat e_{obs} + D \hat u`).  The expected maps are written here from
these equations, never from ``DiscretePHS.close()``, so that a dropped D fails.
"""

from __future__ import annotations

import numpy as np
import pytest
from numeric_models import FEEDTHROUGH, observer_loop_residual

from phdesign.core.errors import NumericError
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.control.assembly import NumericLoop, assemble
from phdesign.numeric.control.simulation import simulate_loop
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.time.options import SimulationOptions

# both sensors and a non-scalar L: (I + K_o D)⁻¹ differs from I in every block.  One
# actuated input checks the free input's map P = M S_rᵀ (there M K_a = K_a: K_a D is
# nilpotent), two check the feedback F = −M K_a C_f.
C_M, GAIN = np.eye(2), np.diag([0.5, 2.0])
K_O = C_M.T @ GAIN @ C_M
LOOPS = {
    "u1": NumericLoop((0,), np.array([[1.5]]), C_M, GAIN),
    "u1, u2": NumericLoop((0, 1), np.array([[1.5, 0.3], [-0.3, 1.0]]), C_M, GAIN),
}
RESOLUTION = 10


def _close(actual, expected):
    scale = max(float(np.max(np.abs(expected), initial=0.0)), 1.0)
    return float(np.max(np.abs(actual - expected), initial=0.0)) <= 1e-12 * scale


@pytest.mark.parametrize("actuated", list(LOOPS))
def test_the_assembled_maps_solve_plant_observer_and_controller(actuated):
    loop = LOOPS[actuated]
    d = discretize(to_numeric(FEEDTHROUGH), "fd", RESOLUTION)
    assert np.abs(d.D).max() > 0.1
    s = assemble(d, loop)
    n, Bt, D = d.dim, d.B.T, d.D
    zero = np.zeros_like(Bt)
    u_hat_x = s.C_u + K_O @ (s.C_y - s.C_yhat)  # û = u + K_o (y − ŷ)
    u_hat_v = s.D_u + K_O @ (s.D_y - s.D_yhat)
    assert _close(s.C_y, np.hstack([Bt, zero]) + D @ s.C_u)  # y = Bᵀ ê + D u
    assert _close(s.D_y, D @ s.D_u)
    assert _close(s.C_yhat, np.hstack([zero, Bt]) + D @ u_hat_x)  # ŷ = Bᵀ ê_obs + D û
    assert _close(s.D_yhat, D @ u_hat_v)
    a, r = list(loop.actuated), list(s.others)  # u_a = −K ŷ_a, u_r = v
    assert _close(s.C_u[a], -loop.K @ s.C_yhat[a])
    assert _close(s.D_u[a], -loop.K @ s.D_yhat[a])
    assert _close(s.C_u[r], np.zeros((len(r), 2 * n)))
    assert _close(s.D_u[r], np.eye(len(r)))
    JR = d.J - d.R  # E ê' = (J − R) ê + B u, E ê_obs' = (J − R) ê_obs + B û
    plant = np.hstack([JR, np.zeros((n, n))]) + d.B @ s.C_u
    observer = np.hstack([np.zeros((n, n)), JR]) + d.B @ u_hat_x
    assert _close(s.A, np.vstack([plant, observer]))
    assert _close(s.B, np.vstack([d.B @ s.D_u, d.B @ u_hat_v]))


@pytest.mark.parametrize("actuated", list(LOOPS))
def test_the_simulated_loop_reports_outputs_that_solve_the_loop(actuated):
    loop = LOOPS[actuated]
    nm = to_numeric(FEEDTHROUGH)
    d = discretize(nm, "fd", RESOLUTION)
    x0 = lambda z: np.column_stack([np.sin(np.pi * z), z])  # noqa: E731
    free = len(loop.actuated) == 1  # drive the other input
    run = simulate_loop(
        nm,
        loop,
        x0=x0,
        u=(lambda t: np.array([0.0, np.sin(2 * t)])) if free else None,
        options=SimulationOptions(t_end=0.5, samples=6, method="fd", resolution=RESOLUTION),
    )
    y_plant = run.states @ d.B + run.u @ d.D.T
    assert _close(run.y, y_plant)
    assert observer_loop_residual(d, K_O, run.states_hat, run.u, run.y, run.y_hat) < 1e-12
    a = list(loop.actuated)
    assert _close(run.u[:, a], -run.y_hat[:, a] @ loop.K.T)


def test_an_ill_posed_feedthrough_loop_is_refused_with_its_condition_number():
    # D = δ [[0, 1], [-1, 0]] gives D² = -δ² I, so K = D / δ² makes I + K D = 0
    d = discretize(to_numeric(FEEDTHROUGH), "fd", RESOLUTION)
    delta = d.D[0, 1]
    with pytest.raises(NumericError, match=r"ill-posed: I \+ K D is singular .*condition"):
        d.close(d.D / delta**2)
