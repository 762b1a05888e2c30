"""The sweep's ``gain`` job: each point is the gain report's numbers (issue 27)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("xarray", reason="install the sweep extra")
pytest.importorskip("zarr", reason="install the sweep extra")

from disturbance_models import damped_tip_wave, wave_hinf

import phdesign
from phdesign import Observer
from phdesign.design.plant import Plant
from phdesign.io import model_from_dict, model_to_dict
from phdesign.models import load_builtin

SYNC = {"scheduler": "synchronous", "progress": False}


def test_a_parameter_sweep_gives_the_gain_reports_norms():
    """Every point equals Plant(model with that k).gain(): the same refinement, exactly.

    The H∞ norm is also the hand-derived transfer function's (disturbance_models): to
    1e-8, the agreement the gain report converges to (tests/numeric/noise/).
    """
    ks = [0.25, 0.5]
    ds = phdesign.sweep(damped_tip_wave(0.5), job="gain", param_grid={"k": ks}, **SYNC)
    for i, k in enumerate(ks):
        report = Plant(damped_tip_wave(k)).gain()
        assert ds.hinf.values[i] == report.hinf.value
        assert ds.hinf_frequency.values[i] == report.hinf.frequency
        assert bool(ds.hinf_converged.values[i]) is report.hinf.converged is True
        assert bool(ds.h2_converged.values[i]) is report.h2.converged
        if report.h2.value is None:
            assert np.isnan(ds.h2.values[i])
        else:
            assert ds.h2.values[i] == report.h2.value
        assert ds.hinf.values[i] == pytest.approx(wave_hinf(k)[0], rel=1e-8)


def test_a_gain_sweep_gives_the_observers_gain_reports():
    data = model_to_dict(load_builtin("wave"))
    data["disturbances"] = {"B": [[1], [0]]}
    data["performance"] = {"outputs": ["integral(e1)"]}
    model = model_from_dict(data)
    ds = phdesign.sweep(
        model, job="gain", sensors=[2], grid={"l1": [0.5]}, options={"intensity": 0.1}, **SYNC
    )
    report = Observer(model, sensors=[2], gain=0.5).gain(intensity=0.1)
    assert ds.hinf.values[0] == report.hinf.value
    assert bool(ds.steady_state.values[0])
