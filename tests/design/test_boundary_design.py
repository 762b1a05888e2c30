"""The design objects on models with boundary systems (issue 26): observer, export, noise."""

from __future__ import annotations

import numpy as np
import pytest

import phdesign as phd


def test_observer_of_the_tip_mass_string_measures_the_mass_and_never_decays_uniformly():
    # y2 is the mass's velocity (a boundary-system output), injected as a force on the mass
    obs = phd.Observer(phd.load("string-tip-mass"), sensors=[2], gain=2)
    assert obs.classify().verdict == "asymptotic"
    report = obs.spectrum()
    assert report.no_decay
    assert report.spectral_abscissa == 0.0
    assert report.system == "observer error system"


def test_exports_carry_the_boundary_states():
    obs = phd.Observer(phd.load("string-motor"), sensors=[2], gain=1)
    for system, prefix in (("plant", ""), ("observer", "hat_"), ("error", "err_")):
        labels = obs.statespace(system).state_labels
        assert labels[-2:] == [f"{prefix}e(winding flux)", f"{prefix}e(rotor momentum)"]
    d = phd.discretize(phd.to_numeric(phd.load("string-motor")), "galerkin", 8)
    assert d.info["boundary_states"] == (17, 2)  # 2 (p + 1) - 1 (u_t(0) is imposed) + 2
    # an explicit order counts the motor's states too: 19 = 2 (8 + 1) + 1 is degree 8's
    exported = obs.export(dt=1e-3, order=d.dim)
    assert exported.A.shape[0] == d.dim  # the PDE's states and the motor's two


def test_simulated_error_energy_includes_the_mass_and_never_grows():
    obs = phd.Observer(phd.load("string-tip-mass"), sensors=[2], gain=1)
    run = obs.simulate(x0="x1: sin(pi*z)", t_end=4, samples=81)
    assert np.all(np.diff(run.H_err) <= 1e-12 * run.H_err[0])  # dissipative error system
    assert run.H_err[-1] < 0.5 * run.H_err[0]
    assert run.output_labels[-1] == "mass velocity"


def test_observer_based_control_through_the_motor():
    # u2 is the motor's voltage: V = -k i_hat. Fed its own current, the motor's winding gets
    # the resistance Rw + k (hand-derived: R_c + B k B^T with B = (1, 0)^T), the string none.
    obs = phd.Observer(phd.load("string-motor"), sensors=[2], gain=1)
    loop = phd.Loop(obs, actuate=2, feedback=3)
    plant = loop.controlled_plant()
    (motor,) = plant.boundary_systems
    Rw = next(s for s, _ in plant.parameters if s.name == "Rw")
    assert motor.R.tolist() == [[Rw + 3, 0], [0, 0]]
    assert motor.B is None
    assert plant.n_ports == 1  # the string's far end e1(1) is left
    result = loop.classify()
    assert result.plant.verdict == result.error.verdict == "asymptotic"
    assert result.verdict != "exponential"
    report = loop.spectrum()
    # separation (block-triangular in (x, x~)): the loop's abscissa is the larger of the two
    assert report.spectral_abscissa == max(
        report.plant.spectral_abscissa, report.error.spectral_abscissa
    )


@pytest.mark.slow  # three converged spectra and three classifications: ~30 s under load
def test_sweeps_over_the_mass():
    # every tip mass: no exponential decay (spectrum) and asymptotic by the ABLV test
    pytest.importorskip("xarray", reason="install the sweep extra")
    model = phd.load("string-tip-mass")
    common = {"sensors": [2], "grid": {"l1": "1"}, "param_grid": {"m": "0.5:2:3"}}
    options = {"scheduler": "synchronous", "progress": False}
    spectra = phd.sweep(model, **common, **options)
    assert np.all(spectra.spectral_abscissa.values == 0.0)
    verdicts = phd.sweep(model, **common, job="classify", **options)
    assert set(verdicts.verdict.values.ravel()) == {"asymptotic"}
    assert set(verdicts.best.values.ravel()) == {"ABLV"}
