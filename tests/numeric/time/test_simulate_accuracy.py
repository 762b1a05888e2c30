"""Simulation accuracy: the error energy from the error state, its resolved floor, midpoint.

References: the exact decay rate of the Timoshenko error system (a root of its
characteristic determinant in mpmath, tests/characteristic.py), python-control's own
stepping of the exported error system, and the exact matrix exponential for the implicit
midpoint scheme.
"""

from __future__ import annotations

import json
import warnings
from dataclasses import replace

import mpmath
import numpy as np
import pytest
from characteristic import characteristic_determinant
from numeric_models import PAPER_SENSORS, numeric

from phdesign.models import load_builtin
from phdesign.numeric.discretization.registry import discretize, feedback_matrix
from phdesign.numeric.inputs import initial_state_function
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.result import ResolutionWarning
from phdesign.numeric.time.simulation import coupled_system, simulate
from phdesign.numeric.time.stepping import integrate

TIMOSHENKO_SENSORS = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


def _paper_beam():
    beam = load_builtin("euler-bernoulli")
    nm = numeric("euler-bernoulli")
    return nm, initial_state_function("x1: 0, x2: z - 0.9", nm, model=beam)


def test_error_energy_is_resolved_only_down_to_its_floor():
    # Timoshenko, sensors y3, y4, L = I, a smooth initial error.  The exact abscissa alpha
    # is the rightmost root of Delta (start: the spectrum's -0.779119); once the slowest
    # mode dominates, H_err falls by 100 in ln(100) / (2 |alpha|).  At degree 20 the
    # unresolved modes stop H_err near 4e-10 of H_err(0) (degree 40 reaches 1e-13): below
    # that the run must not answer (it said t = 14.74 for 1e-10; degree 40: 14.63).
    nm = numeric("timoshenko")
    delta = characteristic_determinant(nm, feedback_matrix(TIMOSHENKO_SENSORS, np.eye(2), 4))
    with mpmath.workdps(18):
        alpha = float(mpmath.re(mpmath.findroot(delta, mpmath.mpc(-0.78, 0.5))))
    assert abs(alpha + 0.7791193346988254) < 1e-9
    model = load_builtin("timoshenko")
    x0 = initial_state_function("x2: sin(pi*z)**6, x3: sin(pi*z)**4", nm, model=model)
    r = simulate(
        nm,
        TIMOSHENKO_SENSORS,
        np.eye(2),
        x0=x0,
        options=SimulationOptions(t_end=20.0, samples=201, resolution=20),
    )
    assert 1e-11 < r.resolved_floor < 1e-8
    assert 10.0 < r.resolved_until < 18.0
    assert any("resolved only down to" in w for w in r.warnings)
    t6, t8 = r.time_below(1e-6), r.time_below(1e-8)
    assert abs((t8 - t6) - np.log(100) / (2 * abs(alpha))) < 0.01 * (t8 - t6)  # measured 0.3 %
    with pytest.warns(ResolutionWarning, match="below what this discretization resolves"):
        assert r.time_below(1e-10) is None
    data = r.to_dict()
    assert data["resolved_floor"] == r.resolved_floor
    json.dumps(data, allow_nan=False)


def test_error_energy_comes_from_the_error_state():
    # Paper's beam, design 2 (alpha = -2.91): by t = 4.5 s H_err is ~1e-11 of H_err(0).
    # Plant minus observer loses the relative accuracy of that difference (2e-4 before);
    # the error system stepped on its own agrees with python-control's initial_response
    # of the exported error system (7e-8 was quoted for it) to 1e-7 relative at every
    # sample (measured: identically, both step with one exponential of A dt).
    import control

    from phdesign.numeric.statespace import error_statespace

    nm, x0 = _paper_beam()
    L = np.diag([0.1, 1.0])
    d = discretize(nm, "galerkin", 40)
    t = np.linspace(0.0, 4.5, 46)
    r = simulate(
        nm, PAPER_SENSORS, L, x0=x0, discrete=d, options=SimulationOptions(t_end=4.5, samples=46)
    )
    ref = control.initial_response(error_statespace(d, PAPER_SENSORS, L), T=t, X0=d.project(x0))
    H_ref = d.hamiltonian(ref.states.T)
    assert H_ref[-1] / H_ref[0] < 1e-10
    np.testing.assert_allclose(r.H_err, H_ref, rtol=1e-7)
    # the observer is the plant less the error, and the error coordinates are triangular
    np.testing.assert_allclose(r.states_hat, r.states - ref.states.T, atol=1e-9)
    _, A2, _ = coupled_system(d, feedback_matrix(PAPER_SENSORS, L, 4), coordinates="error")
    assert not np.any(A2[d.dim :, : d.dim])


def test_midpoint_controls_its_step_against_the_exact_solution():
    # Before, midpoint stepped at the output spacing (dt = 0.01): H_err 75 % off at t = 2
    # on the paper's beam.  Its substeps now keep the estimated error of the error system
    # below tol = 1e-6 (relative energy norm): H_err agrees with the exact exponential to
    # ~1e-9 of H_err(0).  The plant's incompatible initial state (x2(1) = 0.1 at a free
    # end) excites top modes that no affordable midpoint step resolves: it says so.
    nm, x0 = _paper_beam()
    options = SimulationOptions(t_end=2.0, samples=201, check_resolution=False)
    exact = simulate(nm, PAPER_SENSORS, np.diag([0.1, 1.0]), x0=x0, options=options)
    midpoint = replace(options, scheme="midpoint")
    mid = simulate(nm, PAPER_SENSORS, np.diag([0.1, 1.0]), x0=x0, options=midpoint)
    assert np.max(np.abs(mid.H_err - exact.H_err)) < 1e-6 * exact.H_err[0]
    assert abs(mid.H_err[-1] / exact.H_err[-1] - 1) < 1e-4
    assert mid.info["midpoint_error_estimate_error_system"] <= 1e-6
    assert mid.info["midpoint_substeps_error_system"] > 1
    assert any("midpoint did not reach its tolerance" in w and "plant" in w for w in mid.warnings)
    np.testing.assert_allclose(mid.H, exact.H, rtol=1e-5)


def test_midpoint_step_doubling_meets_its_tolerance_and_conserves_energy(rng):
    # Undamped wave, u = 0, smooth state: the Cayley map conserves the energy exactly and
    # the step-doubling estimate (||X_h - X_h/2|| / 3, order 2) bounds the error against
    # the exact flow (expm): both to the stated tolerance.
    d = discretize(numeric("wave"), "galerkin", 12)
    e0 = d.project(lambda z: np.column_stack([np.sin(np.pi * z), np.cos(np.pi * z)]))
    t = np.linspace(0.0, 3.0, 31)
    exact = integrate(d.E, d.J - d.R, d.B, e0, t)
    for tol in (1e-5, 1e-9):
        mid = integrate(d.E, d.J - d.R, d.B, e0, t, scheme="midpoint", tol=tol)
        assert mid.met_tolerance
        err = np.sqrt(np.max(np.sum(((mid.X - exact.X) @ d.E) * (mid.X - exact.X), axis=1)))
        scale = np.sqrt(np.max(np.sum((exact.X @ d.E) * exact.X, axis=1)))
        assert err / scale <= 3 * tol, (tol, err / scale, mid.substeps)
        # exact conservation, up to the round-off of 2^j squarings per output interval
        H = d.hamiltonian(mid.X)
        bound = 10 * (t.size - 1) * mid.substeps * np.finfo(float).eps
        assert np.max(np.abs(H / H[0] - 1)) < bound


def test_the_drift_warning_points_to_what_helps():
    # Airy, all sensors, degree 40: the exponential of the error system loses accuracy
    # (H_err 1.3e-3 off; the balance drifts by 5e-5).  The warning names midpoint, and
    # midpoint does help: within 2e-5 of the degree-16 exact run (resolved there).
    airy = load_builtin("airy")
    nm = numeric("airy")
    x0 = initial_state_function("x1: sin(pi*z)", nm, model=airy)
    options = SimulationOptions(t_end=1.0, samples=101, check_resolution=False)
    reference = simulate(nm, np.eye(3), np.eye(3), x0=x0, options=replace(options, resolution=16))
    drift = simulate(nm, np.eye(3), np.eye(3), x0=x0, options=replace(options, resolution=40))
    warning = next(w for w in drift.warnings if "energy balance drifts" in w)
    assert "scheme 'midpoint'" in warning
    assert np.max(np.abs(drift.H_err - reference.H_err)) > 1e-4 * reference.H_err[0]
    midpoint = replace(options, resolution=40, scheme="midpoint")
    fixed = simulate(nm, np.eye(3), np.eye(3), x0=x0, options=midpoint)
    assert np.max(np.abs(fixed.H_err - reference.H_err)) < 2e-5 * reference.H_err[0]


def test_simulation_result_prints_as_the_command_line():
    nm, x0 = _paper_beam()
    r = simulate(
        nm,
        PAPER_SENSORS,
        np.diag([0.1, 1.0]),
        x0=x0,
        options=SimulationOptions(t_end=0.2, samples=5, resolution=12),
    )
    assert str(r) == r.to_csv()
    assert len(repr(r)) <= 300
    assert "<table>" in r._repr_html_()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        json.loads(json.dumps(r.to_dict(), allow_nan=False))
