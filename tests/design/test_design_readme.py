"""The getting-started block of the design object's noise, trade-off, export and loop runs.

Expected values that do not come from the code under test: the error system's converged
abscissa −2.9106562986 of the paper's design 2 (tests/numeric/spectrum/test_numeric_spectrum.py, 13
digits), which the trade-off's point s = 1 must reproduce as its decay rate; the export's
signal names (the JSON contract: plant inputs ``u1…`` then the measured ``y3, y4``;
``yhat1…`` then the displacement ``w(1)``); and separation: in coordinates
:math:`(x, \\tilde x)` the loop is block-triangular, so its abscissa is the larger of the
controlled plant's and the error system's.
"""

from __future__ import annotations

import pytest
from doc_blocks import DOCS, python_blocks

import phdesign as phd


def design_block() -> str:
    (block,) = [b for b in python_blocks(DOCS / "getting_started.rst") if "obs.noise()" in b]
    return block


def test_readme_noise_tradeoff_export_loop_block_runs():
    obs = phd.Observer(phd.load("euler-bernoulli"), sensors=[3, 4], gain=[0.1, 1])
    namespace = {"phd": phd, "obs": obs}
    report, trade, sampled, loop = (
        eval(line.split("  #")[0], namespace) for line in design_block().strip().splitlines()
    )
    (tip,) = report.performance
    assert tip.name == "w(1)"
    assert tip.converged
    assert round(tip.value, 4) == 0.1347  # the page's 4-digit claim
    assert report.error_energy.diverges
    # design 2's converged abscissa (module docstring); 1e-8: the page's 10 digits
    decay = {p.scale: p.decay_rate for p in trade.points}
    assert decay[1.0] == pytest.approx(2.9106562986, abs=1e-8)
    assert max(decay, key=lambda s: decay[s]) == 1.0
    assert sampled.inputs == ("u1", "u2", "u3", "u4", "y3", "y4")
    assert sampled.outputs == ("yhat1", "yhat2", "yhat3", "yhat4", "w(1)")
    assert (sampled.dt, sampled.sampler) == (1e-3, "average")
    # separation; 1e-9: the two blocks' abscissas converge to ~13 digits (the report's own)
    assert loop.converged
    expected = max(loop.plant_abscissa, loop.error_abscissa)
    assert loop.spectral_abscissa == pytest.approx(expected, abs=1e-9)
    assert loop.error_abscissa == pytest.approx(-2.9106562986, abs=1e-8)
    for value in (report, trade, sampled, loop):
        assert len(repr(value)) <= 300, type(value).__name__
        assert callable(getattr(value, "_repr_html_", None)), type(value).__name__
