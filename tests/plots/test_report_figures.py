"""Figures fit for a report (issue 28): titles that say what was run, units, no warnings.

Every check reads the Figure objects (titles, axis labels, number of axes, scales, limits)
or the warnings raised while drawing; nothing is timed and no pixel is compared.
"""

from __future__ import annotations

import warnings

import pytest
from string_models import wave_in_ms

import phdesign as phd


@pytest.fixture(scope="module")
def beam_loop():
    """The beam of notebook 07 at a small resolution: u3 = −K ŷ3, sensor y4."""
    return phd.Loop(phd.load("euler-bernoulli"), 3, 1, [4], 1, resolution=16)


def test_loop_simulation_figure_names_the_design_and_draws_u(beam_loop):
    run = beam_loop.simulate(x0="x1: 0, x2: z", t_end=1.0, samples=21)
    fig = run.plot()
    title = " ".join(fig.get_suptitle().split())
    for part in (
        "euler-bernoulli",
        "u3 = -K ŷ3",
        "K = [[1]]",
        "C_m = [[0, 0, 0, 1]]",
        "L = [[1]]",
    ):
        assert part in title, title
    panel = next(ax for ax in fig.axes if ax.get_title() == "control input u(t)")
    (line,) = panel.get_lines()
    assert line.get_ydata().tolist() == run.u[:, 2].tolist()  # u3, the actuated input
    assert panel.get_xlabel() == "time t [s]"


def test_loop_spectrum_figure_has_title_and_units(beam_loop):
    spectrum = beam_loop.spectrum(count=4, resolution=12, max_resolution=24)
    fig = spectrum.plot()
    title = " ".join(fig.get_suptitle().split())
    assert title.startswith("euler-bernoulli: u3 = -K ŷ3"), title
    ax = fig.axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("Re λ [1/s]", "Im λ [rad/s]")


@pytest.mark.parametrize("sensors", [None, [2]])
def test_a_run_from_rest_draws_without_a_matplotlib_warning(sensors):
    model = phd.load("wave")
    if sensors is None:
        run = phd.Plant(model, resolution=12).simulate(t_end=0.5, samples=11)
    else:
        run = phd.Observer(model, sensors=sensors, gain=1, resolution=12).simulate(
            t_end=0.5, samples=11
        )
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # "Data has no positive values ..." fails here
        fig = run.plot()
        fig.canvas.draw()
    decay = next(ax for ax in fig.axes if ax.get_title().startswith("decay"))
    assert decay.get_yscale() == "linear"  # nothing positive: no log scale
    assert "all zero" in decay.get_ylabel()


@pytest.fixture(scope="module")
def wave_observer():
    """The string with sensor y2 (wave's [displacement] is in m, its time in s)."""
    return phd.Observer(phd.load("wave"), sensors=[2], gain=0.5)


def test_noise_plot_ends_where_the_resolved_band_ends(wave_observer):
    report = wave_observer.noise(max_resolution=40)
    band = report.l2_gain.band
    assert band  # the wave's band is finite: its noise figure resolves up to there
    left = report.plot().axes[0]
    assert left.get_xscale() == "log"
    assert left.get_xlim()[1] == pytest.approx(band)
    for line in left.get_lines():
        assert max(line.get_xdata()) <= band * (1 + 1e-12)


def test_noise_plot_frequency_axis_is_in_the_model_time_unit(wave_observer, tmp_path):
    in_ms = phd.Observer(phd.load(wave_in_ms(tmp_path)), sensors=[2], gain=0.5)
    report = in_ms.noise(max_resolution=30)
    assert report.time_unit == "ms"
    assert report.plot().axes[0].get_xlabel() == "frequency ω [rad/ms]"
    in_s = wave_observer.noise(max_resolution=30)
    assert in_s.plot().axes[0].get_xlabel() == "frequency ω [rad/s]"


def test_tradeoff_rms_axis_has_the_model_unit():
    beam = phd.Observer(phd.load("euler-bernoulli"), sensors=[3, 4], gain=[0.1, 1])
    result = beam.tradeoff(direction=[0.1, 1.0], scales=[1.0, 2.0])  # RMS of w(1), in m
    ax = result.plot().axes[0]
    assert ax.get_xlabel().endswith("[m]"), ax.get_xlabel()
    assert ax.get_ylabel() == "decay rate −α [1/s]"


def test_three_spectrum_panels_keep_their_room():
    """Notebook 02's figure: three spectra side by side, each with its legend."""
    import numpy as np

    from phdesign.plots import new_figure

    lam = np.array([-1 + 5j, -1 - 5j, -2 + 40j, -20 + 900j])
    resolved = np.array([True, True, True, False])
    fig, axes = new_figure(1, 3, figsize=(10, 3))  # the notebook in a narrower window
    for k, ax in enumerate(axes):
        phd.plots.plot_spectrum(lam, resolved, ax=ax, abscissa=-1.0, title=f"design {k}")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # "constrained_layout not applied ..." fails here
        fig.canvas.draw()
    for ax in axes:
        assert ax.get_position().height > 0.5  # of the figure: not squeezed by legends
