"""A new noise figure is one class: a Metric with a name and a value, judged by settle()."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

import phdesign as phd
from phdesign.numeric.noise.metrics import ErrorEnergy, Metric


@dataclass(frozen=True)
class TraceEP(Metric):
    """tr(E P): twice the expected error energy (E[H~] = tr(E P) / 2, exactly)."""

    name: str = "tr(E P)"
    smooth: bool = False

    def value(self, stats):
        return float(np.sum(stats.discrete.E * stats.covariance))


def test_a_metric_of_ones_own_is_reported_with_its_verdict():
    # the damped string (sensor 2, k = 0.5): white noise at the boundary gives an infinite
    # error energy, so tr(E P) diverges with E[H~], at twice its values (its definition)
    obs = phd.Observer(phd.load("wave"), sensors=[2], gain=0.5)
    report = obs.noise(performance="x2: 1", metrics=[TraceEP()])
    (figure,) = report.figures
    assert figure.name == "tr(E P)"
    np.testing.assert_allclose(figure.values, 2 * np.array(report.error_energy.values), rtol=1e-12)
    assert figure.diverges
    assert report.error_energy.diverges
    assert report.to_dict()["figures"][0]["name"] == "tr(E P)"
    assert "tr(E P)" in str(report)
    assert any(w.startswith("tr(E P) diverges") for w in report.warnings)


def test_the_built_in_figures_are_metrics():
    assert ErrorEnergy().label == "E[H~]"
    assert not ErrorEnergy().smooth
    with pytest.raises(NotImplementedError, match="defines no value"):
        Metric(name="nothing").value(None)  # type: ignore[arg-type]


def test_a_displacement_row_is_built_once_per_discretization_and_point():
    # the variance of w(1) reads the row c with w(1) = c ê at every call: it is the
    # discretization's displacement basis at the point, built once and shared read-only
    from phdesign.numeric.bridge import to_numeric
    from phdesign.numeric.discretization.functionals import displacement_at
    from phdesign.numeric.discretization.registry import discretize

    d = discretize(to_numeric(phd.load("euler-bernoulli")), "galerkin", 20)
    tip = displacement_at(d.model, 1.0)
    built = []
    basis = d.displacement_basis

    class Probe:
        model, displacement_basis = d.model, staticmethod(lambda z: built.append(1) or basis(z))

    probe = Probe()
    first, again = tip.row(probe), tip.row(probe)  # type: ignore[arg-type]
    assert len(built) == 1
    assert again is first
    np.testing.assert_array_equal(first, basis(np.array([1.0]))[0])
    assert not first.flags.writeable
    assert tip.row(d) is not first  # another owner, its own entry
