"""Decay rate against the H∞ norm over a family of gains (issue 27).

The string with ρ = T = 2 under a uniform force, sensor y2, gain k: its error is the
damped-tip string of damper r = k/2 scaled by 1/2 (disturbance_models.string_under_force), so
-α = ½ ln|(1 + r)/(1 - r)| and γ = γ₁(r)/2 with γ₁ hand-derived (disturbance_models).
"""

from __future__ import annotations

import math

import pytest
from disturbance_models import string_under_force, wave_hinf

from phdesign import Observer
from phdesign.core.errors import ObserverError


@pytest.fixture(scope="module")
def curve():
    obs = Observer(string_under_force(2.0), sensors=[2])
    return obs.tradeoff(scales=[0.5, 1.5, 3.0], against="hinf", intensity=0)


def test_each_point_is_the_closed_form(curve):
    for point, k in zip(curve.points, (0.5, 1.5, 3.0), strict=True):
        r = k / 2
        decay = 0.5 * math.log(abs((1 + r) / (1 - r)))
        assert point.decay_rate == pytest.approx(decay, abs=1e-9)  # the abscissa's 1e-10
        assert point.figure == pytest.approx(wave_hinf(r)[0] / 2, rel=1e-8)  # the report's


def test_the_pareto_front_and_the_outputs(curve, tmp_path):
    # r = 0.75 decays fastest (ln 7 / 2) with the least γ: it beats r = 0.25 and r = 1.5
    assert [p.pareto for p in curve.points] == [False, True, False]
    assert curve.pareto_points == (curve.points[1],)
    assert "decay rate -α against the H∞ norm from w1" in str(curve)
    assert curve.to_csv().splitlines()[0].startswith("l1,scale,spectral_abscissa")
    assert curve.to_dict()["pareto"] == [1]
    figure = curve.plot(tmp_path / "t.png")
    assert (tmp_path / "t.png").stat().st_size > 0
    assert "speed against disturbances" in figure.axes[0].get_title()


def test_the_figure_to_trade_is_named():
    obs = Observer(string_under_force(2.0), sensors=[2])
    with pytest.raises(ObserverError, match="against must be 'rms' or 'hinf'; found 'h2'"):
        obs.tradeoff(against="h2")
    with pytest.raises(ObserverError, match="input_intensity belongs to the RMS trade-off"):
        obs.tradeoff(against="hinf", input_intensity=1)
