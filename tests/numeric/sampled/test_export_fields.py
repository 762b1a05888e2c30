r"""Named fields in the exported observer: ``export(points=["rotation(1)", ...])``.

Expected values: the built-in ``timoshenko`` under the static tip load P (u = (0, 0, P, 0))
has the equilibrium x1 = P/K, x3 = P (1 − z)/EI and, by hand, φ(z) = P (z − z²/2)/EI and
w(z) = P z/K + P (z²/2 − z³/6)/EI (tests/numeric/discretization/test_fields.py): φ(1) =
P/(2EI), φ(0.5) = 3P/(8EI), w(1) = P/K + P/(3EI).

Why the exported observer must reproduce them: fed with constant inputs v = (u; y_m), the
sampled observer x̂_{k+1} = A x̂_k + B v has the fixed point x̂* = (I − A)⁻¹ B v.  For a
constant input both samplers are exact (the mean of a constant is the constant), so x̂* is
the continuous observer's equilibrium, (J − R − B K Bᵀ) ê + B (u + C_mᵀ L y_m) = 0 (D = 0
here).  With y_m = C_m Bᵀ ê_p of the plant's equilibrium ((J − R) ê_p + B u = 0) the
plant's ê_p solves it, so x̂* = ê_p (projected: its efforts are of degree ≤ 1, which a
degree-3 Legendre observer holds exactly).  The static plant's measured outputs are the
tip velocities y3 = e2(1) = y4 = e4(1) = 0.  The tolerance 1e-10 allows the solve with
cond(I − A) ≈ 50 (observed 46) and the exponential's round-off.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import phdesign as phd
from phdesign.core.errors import NumericError

P_TIP = 0.7
VALUES = {"K": 3.0, "EI": 2.0, "rho": 1.5, "I_rho": 0.5}
K, EI = VALUES["K"], VALUES["EI"]
POINTS = ["rotation(1)", "rotation(0.5)", 1]
NAMES = ["rotation(1)", "rotation(0.5)", "w(1)"]


@pytest.fixture(scope="module")
def exported():
    obs = phd.Observer(phd.load("timoshenko"), sensors=[3, 4], gain=1, parameters=VALUES)
    return obs.export(dt=1e-2, order=16, points=POINTS)


def test_the_exported_rotation_is_the_static_tip_load_formula(exported) -> None:
    assert list(exported.outputs) == ["yhat1", "yhat2", "yhat3", "yhat4", *NAMES]
    v = np.array([0.0, 0.0, P_TIP, 0.0, 0.0, 0.0])  # u = (0, 0, P, 0); y3 = y4 = 0
    x = np.linalg.solve(np.eye(exported.order) - exported.A, exported.B @ v)
    out = exported.C @ x + exported.D @ v
    expected = [P_TIP / (2 * EI), 3 * P_TIP / (8 * EI), P_TIP / K + P_TIP / (3 * EI)]
    assert out[4:] == pytest.approx(expected, rel=1e-10, abs=0)


def test_every_format_names_the_field_slots(exported, tmp_path) -> None:
    described = exported.continuous.output_descriptions[4:]
    assert described == (
        "rotation(1) = estimated rotation at z = 1",
        "rotation(0.5) = estimated rotation at z = 0.5",
        "w(1) = estimated displacement at z = 1",
    )
    (path,) = exported.write(str(tmp_path / "o.json"), "json")
    data = json.loads(Path(path).read_text(encoding="utf-8"))
    assert data["outputs"][4:] == NAMES
    assert data["output_descriptions"][4:] == list(described)
    (path,) = exported.write(str(tmp_path / "o.npz"), "npz")
    assert np.load(path)["outputs"].tolist()[4:] == NAMES
    # python-control refuses '.' in a name: rotation(0.5) is rotation(0p5) there
    assert exported.statespace().output_labels[4:] == ["rotation(1)", "rotation(0p5)", "w(1)"]
    pytest.importorskip("jinja2")
    header = next(f for f in exported.write(str(tmp_path / "c"), "c") if f.endswith(".h"))
    text = Path(header).read_text(encoding="utf-8")
    for k, line in enumerate(described, start=4):
        assert f"out[{k}] = {line}" in text
    (module,) = exported.write(str(tmp_path / "o.py"), "statespace")
    assert "out[4] = rotation(1) = estimated rotation at z = 1" in Path(module).read_text(
        encoding="utf-8"
    )


@pytest.mark.parametrize(
    ("points", "message"),
    [
        ("rotaton(1)", r"^points: rotaton\(1\): .*\(did you mean 'rotation'\?\); its fields are "
         r"w, rotation$"),
        (["rotation(1)", "rotation(1.0)"], r"^points: rotation\(1\) and rotation\(1.0\) both give "
         r"the output rotation\(1\)"),
        ("rotation(3)", r"^points: displacement point 3 is outside the interval \[0, 1\]"),
    ],
)  # fmt: skip
def test_bad_field_points_are_refused_before_any_work(points, message) -> None:
    obs = phd.Observer(phd.load("timoshenko"), sensors=[3, 4], gain=1)
    with pytest.raises(NumericError, match=message):
        obs.export(dt=1e-2, order=16, points=points)
