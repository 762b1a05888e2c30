"""Numerical honesty: each rule of issue 7 on a case built to trigger it.

1. A spectrum that did not converge says so (and prints no false digits).
2. Ill-conditioned rightmost eigenvalues are flagged (near a coalescence).
3. A simulation whose energy balance drifts beyond tolerance warns.
4. The classifier says which path computed κ*; its decisions never rest on floating point.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy

from phdesign.cli import main
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.inputs import initial_state_function
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.simulation import ENERGY_BALANCE_RTOL, simulate
from phdesign.symbolic.classify import classify
from phdesign.symbolic.observer import gain_matrix, sensor_matrix

TIP_SENSORS = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])  # beam y3, y4


def test_unconverged_spectrum_says_so():
    """Cap the resolution at the first refinement pair: the abscissa cannot reach 1e-14.

    The beam error system at L = diag(0.1, 1) needs degree ~30 for 1e-10 (benchmark);
    at degrees 8 and 12 the two abscissas differ far more than the requested 1e-14.
    """
    report = spectrum(
        to_numeric(load_builtin("euler-bernoulli")),
        TIP_SENSORS,
        np.diag([0.1, 1.0]),
        resolution=8,
        max_resolution=12,
        tol=1e-14,
    )
    assert not report.converged
    assert any("converge" in w for w in report.warnings)
    assert report.digits is not None
    assert report.digits < 14


def test_ill_conditioned_rightmost_is_flagged_from_the_command_line(capsys):
    """At the tuned optimum of the beam (8 digits, from ``tune``) three real eigenvalues
    of the error system coalesce near -5.8; the library-level check of the same point is
    ``test_numeric_spectrum.py::test_ill_conditioned_rightmost_is_flagged_not_dropped``.
    The command line must carry the flag and keep the rightmost eigenvalue."""
    gain = "[[0.1754978884476792, 0], [0, 1.0256694108445266]]"
    status = main(["spectrum", "euler-bernoulli", "--sensors", "3,4", "--gain", gain, "--json"])
    data = json.loads(capsys.readouterr().out)
    assert status == 0
    assert data["ill_conditioned"] is True
    assert data["converged"] is False
    assert data["rightmost"], "the rightmost eigenvalue must never be dropped silently"
    assert -6.2 < data["spectral_abscissa"] < -5.5


def _airy_run(resolution):
    airy = load_builtin("airy")
    nm = to_numeric(airy)
    x0 = initial_state_function("x1: sin(pi*z)", nm, model=airy)
    return simulate(
        nm,
        np.eye(3),
        np.eye(3),
        x0=x0,
        options=SimulationOptions(t_end=1.0, resolution=resolution),
    )


def test_healthy_simulation_balances_energy_to_round_off():
    """The paper's setting (FD, 140 states): the exact flow leaves only round-off.

    Its error energy is resolved only down to ~3e-9 of H_err(0) (t ~ 3.5 s): beyond, FD
    with 70 and 105 nodes per group disagree by more than 5 % (at t = 5: FD-105 is 3.3x
    and Galerkin-45 6x lower), and the run says so."""
    beam = load_builtin("euler-bernoulli")
    nm = to_numeric(beam)
    x0 = initial_state_function("x1: 0, x2: z - 0.9", nm, model=beam)
    result = simulate(
        nm, TIP_SENSORS, np.diag([0.1, 1.0]), x0=x0, options=SimulationOptions(method="fd")
    )
    assert not any("energy balance" in w for w in result.warnings)
    assert result.info["energy_balance_residual_plant"] < 1e-12
    assert result.info["energy_balance_residual_error_system"] < 1e-12
    assert any("resolved only down to" in w for w in result.warnings)
    assert 1e-10 < result.resolved_floor < 1e-8


def test_drifting_energy_balance_warns():
    """Airy (N = 3) at Galerkin degree 40: the weakly imposed second-derivative feedback
    makes the error system's norm grow like p^8 (about 1e13 here), so the matrix
    exponential loses digits and the balance ΔH = -∫ xᵀPx drifts (measured 5.3e-5 of max
    H; H_err itself is then off by 1.3e-3).  The plant alone (no feedback) keeps 1.5e-9."""
    result = _airy_run(40)
    assert result.info["energy_balance_residual_error_system"] > ENERGY_BALANCE_RTOL
    assert result.info["energy_balance_residual_plant"] < ENERGY_BALANCE_RTOL
    warning = next(w for w in result.warnings if "energy balance drifts" in w)
    assert "scheme 'midpoint'" in warning
    # ... while a modest degree stays within tolerance
    assert not any("energy balance" in w for w in _airy_run(12).warnings)


def test_simulate_cli_prints_the_drift_warning_on_stderr(capsys):
    status = main(
        [
            "simulate",
            "airy",
            "--sensors",
            "1,2,3",
            "--x0",
            "x1: sin(pi*z)",
            "--t-end",
            "1",
            "--resolution",
            "40",
            "--json",
        ]
    )
    out, err = capsys.readouterr()
    assert status == 0
    assert "phdesign: warning:" in err
    assert "energy balance drifts" in err
    assert json.loads(out)["warnings"]


@pytest.mark.parametrize("method", ["exact", "float", "auto"])
def test_classifier_reports_its_path_and_agrees(method):
    """Beam, y3 and y4, L = diag(1/10, 1): 3.4 variant 3 has κ* = min(l2, l1/(1+l1²)) = 10/101
    (paper §IV-D, corrected). Whatever computes κ*, the decision is exact and equal."""
    result = classify(
        load_builtin("euler-bernoulli"),
        sensor_matrix([3, 4], 4),
        gain_matrix([0.1, 1], 2),
        method=method,
    )
    variant = result.result("3.4", 3)
    assert variant.holds
    assert abs(variant.kappa_json() - 10 / 101) < 1e-12
    row = next(
        r for r in result.to_dict()["results"] if r["proposition"] == "3.4" and r["variant"] == 3
    )
    expected_path = "float" if method == "float" else "exact"
    assert row["path"] == expected_path
    if method != "float":
        assert sympy.sympify(row["kappa_exact"]) == sympy.Rational(10, 101)
