"""``phdesign certify`` and ``phdesign check``: the proof file, its re-check, a rejected claim."""

from __future__ import annotations

import json
import sys

import pytest

from phdesign.cli import main

pytest.importorskip("flint", reason="certificates need the extra 'certify' (python-flint)")


def run(capsys, *argv):
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_certify_writes_a_proof_that_check_verifies(capsys, tmp_path):
    proof = tmp_path / "string.json"
    status, out, err = run(
        capsys, "certify", "wave", "--sensors", "2", "--gain", "0.5", "-o", str(proof)
    )
    assert status == 0, err
    assert "spectral abscissa in [-0.5493061443" in out
    assert "the whole plane" in out
    data = json.loads(proof.read_text())
    assert data["format"] == "phdesign-proof"
    assert data["claim"]["whole_plane"] is True
    status, out, err = run(capsys, "check", str(proof))
    assert (status, err) == (0, "")
    assert out.startswith("verified")
    status, out, _ = run(capsys, "check", str(proof), "--json")
    assert json.loads(out)["verified"] is True
    # the same file again without --force: refused before any work, nothing changed
    before = proof.read_bytes()
    status, _, err = run(
        capsys, "certify", "wave", "--sensors", "2", "--gain", "0.5", "-o", str(proof)
    )
    assert status == 2
    assert "--force" in err
    assert proof.read_bytes() == before


def test_check_rejects_a_claim_moved_inside_the_true_abscissa(capsys, tmp_path):
    # wave-damper (k = 1/2 at z = 1) with the observer's gain 2 at z = 0: its abscissa is
    # -ln 3 = -1.0986 (tests/numeric/certified/test_certificate.py derives it); an upper
    # bound of -1.1 puts the true rightmost eigenvalues outside the claim
    proof = tmp_path / "string.json"
    argv = ("certify", "wave-damper", "--sensors", "1", "--gain", "2")
    status, out, err = run(capsys, *argv, "-o", str(proof))
    assert status == 0, err
    data = json.loads(proof.read_text())
    data["claim"]["abscissa_interval"] = [data["claim"]["abscissa_interval"][0], "-11/10"]
    wrong = tmp_path / "wrong.json"
    wrong.write_text(json.dumps(data))
    status, out, err = run(capsys, "check", str(wrong))
    assert status == 1
    assert err == ""
    assert out.startswith("rejected:")
    assert "is below ln|ζ|/τ" in out
    # a tampered system (another gain) changes Δ: the boundary rows no longer match
    data = json.loads(proof.read_text())
    data["system"]["G"][0][0] = "3"
    wrong.write_text(json.dumps(data))
    status, out, _ = run(capsys, "check", str(wrong))
    assert status == 1
    assert "U + G Y" in out


def test_certify_without_python_flint_says_which_extra(capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "flint", None)  # import flint now raises ImportError
    status, out, err = run(capsys, "certify", "wave", "--sensors", "2", "--gain", "0.5")
    assert status == 2
    assert out == ""
    assert err.count("\n") == 1
    assert "phdesign[certify]" in err
