"""Model files: exact round trips, for the built-in models and for random valid models."""

from __future__ import annotations

import os
import stat

import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from phdesign.core.errors import ModelFileError, OutputFileError
from phdesign.io import atomic_write, model_from_toml, model_to_toml, read_model, write_model
from phdesign.models import builtin_names, builtin_toml, load_builtin
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.ports import derive_ports, q_matrix, trace_vector
from phdesign.symbolic.printing import format_expression


@pytest.mark.parametrize("name", builtin_names())
def test_builtin_round_trip_is_exact(name):
    model = load_builtin(name)
    text = model_to_toml(model)
    again = model_from_toml(text)
    assert again == model
    assert model_to_toml(again) == text  # and printing is stable


def test_builtin_files_are_what_design_md_defines():
    wave = load_builtin("wave")
    assert [format_expression(e, wave.interval) for e in wave.inputs] == ["e1(0)", "e2(1)"]
    assert [format_expression(e, wave.interval) for e in wave.outputs] == ["-e2(0)", "e1(1)"]
    beam = load_builtin("euler-bernoulli")
    assert beam.P[2] == sympy.Matrix([[0, -1], [1, 0]])
    assert beam.P[0].xreplace(beam.parameter_defaults) == sympy.Matrix(
        [[-sympy.Rational(1, 5), 0], [0, 0]]
    )
    airy = load_builtin("airy")
    assert (airy.order, airy.size) == (3, 1)
    timo = load_builtin("timoshenko")
    assert timo.P[0] == sympy.Matrix([[0, 0, 0, -1], [0, 0, 0, 0], [0, 0, 0, 0], [1, 0, 0, 0]])


@st.composite
def random_models(draw) -> BCPHS:
    """Random valid BC-PHS: P_k of the right symmetry, P_N invertible, H diagonal > 0.

    Ports: u = M f_∂ and y = M^{-T} e_∂ with M invertible, so W_B = [M 0] and
    W_C = [0 M^{-T}] satisfy W_C Σ W_Bᵀ = M^{-T} Mᵀ = I and both isotropy identities.
    """
    order = draw(st.integers(1, 3))
    size = 2 if order % 2 == 0 else draw(st.integers(1, 2))  # skew P_N invertible needs n even
    ints = st.integers(-3, 3)
    nonzero = st.integers(1, 3)
    P = {}
    for k in range(1, order + 1):
        A = sympy.Matrix(size, size, lambda i, j: draw(ints))
        P[k] = A + A.T if k % 2 == 1 else A - A.T
    c = draw(nonzero)
    P[order] = sympy.eye(size) * c if order % 2 == 1 else sympy.Matrix([[0, -c], [c, 0]])
    B = sympy.Matrix(size, size, lambda i, j: draw(ints))
    S = sympy.Matrix(size, size, lambda i, j: draw(ints))
    P[0] = -B * B.T + (S - S.T)
    use_parameter = draw(st.booleans())
    H = sympy.diag(
        *[
            draw(
                st.sampled_from(
                    ["1", "2", "2 + z", "3/2", "k"]
                    if use_parameter
                    else ["1", "2", "1 + z**2", "1/2"]
                )
            )
            for _ in range(size)
        ]
    )
    parameters = {"k": draw(st.sampled_from([1, 0.5, 2.25]))} if use_parameter else {}
    interval = draw(st.sampled_from([(0, 1), (-1, 1), (0, 0.5)]))
    N_n = order * size
    M = sympy.eye(N_n)
    for _ in range(draw(st.integers(0, 3))):  # random unimodular row operations
        i, j = draw(st.integers(0, N_n - 1)), draw(st.integers(0, N_n - 1))
        if i != j:
            M[i, :] += draw(ints) * M[j, :]
    Q = q_matrix([sympy.zeros(size)] + [P[k] for k in range(1, order + 1)], order)
    v = sympy.Matrix(trace_vector(order, size))
    phi_b, phi_a = v[:N_n, :], v[N_n:, :]
    f = (Q * phi_b - Q * phi_a) / sympy.sqrt(2)
    e = (phi_b + phi_a) / sympy.sqrt(2)
    u, y = M * f, M.inv().T * e
    return BCPHS.define(
        name="random",
        interval=interval,
        order=order,
        P={k: v.tolist() for k, v in P.items()},
        H=[[str(x) for x in row] for row in H.tolist()],
        parameters=parameters,
        inputs=[format_expression(x, interval) for x in u],
        outputs=[format_expression(x, interval) for x in y],
    )


@settings(max_examples=25)
@given(random_models())
def test_random_models_round_trip_exactly(model):
    assert model_from_toml(model_to_toml(model)) == model
    assert all(value == 0 for value in derive_ports(model).identities.values())


def test_read_and_write_files(tmp_path):
    path = tmp_path / "beam.toml"
    path.write_text(builtin_toml("euler-bernoulli"))
    beam = read_model(path)
    assert beam == load_builtin("euler-bernoulli")
    out = tmp_path / "copy.toml"
    write_model(beam, out)
    assert read_model(out) == beam
    with pytest.raises(OutputFileError, match="exists; pass `force=True`"):
        write_model(beam, out)
    write_model(beam.with_parameters({"d": 0.5}), out, force=True)
    assert read_model(out) != beam
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")] == []


def test_atomic_write_gives_the_usual_file_mode(tmp_path):
    """The temporary file of mkstemp is 0600; the written file must honour the umask instead."""
    umask = os.umask(0o022)
    try:
        atomic_write(tmp_path / "x.txt", "x")
    finally:
        os.umask(umask)
    assert stat.S_IMODE((tmp_path / "x.txt").stat().st_mode) == 0o644


def test_atomic_write_refuses_unwritable_places(tmp_path):
    with pytest.raises(OutputFileError, match="cannot write"):
        atomic_write(tmp_path / "missing-folder" / "x.toml", "x")
    with pytest.raises(OutputFileError, match="is a folder"):
        atomic_write(tmp_path, "x", force=True)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("name = ", "not valid TOML"),
        ("name = 'x'", "lacks the key"),
        ("\x00", "not valid TOML"),
    ],
)
def test_bad_toml(text, message):
    with pytest.raises(ModelFileError, match=message):
        model_from_toml(text)


def test_missing_file(tmp_path):
    with pytest.raises(ModelFileError, match="cannot read model file"):
        read_model(tmp_path / "nope.toml")


def test_a_ports_table_without_inputs_is_refused_by_name():
    # the reading of [ports] comes before the inputs are used (a KeyError escaped once)
    from phdesign.core.errors import ModelFileError
    from phdesign.io import model_from_dict

    data = {
        "name": "x",
        "interval": [0, 1],
        "order": 1,
        "matrices": {"P1": [[0, 1], [1, 0]], "H": [[1, 0], [0, 1]]},
        "ports": {"outputs": "conjugate"},
    }
    with pytest.raises(ModelFileError, match=r"\[ports\] must hold exactly inputs and outputs"):
        model_from_dict(data)
