"""Every export names each signal by the trace it is, and says how [feedback] renumbered.

Expected texts are the ports of the beam (DESIGN.md: inputs e1(0), e1'(0), e2(1), e2'(1);
outputs e2'(0), -e2(0), e1'(1), -e1(1)).  Closing its u3 (tip torque, u3 = -k y3) leaves
the external inputs e1(0), e1'(0), e2'(1): the external u3 is the model's u4 and y3 its y4.
"""

from __future__ import annotations

import numpy as np
import pytest

from phdesign.cli import main
from phdesign.core.errors import ObserverError
from phdesign.design.observer import Observer
from phdesign.io import write_model
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.sampled.export import export_observer
from phdesign.numeric.statespace import observer_statespace, plant_statespace
from phdesign.symbolic.closing import close_inputs

BEAM = load_builtin("euler-bernoulli")
TORQUE = close_inputs(BEAM, [3], [[1]])  # u3 = -y3: the tip rotation damped


def test_the_open_beam_names_each_slot_by_its_trace():
    pytest.importorskip("control")
    d = discretize(to_numeric(BEAM), "galerkin", 8)
    obs = observer_statespace(d, np.array([[0, 0, 1.0, 0], [0, 0, 0, 1.0]]), np.eye(2))
    assert obs.input_labels[4:] == ["y3", "y4"]  # as the export names them
    assert obs.output_labels[:4] == ["yhat1", "yhat2", "yhat3", "yhat4"]
    assert obs.signal_descriptions["inputs"] == (
        "u1 = e1(0)", "u2 = e1'(0)", "u3 = e2(1)", "u4 = e2'(1)", "y3 = e1'(1)", "y4 = -e1(1)",
    )  # fmt: skip
    assert obs.signal_descriptions["outputs"][0] == "yhat1 = estimate of y1 = e2'(0)"
    assert plant_statespace(d).signal_descriptions["outputs"][1] == "y2 = -e2(0)"


def test_a_feedback_closure_says_which_model_port_each_external_index_is(tmp_path):
    pytest.importorskip("jinja2")
    nm = to_numeric(TORQUE)
    sampled = export_observer(nm, np.array([[0, 0, 1.0]]), np.eye(1), dt=1e-3, order=12)
    inputs, outputs = sampled.descriptions()
    assert inputs == ("u1 = e1(0)", "u2 = e1'(0)", "u3 = e2'(1) (the model's u4)",
                      "y3 = -e1(1) (the model's y4)")  # fmt: skip
    assert outputs[2] == "yhat3 = estimate of y3 = -e1(1) (the model's y4)"
    assert sampled.renumbering == "[feedback] closes u3: external u3 = the model's u4 (y3 = y4)"
    sampled.write(str(tmp_path / "c"), "c")
    text = (tmp_path / "c" / "observer.h").read_text()
    assert " *   v[2] = u3 = e2'(1) (the model's u4)" in text
    assert " *   v[3] = y3 = -e1(1) (the model's y4)" in text
    data = sampled.to_dict()
    assert data["inputs"] == ["u1", "u2", "u3", "y3"]  # the names stay (JSON contract)
    assert data["input_descriptions"][2] == "u3 = e2'(1) (the model's u4)"
    assert "inputs v: u1 = e1(0), u2 = e1'(0), u3 = e2'(1) (the model's u4)" in str(sampled)


def test_sensors_out_of_range_after_a_closure_and_show_say_how_it_renumbered(capsys, tmp_path):
    numbering = (
        "[feedback] closes u3: the external u1, u2, u3 (and y1, y2, y3) are the model's "
        "u1, u2, u4 (y1, y2, y4)"
    )
    with pytest.raises(ObserverError) as info:
        Observer(TORQUE, sensors=[4], gain=1)
    assert str(info.value) == (
        f"sensors: output index 4 is out of range; expected 1..3 ({numbering})"
    )
    path = tmp_path / "torque.toml"
    write_model(TORQUE, path)
    assert main(["show", str(path)]) == 0
    assert numbering in capsys.readouterr().out.splitlines()
    assert main(["classify", str(path), "--sensors", "4", "--json"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("phdesign: error: --sensors: output index 4 is out of range")
    assert "the model's u1, u2, u4" in err
