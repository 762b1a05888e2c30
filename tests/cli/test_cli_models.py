"""The command line: models, show, ports; exit status 2 and one stderr line on bad input."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from phdesign.cli import main
from phdesign.io import model_from_toml
from phdesign.models import builtin_names, builtin_toml, load_builtin


def run(capsys, *argv):
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_models_lists_builtins(capsys):
    status, out, _ = run(capsys, "models", "--json")
    assert status == 0
    assert [row["name"] for row in json.loads(out)] == list(builtin_names())


@pytest.mark.parametrize("name", builtin_names())
def test_show_toml_round_trips(capsys, name):
    status, out, _ = run(capsys, "show", name, "--toml")
    assert status == 0
    assert model_from_toml(out) == load_builtin(name)


def test_ports_json_contract(capsys):
    status, out, _ = run(capsys, "ports", "euler-bernoulli", "--json")
    assert status == 0
    data = json.loads(out)
    assert {"model", "order", "size", "Q", "W_B", "W_C", "identities"} <= set(data)
    assert data["identities"] == {
        "WB_Sigma_WBt": 0.0,
        "WC_Sigma_WCt": 0.0,
        "WC_Sigma_WBt_minus_I": 0.0,
    }
    # Q for the beam: Q_11 = P1 = 0, Q_12 = P2, Q_21 = -P2, Q_22 = 0 (DESIGN.md sign)
    assert data["Q"] == [
        ["0", "0", "0", "-1"],
        ["0", "0", "1", "0"],
        ["0", "1", "0", "0"],
        ["-1", "0", "0", "0"],
    ]
    assert data["W_B"][0][3] == "sqrt(2)/2"  # exact sympy strings


def test_param_override_reaches_the_model(capsys, tmp_path):
    out_file = tmp_path / "beam.toml"
    status, _, _ = run(
        capsys, "show", "euler-bernoulli", "--toml", "--param", "d=0.5", "-o", str(out_file)
    )
    assert status == 0
    assert "d = 0.5" in out_file.read_text()


def test_model_from_a_file(capsys, tmp_path):
    path = tmp_path / "wave.toml"
    path.write_text(builtin_toml("wave"))
    status, out, _ = run(capsys, "ports", str(path), "--json")
    assert status == 0
    assert json.loads(out)["size"] == 2


def test_existing_output_is_not_overwritten(capsys, tmp_path):
    target = tmp_path / "mine.toml"
    target.write_text("precious")
    status, _, err = run(capsys, "show", "wave", "--toml", "-o", str(target))
    assert status == 2
    assert "exists; pass --force" in err
    assert target.read_text() == "precious"


def test_code_in_a_model_file_is_never_run(tmp_path):
    """A trace expression that tries to run code is refused before anything runs."""
    witness = tmp_path / "pwned"
    text = builtin_toml("wave").replace(
        '"e2(1)"]', f"\"__import__('os').system('touch {witness}')\"]"
    )
    path = tmp_path / "evil.toml"
    path.write_text(text)
    result = subprocess.run(
        [sys.executable, "-m", "phdesign", "ports", str(path)], capture_output=True, text=True
    )
    assert result.returncode == 2
    assert len(result.stderr.splitlines()) == 1
    assert "unexpected character" in result.stderr
    assert "Traceback" not in result.stderr
    assert not witness.exists()
    assert Path(path).read_text() == text
