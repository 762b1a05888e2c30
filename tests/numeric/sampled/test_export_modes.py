"""Exports: truncation to resolved modes, physical observer outputs, one closed loop.

Reference for the truncation: a string whose density makes the eigenproblem an Euler
equation.  With rho(z) = (1 + z)^-2, T = 1 (H = diag((1 + z)^2, 1)), velocity v and
strain: lambda^2 rho v = v'', so v = (1 + z)^s with s(s - 1) = lambda^2.  The error system
with sensor y2 = v(1) and gain k has v(0) = 0 and v'(1) = -k lambda v(1):
v = (1 + z)^s1 - (1 + z)^s2, s1,2 = 1/2 +- r, r = sqrt(1/4 + lambda^2), and
g(lambda) = [s1 2^(s1-1) - s2 2^(s2-1) + k lambda (2^s1 - 2^s2)] / (s1 - s2) = 0
(entire in lambda: both brackets change sign with s1 <-> s2).
"""

from __future__ import annotations

import warnings

import mpmath
import numpy as np
import pytest
from numeric_models import FEEDTHROUGH, PAPER_SENSORS, numeric

from phdesign.core.errors import NumericError
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import discretize, feedback_matrix
from phdesign.numeric.inputs import initial_state_function
from phdesign.numeric.statespace import error_statespace, observer_statespace, plant_statespace
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.simulation import simulate
from phdesign.symbolic.model import BCPHS

GRADED = BCPHS.define(
    name="graded string",
    interval=[0, 1],
    order=1,
    P={1: [[0, 1], [1, 0]]},
    H=[["(1 + z)**2", 0], [0, 1]],
    inputs=["e1(0)", "e2(1)"],
    outputs=["-e2(0)", "e1(1)"],
)


def _g(lam, k):
    r = mpmath.sqrt(mpmath.mpf(1) / 4 + lam**2)
    s1, s2 = mpmath.mpf(1) / 2 + r, mpmath.mpf(1) / 2 - r
    return (s1 * 2 ** (s1 - 1) - s2 * 2 ** (s2 - 1) + k * lam * (2**s1 - 2**s2)) / (s1 - s2)


def test_error_export_keeps_only_resolved_modes():
    # Degree 30, gain k = 2: all 62 poles have max Re ~ -0.012 (unresolved high
    # frequencies losing the damping); the resolved rightmost is -0.3645107, and the
    # truncated system's poles are roots of g (|g| below 1e-6 of |g| at distance 1e-4).
    import control

    k = 2.0
    d = discretize(to_numeric(GRADED), "galerkin", 30)
    C, L = np.array([[0.0, 1.0]]), np.array([[k]])
    full = error_statespace(d, C, L)
    cut = error_statespace(d, C, L, modes="resolved")
    assert np.max(control.poles(full).real) > -0.05
    poles = control.poles(cut)
    assert cut.nstates == len(cut.truncation.kept) == poles.size
    assert cut.truncation.n_removed == full.nstates - cut.nstates > 0
    for z in poles[np.argsort(-poles.real)][:6]:
        center = mpmath.mpc(z.real, z.imag)
        ring = center + 1e-4 * max(1, abs(z)) * mpmath.expjpi(mpmath.mpf(1) / 3)
        assert abs(_g(center, k)) < 1e-6 * abs(_g(ring, k)), z
    assert abs(np.max(poles.real) + 0.3645107231683) < 1e-9
    assert cut.state_labels[0] == "mode1"
    assert "resolved modes kept" in str(cut.truncation)
    # the observer has the same dynamics: the same resolved poles
    obs = observer_statespace(d, C, L, modes="resolved")
    np.testing.assert_allclose(
        np.sort_complex(control.poles(obs)), np.sort_complex(poles), atol=1e-9
    )


def test_truncation_matches_the_static_gain_and_says_what_it_removed():
    # Modal truncation is a spectral projection: G_full(s) - G_cut(s) is the sum of the
    # removed modes' partial fractions.  For boundary inputs their residues are large
    # (traces of high modes), so their sum is kept as a static feedthrough (match_dc):
    # exact at s = 0; the rest is O(|s| / min |lambda_removed|) of a large removed part,
    # measured 1.2 % of max |G| at s = 0.3i on the beam at degree 24 (without the
    # feedthrough: 200 %).
    d = discretize(numeric("euler-bernoulli"), "galerkin", 24)
    full, cut = plant_statespace(d), plant_statespace(d, modes="resolved")
    removed = np.array(cut.truncation.removed)
    assert removed.size == full.nstates - cut.nstates > 0
    assert np.min(np.abs(removed)) > 1000
    # (round-off of the Schur, Sylvester and T22 solves: 2e-12 of max |G(0)| measured)
    np.testing.assert_allclose(cut(0), full(0), rtol=1e-9, atol=1e-10 * np.abs(full(0)).max())
    gap = np.abs(full(0.3j) - cut(0.3j)).max() / np.abs(full(0.3j)).max()
    assert gap < 0.02, gap
    assert cut.input_labels == full.input_labels
    assert cut.truncation.to_dict()["n_removed"] == removed.size


def test_observer_outputs_are_physical_estimates():
    # Default observer outputs: the estimated model outputs, then the estimated state x
    # at both ends and the midpoint; the displacement option estimates w(z), which must
    # reproduce simulate()'s w_hat (an exact-in-time run of the same observer).
    import control

    beam = load_builtin("euler-bernoulli")
    nm = to_numeric(beam)
    x0 = initial_state_function("x1: 0, x2: z - 0.9", nm, model=beam)
    L = np.diag([0.1, 1.0])
    d = discretize(nm, "galerkin", 24)
    obs = observer_statespace(d, PAPER_SENSORS, L)
    assert obs.output_labels == [
        "yhat1", "yhat2", "yhat3", "yhat4",
        "x1_hat(z=0)", "x2_hat(z=0)", "x1_hat(z=0p5)", "x2_hat(z=0p5)",
        "x1_hat(z=1)", "x2_hat(z=1)",
    ]  # fmt: skip
    obs_w = observer_statespace(d, PAPER_SENSORS, L, quantity="displacement", z=[0.5, 1.0])
    assert obs_w.output_labels[4:] == ["w_hat(z=0p5)", "w_hat(z=1)"]
    r = simulate(
        nm,
        PAPER_SENSORS,
        L,
        x0=x0,
        discrete=d,
        options=SimulationOptions(t_end=1.0, samples=101, z_w=[0.5, 1.0]),
    )
    P = plant_statespace(d)
    # the observer's sensor inputs are named y3, y4 like the plant outputs they measure
    # (issue 28: one name per signal in every export), so interconnect joins them by name
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        loop = control.interconnect(
            [P, obs_w], inplist=P.input_labels, outlist=obs_w.output_labels[4:]
        )
    X0 = np.concatenate([d.project(x0), np.zeros(d.dim)])
    fr = control.forced_response(loop, T=r.t, U=np.zeros((4, r.t.size)), X0=X0)
    np.testing.assert_allclose(fr.outputs.T, r.w_hat, atol=1e-9 * np.abs(r.w).max())
    with pytest.raises(NumericError, match="defines no displacement"):
        observer_statespace(
            discretize(numeric("wave"), "galerkin", 8), [[0, 1]], [[1]], quantity="displacement"
        )
    with pytest.raises(NumericError, match="lie in the interval"):
        observer_statespace(d, PAPER_SENSORS, L, z=[2.0])


def test_close_solves_the_feedthrough_loop_once(rng):
    # u = v - K y with y = B^T e + D u (FD with a skew feedthrough D != 0): the loop's
    # matrices must satisfy the loop equations for any e, v, and the effective gain
    # G = (I + K D)^-1 K keeps the loop dissipative (sym(G) >= 0).
    d = discretize(to_numeric(FEEDTHROUGH), "fd", 20)
    assert np.any(d.D)
    K = feedback_matrix(np.array([[0.0, 1.0], [1.0, 0.0]]), np.array([[2.0, 0.5], [-0.5, 1.0]]), 2)
    loop = d.close(K)
    for _ in range(3):
        e, v = rng.standard_normal(d.dim), rng.standard_normal(2)
        u = np.linalg.solve(np.eye(2) + K @ d.D, v - K @ d.B.T @ e)
        y = d.B.T @ e + d.D @ u
        np.testing.assert_allclose(u, v - K @ y, atol=1e-12)
        np.testing.assert_allclose(loop.A @ e + loop.B @ v, (d.J - d.R) @ e + d.B @ u, atol=1e-12)
        np.testing.assert_allclose(loop.C @ e + loop.D @ v, y, atol=1e-12)
    assert np.min(np.linalg.eigvalsh(loop.gain + loop.gain.T)) > -1e-12
    np.testing.assert_array_equal(d.closed_matrix(K), loop.A)
    assert len(repr(loop)) <= 300
