r"""Named fields on the command line: ``simulate --at`` (also sampled, noisy, loop), ``tune --at``,
``export --at``.

The built-in ``timoshenko`` (unit parameters, clamped at 0) has the rotation
φ(z) = ∫_0^z x3 (``[fields.rotation]``).  Under the static tip load P (u3 = e1(1) = P) its
equilibrium is x1 = P/K, x3 = P (1 − z)/EI, x2 = x4 = 0, and by hand φ(1) = P/(2EI)
(derived in tests/numeric/discretization/test_fields.py; K = EI = 1 here): a run started
there keeps φ(1) = P/2.
"""

from __future__ import annotations

import csv
import io
import json

import pytest

from phdesign.cli import main

P_TIP = 0.7
STATIC = ("--x0", f"x1: {P_TIP}, x3: {P_TIP}*(1 - z)", "--u", f"u3: {P_TIP}")
RUN = ("--t-end", "1", "--samples", "5", "--resolution", "12")


def run(capsys, *argv):
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_simulate_at_writes_the_rotation_and_its_estimate(capsys) -> None:
    argv = ("simulate", "timoshenko", "--sensors", "3,4", "--gain", "1", *STATIC, *RUN)
    status, out, err = run(capsys, *argv, "--at", "rotation(1),rotation(0.5)")
    assert status == 0, err
    rows = list(csv.DictReader(io.StringIO(out)))
    assert {"rotation(1)", "rotation_hat(1)", "rotation(0.5)", "rotation_hat(0.5)"} <= set(rows[0])
    for row in rows:  # φ(1) = P/(2EI), φ(0.5) = 3P/(8EI) with EI = 1
        assert float(row["rotation(1)"]) == pytest.approx(P_TIP / 2, rel=1e-10)
        assert float(row["rotation(0.5)"]) == pytest.approx(3 * P_TIP / 8, rel=1e-10)
    assert float(rows[0]["rotation_hat(1)"]) == 0.0  # the observer starts at rest
    status, out, err = run(capsys, *argv, "--at", "rotation(1)", "--json")
    assert status == 0, err
    data = json.loads(out)
    assert data["at"] == ["rotation(1)"]
    assert data["at_values"]["rotation(1)"] == pytest.approx([P_TIP / 2] * 5, rel=1e-10)
    assert data["units"]["rotation"] == "rad"


@pytest.mark.parametrize("command", ["simulate", "tune", "export"])
def test_an_unknown_field_is_one_line_naming_the_known_fields(capsys, tmp_path, command) -> None:
    extra = {
        "simulate": (),
        "tune": ("--sensors", "3,4", "--max-rms", "1"),
        "export": ("--sensors", "3,4", "--gain", "1", "--dt", "1e-2", "--format", "json",
                   "-o", str(tmp_path / "o.json")),
    }[command]  # fmt: skip
    status, out, err = run(capsys, command, "timoshenko", *extra, "--at", "rotaton(1)")
    assert status == 2
    assert out == ""
    assert err.count("\n") == 1
    assert "no field 'rotaton' (did you mean 'rotation'?); its fields are w, rotation" in err
    assert not (tmp_path / "o.json").exists()


@pytest.mark.parametrize(
    ("command", "extra"),
    [
        (("simulate",), ("--dt", "0.05", "--observer-resolution", "8")),
        (("simulate",), ("--noise-intensity", "0.01", "--seed", "1")),
        (("loop", "simulate"), ("--actuate", "4")),
    ],
    ids=["sampled", "noisy", "loop"],
)
def test_sampled_noisy_and_loop_simulations_report_named_fields(capsys, command, extra) -> None:
    """The observer starts at the plant's equilibrium too: φ(1) = P/2 for both (EI = 1).

    Sensor noise moves only the estimate, so the noisy run checks the plant's column.
    """
    argv = (*command, "timoshenko", "--sensors", "3,4", *STATIC, *RUN, *extra)
    status, out, err = run(capsys, *argv, "--xhat0", STATIC[1], "--at", "rotation(1)")
    assert status == 0, err
    rows = list(csv.DictReader(io.StringIO(out)))
    assert len(rows) == 5
    columns = (
        ["rotation(1)"] if "--noise-intensity" in extra else ["rotation(1)", "rotation_hat(1)"]
    )
    for row in rows:
        for column in columns:
            assert float(row[column]) == pytest.approx(P_TIP / 2, rel=1e-10)


@pytest.mark.slow
def test_tune_at_rotation_meets_its_bound_on_the_rotation(capsys) -> None:
    """``tune --at rotation(1) --max-rms R``: the constraint is on φ(1)'s error RMS.

    What is checked is the contract, not a closed form: the performance output is the
    rotation, the bound holds at the tuned gain, and rms² is the variance reported beside it.
    """
    argv = ("tune", "timoshenko", "--sensors", "3,4", "--at", "rotation(1)", "--max-rms", "1")
    status, out, err = run(capsys, *argv, "--json")
    assert status == 0, err
    data = json.loads(out)
    (perf,) = data["noise"]["performance"]
    assert perf["name"] == "rotation(1)"
    assert perf["converged"]
    assert data["feasible"]
    assert data["rms"] <= 1.0
    assert data["rms"] == pytest.approx(perf["variance"] ** 0.5, rel=1e-12)
