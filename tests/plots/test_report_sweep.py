"""Sweep figures fit for a report (issue 28): the title fits and names the grid's gains.

The title and the colour bar are read from the Figure; that the title fits is measured on
the drawn figure (its extent inside the figure's), not on pixels.
"""

from __future__ import annotations

import pytest

pytest.importorskip("xarray", reason="install the sweep extra")
pytest.importorskip("zarr", reason="install the sweep extra")

from string_models import wave_in_ms

import phdesign
from phdesign.plots.sweep import plot_sweep
from phdesign.sweep import summarize

SYNC = {"scheduler": "synchronous"}


@pytest.fixture(scope="module")
def gain_map():
    """Both diagonal entries of L are the grid's axes (a gain map over (l1, l2))."""
    grid = {"l1": "0.2,0.5,0.8", "l2": "0.3,0.6"}
    return phdesign.sweep("wave", sensors=[1, 2], grid=grid, **SYNC)


def _title_inside(fig) -> bool:
    fig.canvas.draw()
    box, frame = fig._suptitle.get_window_extent(), fig.bbox
    return box.x0 >= frame.x0 and box.x1 <= frame.x1


def test_gain_map_title_fits_and_names_the_grid_axes(gain_map):
    fig = plot_sweep(gain_map)
    title = fig.get_suptitle()
    assert "gain 1 on every sensor" not in title
    assert title.startswith("spectral abscissa: spectrum on wave")
    assert "l1, l2 (the grid's axes)" in " ".join(title.split())
    assert _title_inside(fig), title
    colorbar = fig.axes[1]
    assert colorbar.get_ylabel() == "spectral abscissa α [1/s]"


def test_summary_names_the_grid_axes(gain_map):
    first = str(summarize(gain_map)).splitlines()[0]
    assert first == "sweep: spectrum on wave (sensors 1,2; gain l1, l2 (the grid's axes))"


def test_one_axis_of_two_and_the_fixed_entry():
    ds = phdesign.sweep("wave", sensors=[1, 2], gain="0.5,2", grid={"l2": "0.3,0.6"}, **SYNC)
    assert ds.attrs["gain"] == "0.5, l2 (l2: the grid's axis)"


def test_the_model_time_unit_is_the_abscissa_unit(tmp_path):
    ds = phdesign.sweep(str(wave_in_ms(tmp_path)), sensors=[2], grid={"l1": "0.3,0.6"}, **SYNC)
    assert ds["spectral_abscissa"].attrs["units"] == "1/ms"
    fig = plot_sweep(ds)
    assert fig.axes[0].get_ylabel() == "spectral abscissa α [1/ms]"


def test_a_sensor_set_study_is_bars_with_verdict_and_kappa():
    ds = phdesign.sweep("euler-bernoulli", job="classify", sensor_sets="3;4;3,4", **SYNC)
    for figure in ("verdict", "kappa"):
        ax = plot_sweep(ds, figure).axes[0]
        assert not ax.get_lines()  # no line joins categories
        assert len(ax.patches) == 3
        assert [t.get_text() for t in ax.get_xticklabels()] == [
            "sensors 3",
            "sensors 4",
            "sensors 3,4",
        ]
        labels = [t.get_text() for t in ax.texts]
        for k, verdict in enumerate(ds.verdict.values):
            assert labels[k].splitlines()[0] == verdict
            kappa = float(ds.kappa.values[k])
            assert labels[k].splitlines()[1] == (
                "κ* = none" if kappa != kappa else f"κ* = {kappa:.3g}"
            )
            assert ax.patches[k].get_height() == pytest.approx(0.0 if kappa != kappa else kappa)
