"""[units] in labels and JSON, and plant inputs from the command line (simulate --u)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.integrate import simpson

from phdesign import plots
from phdesign.cli import main
from phdesign.core.errors import ModelError
from phdesign.io import model_from_toml, model_to_toml
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.inputs import input_function
from phdesign.numeric.time.options import SimulationOptions
from phdesign.numeric.time.simulation import simulate
from phdesign.symbolic.model import BCPHS


def string(units=None):
    return BCPHS.define(
        name="string",
        interval=(0, 1),
        order=1,
        P={1: [[0, 1], [1, 0]]},
        H=[["1/rho", 0], [0, 1]],
        parameters={"rho": 1},
        inputs=["e1(0)", "e2(1)"],
        units=units,
    )


def test_plot_labels_carry_the_units_the_model_states_and_none_it_does_not():
    stated = string({"t": "ms", "energy": "kJ", "z": "mm", "rho": "g/mm"})
    assert model_from_toml(model_to_toml(stated)).units == stated.units
    for model, time, energy in (
        (stated, "time t [ms]", "energy [kJ]"),
        (string(), "time t", "energy"),  # nothing stated: no unit claimed
        (load_builtin("wave"), "time t [s]", "energy [J]"),  # the built-ins state SI
    ):
        run = simulate(
            to_numeric(model), options=SimulationOptions(t_end=0.1, samples=3, resolution=6)
        )
        ax = plots.plot_hamiltonians(run).axes[0]
        assert (ax.get_xlabel(), ax.get_ylabel()) == (time, energy)
        assert run.to_dict()["units"] == model.unit_map


def test_units_must_be_a_mapping_of_known_quantities_to_plain_text():
    with pytest.raises(ModelError, match="units must be a mapping"):
        string("s")
    with pytest.raises(ModelError, match=r"units\.rho = .* is malformed"):  # no backslash
        string({"rho": "kg\\m"})


def test_simulate_json_reports_the_units(capsys):
    assert main(["simulate", "wave-damper", "--t-end", "0.1", "--samples", "3", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["units"]["t"] == "s"
    assert out["units"]["k"] == "N*s/m"


def test_plant_inputs_from_the_command_line_drive_the_library_simulation(capsys):
    """simulate --u 'u2: sin(2*t)' equals simulate(u=...) and obeys Ḣ = uᵀy (no damping).

    The wave is lossless, so H(T) - H(0) = ∫ u2 y2 dt (Simpson on the output grid; the
    stepping holds u linear between samples, an O(dt²) = 1e-6 difference at dt = 1e-3).
    """
    argv = ["simulate", "wave", "--u", "u2: sin(2*t)", "--t-end", "2", "--samples", "2001"]
    assert main([*argv, "--json"]) == 0
    cli = json.loads(capsys.readouterr().out)
    nm = to_numeric(load_builtin("wave"))
    run = simulate(
        nm,
        u=lambda t: np.array([0.0, np.sin(2 * t)]),
        options=SimulationOptions(t_end=2.0, samples=2001),
    )
    np.testing.assert_array_equal(np.array(cli["y"]), run.y)
    t = run.t
    supplied = simpson(np.sin(2 * t) * run.y[:, 1], x=t)
    assert run.H[-1] - run.H[0] == pytest.approx(supplied, abs=1e-5)
    assert supplied > 0.01  # the input does work on the string


def test_input_expressions_hold_parameters_and_are_never_evaluated_as_python():
    beam = load_builtin("beam-tip-damper")
    nm = to_numeric(beam)
    u = input_function("u3: EI*cos(t) + 1/2", nm, model=beam)
    np.testing.assert_allclose(u(0.0), [0.0, 0.0, 1.5])
    assert input_function("  ", nm) is None
