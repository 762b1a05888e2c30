"""An outputs error is located: the outputs at fault, the conjugate phdesign derives.

Expected values by hand: negating output i negates row i of W_C Σ W_Bᵀ (= I for the
model as shipped, ``phdesign ports``), so only y_i is at fault and its conjugate is the
shipped output; negating P_N negates Q, hence W_C Σ W_Bᵀ = −I with every output as shipped,
and the identities hold again with P_N's sign reversed.
"""

from __future__ import annotations

from importlib import resources

import pytest

import phdesign as phd
from phdesign.core.errors import ModelFileError, ParameterError, PortError


def _variant(tmp_path, name: str, old: str, new: str):
    text = resources.files("phdesign.models").joinpath(f"{name}.toml").read_text()
    assert old in text
    path = tmp_path / f"{name}-variant.toml"
    path.write_text(text.replace(old, new))
    return str(path)


def test_beam_output_sign_error_names_y4_and_its_conjugate(tmp_path):
    path = _variant(tmp_path, "euler-bernoulli", '"-e1(1)"]', '"e1(1)"]')
    with pytest.raises(PortError) as info:
        phd.load(path)
    text = str(info.value)
    assert "W_C Σ W_Bᵀ = I fails" in text
    assert "outputs at fault: y4 = e1(1) pairs with -1·u4 (expected 1·u4)" in text
    assert "phdesign derives y4 = -e1(1) as the conjugate of u4 = e2'(1)" in text
    assert "y1" not in text
    assert "y3" not in text


def test_beam_p2_sign_slip_is_told_apart(tmp_path):
    path = _variant(
        tmp_path, "euler-bernoulli", "P2 = [[0, -1], [1, 0]]", "P2 = [[0, 1], [-1, 0]]"
    )
    with pytest.raises(PortError, match="sign slip in P2") as info:
        phd.load(path)
    assert "outputs at fault" not in str(info.value)


def test_wave_inputs_at_both_ends_swapped_outputs_are_both_named(tmp_path):
    # y = (e1(1), -e2(0)): W_C Σ W_Bᵀ = [[0, 1], [1, 0]] (each output pairs with the other
    # input): both rows are at fault, and the conjugates are the shipped outputs
    path = _variant(
        tmp_path, "wave", 'outputs = ["-e2(0)", "e1(1)"]', 'outputs = ["e1(1)", "-e2(0)"]'
    )
    with pytest.raises(PortError) as info:
        phd.load(path)
    text = str(info.value)
    assert "y1 = e1(1) pairs with 1·u2 (expected 1·u1)" in text
    assert "phdesign derives y1 = -e2(0)" in text
    assert "phdesign derives y2 = e1(1)" in text


def test_did_you_mean_model_and_parameter():
    with pytest.raises(ModelFileError, match=r"did you mean 'euler-bernoulli'\?"):
        phd.load("euler-bernouli")
    with pytest.raises(ParameterError, match=r"unknown parameter 'rhoo' \(did you mean 'rho'\?\)"):
        phd.load("wave").with_parameters({"rhoo": 2})
