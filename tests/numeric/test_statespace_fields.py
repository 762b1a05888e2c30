r"""Named fields in the python-control exports: ``Observer.statespace(system, at=[...])``.

Expected values are the Timoshenko cantilever's static compliances.  Under the static tip
load P (u3 = e1(1) = P, the other inputs zero) the built-in ``timoshenko`` has, by hand,
φ(1) = P/(2EI) and w(1) = P/K + P/(3EI) (tests/numeric/discretization/test_fields.py),
and its equilibrium efforts are of degree ≤ 1, which the Legendre space holds exactly.  So
the DC gain from u3 is 1/(2EI) to the rotation and 1/K + 1/(3EI) to the tip deflection:

* plant: its DC gain (python-control's ``dcgain``; the undamped beam's A is invertible,
  the clamped-free problem having a unique static solution);
* observer: its DC gain from u3 with y_m = 0, the tip velocities of the static plant: the
  observer's equilibrium is then the plant's (tests/numeric/sampled/test_export_fields.py);
* ``modes="resolved"``: the modal truncation keeps the removed modes' static gain as a
  feedthrough, so the DC gain is unchanged (:mod:`phdesign.numeric.statespace`).

The tolerance 1e-9 allows the solves at degree 12 (round-off ~1e-12 observed).
"""

from __future__ import annotations

import numpy as np
import pytest

import phdesign as phd
from phdesign.core.errors import NumericError

pytest.importorskip("control")

VALUES = {"K": 3.0, "EI": 2.0, "rho": 1.5, "I_rho": 0.5}
K, EI = VALUES["K"], VALUES["EI"]
COMPLIANCE = {"rotation": 1 / (2 * EI), "w": 1 / K + 1 / (3 * EI)}


@pytest.fixture(scope="module")
def observer() -> phd.Observer:
    return phd.Observer(
        phd.load("timoshenko"), sensors=[3, 4], gain=1, parameters=VALUES, resolution=12
    )


def _dc(system, output: str, input_: str) -> float:
    import control

    gain = np.atleast_2d(control.dcgain(system))
    return float(gain[system.output_labels.index(output), system.input_labels.index(input_)])


@pytest.mark.parametrize("modes", ["all", "resolved"])
def test_the_plant_and_observer_dc_gains_are_the_static_compliances(observer, modes) -> None:
    plant = observer.statespace("plant", modes=modes, at=["rotation(1)", 1])
    assert plant.output_labels[-2:] == ["rotation(z=1)", "w(z=1)"]
    assert _dc(plant, "rotation(z=1)", "u3") == pytest.approx(COMPLIANCE["rotation"], rel=1e-9)
    assert _dc(plant, "w(z=1)", "u3") == pytest.approx(COMPLIANCE["w"], rel=1e-9)
    obs = observer.statespace("observer", modes=modes, at=["rotation(1)", 1])
    assert obs.output_labels[-2:] == ["rotation_hat(z=1)", "w_hat(z=1)"]
    assert obs.signal_descriptions["outputs"][-2:] == ("rotation_hat(z=1)", "w_hat(z=1)")
    rotation = _dc(obs, "rotation_hat(z=1)", "u3")
    assert rotation == pytest.approx(COMPLIANCE["rotation"], rel=1e-9)
    assert _dc(obs, "w_hat(z=1)", "u3") == pytest.approx(COMPLIANCE["w"], rel=1e-9)


def test_the_error_system_reads_the_rotation_error(observer) -> None:
    """ẽ0 = the static state of a unit tip load: the error output φ̃(1) is 1/(2EI) at t = 0."""
    error = observer.statespace("error", at="rotation(0.5)")
    assert error.output_labels[-1] == "rotation_err(z=0p5)"
    d = observer.plant.discrete()
    e0 = -np.linalg.solve(d.J - d.R, d.B @ np.array([0.0, 0.0, 1.0, 0.0]))
    # φ(0.5) = (0.5 - 0.125)/EI per unit load (the hand formula φ(z) = P (z - z²/2)/EI)
    assert float(error.C[-1] @ e0) == pytest.approx(0.375 / EI, rel=1e-9)


def test_an_unknown_field_names_the_known_ones(observer) -> None:
    with pytest.raises(NumericError, match=r"did you mean 'rotation'\?\); its fields are w, rot"):
        observer.statespace("observer", at="rotaton(1)")
