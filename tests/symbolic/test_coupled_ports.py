"""``phdesign ports`` of a coupled model: the boundary systems' ports and the external ones."""

from __future__ import annotations

import json

from string_models import string_with_maxwell_end

from phdesign.cli import main
from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric


def ports_json(capsys, name):
    assert main(["ports", name, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_the_external_ports_are_those_the_numbers_use(capsys):
    # the numeric bridge names the coupled system's inputs and outputs on its own (the open
    # traces, then each system's w and z_c): the ports command must list the same, in order
    for name in ("string-tip-mass", "flexible-arm", "string-motor", "beam-tip-body"):
        data = ports_json(capsys, name)
        nm = to_numeric(load_builtin(name))
        external = data["external_ports"]
        assert [p["index"] for p in external] == list(range(1, nm.n_ports + 1))
        # the bridge writes the ends as a, b; the interval is [0, 1] in all four
        names = [y.replace("(a)", "(0)").replace("(b)", "(1)") for y in nm.output_labels]
        assert [p["output"] for p in external] == names
        assert len(external) == load_builtin(name).n_ports
    motor = ports_json(capsys, "string-motor")
    (system,) = motor["boundary_systems"]
    # the motor is joined to u1 = e1(0) (the rotor imposes the velocity); u2 = e1(1) and the
    # voltage are left: gyrator, no feedthrough, so K = 0 and F = S_pc G_c^T = -(0, -1)
    assert system["joined_inputs"] == ["u1 = e1(0)"]
    assert system["joined_outputs"] == ["y1 = -e2(0)"]
    assert (system["K"], system["F"]) == ([["0"]], [["0", "1"]])
    assert [(p["input"], p["source"], p["pde_index"]) for p in motor["external_ports"]] == [
        ("e1(1)", "PDE", 2),
        ("voltage", "motor", None),
    ]


def test_a_feedthrough_end_is_a_damper_in_k(tmp_path, capsys):
    # Maxwell end (tests/string_models.py): gyrator with D_c = d, so
    # K = -(S_pp + S_pc D_c S_cp) = -(0 + (-1) d (1)) = d and F = S_pc G_c^T = -1
    from phdesign.io import write_model

    path = tmp_path / "maxwell.toml"
    write_model(string_with_maxwell_end(d=3), path)
    data = ports_json(capsys, str(path))
    (system,) = data["boundary_systems"]
    assert (system["K"], system["F"]) == ([["d"]], [["-1"]])
    assert system["outputs"] == []
    assert data["external_ports"] == [
        {"index": 1, "input": "e1(0)", "output": "-e2(0)", "source": "PDE", "pde_index": 1}
    ]
    assert main(["ports", str(path)]) == 0
    text = capsys.readouterr().out
    assert "boundary system end: joined to u2 = e2(1) with y2 = e1(1) (gyrator)" in text
    assert "K = [[d]], F = [[-1]]" in text
    assert "  own ports: none" in text
    assert "  1: u1 = e1(0) -> y1 = -e2(0) (PDE)" in text


def test_a_model_without_boundary_systems_lists_its_open_ports(capsys):
    data = ports_json(capsys, "wave")
    assert data["boundary_systems"] == []
    assert [p["input"] for p in data["external_ports"]] == ["e1(0)", "e2(1)"]
