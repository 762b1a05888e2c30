"""Ports: Q from integration by parts, R_ext, W_B, W_C and the three identities."""

from __future__ import annotations

import itertools

import pytest
import sympy

from phdesign.core.errors import PortError
from phdesign.models import builtin_names, load_builtin
from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.ports import (
    coefficient_matrix,
    derive_ports,
    q_matrix,
    sigma_matrix,
    trace_index,
    trace_vector,
)

z = sympy.Symbol("z", real=True)


def generic_P(order: int, size: int) -> list[sympy.Matrix]:
    """Generic symbolic P_1..P_N with P_k^T = (-1)^(k-1) P_k (P_0 is irrelevant here)."""
    matrices = [sympy.zeros(size)]
    for k in range(1, order + 1):
        A = sympy.Matrix(
            size,
            size,
            [sympy.Symbol(f"p{k}_{i}{j}", real=True) for i in range(size) for j in range(size)],
        )
        matrices.append(A + A.T if k % 2 == 1 else A - A.T)
    return matrices


@pytest.mark.parametrize(("order", "size"), [(1, 2), (2, 2), (3, 2), (4, 2), (3, 1), (2, 3)])
def test_energy_identity_is_exact(order, size):
    """Σ_k ∫_0^1 eᵀ P_k ∂^k e dz = ½ [φᵀ Q φ]_0^1 for e a generic polynomial vector.

    A polynomial of degree 2N with symbolic coefficients has independent values of
    e, e', ..., e^(2N-1) at both ends, so the identity checked for it holds for every
    smooth e: this is the integration by parts of DESIGN.md, done by sympy.
    """
    P = generic_P(order, size)
    e = sympy.Matrix(
        size, 1, lambda i, _: sum(sympy.Symbol(f"c{i}_{m}") * z**m for m in range(2 * order + 1))
    )
    lhs = sum(
        sympy.integrate((e.T * P[k] * e.diff(z, k))[0], (z, 0, 1)) for k in range(1, order + 1)
    )
    Q = q_matrix(P, order)
    phi = sympy.Matrix.vstack(*[e.diff(z, k) for k in range(order)])
    boundary = (phi.T * Q * phi)[0] / 2
    rhs = boundary.subs(z, 1) - boundary.subs(z, 0)
    assert sympy.expand(lhs - rhs) == 0


def paper_q_matrix(P, order):
    """The Q printed in the paper: Q_ij = (-1)^(j-1) P_(i+j-1) (sign slip, DESIGN.md)."""
    n = P[order].shape[0]
    return sympy.Matrix(
        sympy.BlockMatrix(
            [
                [
                    (-1) ** (j - 1) * sympy.Matrix(P[i + j - 1])
                    if i + j - 1 <= order
                    else sympy.zeros(n)
                    for j in range(1, order + 1)
                ]
                for i in range(1, order + 1)
            ]
        ).as_explicit()
    )


def test_beam_ports_match_the_paper_and_paper_q_gives_minus_identity():
    """Paper, Eq. (Eq:InputBeam).

    u = (e1(0), e1'(0), e2(1), e2'(1)) and y = (e2'(0), -e2(0), e1'(1), -e1(1)).
    """
    beam = load_builtin("euler-bernoulli")
    ports = derive_ports(beam)
    eye = sympy.eye(4)
    assert ports.W_C * ports.Sigma * ports.W_B.T == eye
    assert (ports.W_B * ports.Sigma * ports.W_B.T).is_zero_matrix
    assert (ports.W_C * ports.Sigma * ports.W_C.T).is_zero_matrix

    # The same ports with the paper's printed Q: W_C Σ W_Bᵀ = -I (DESIGN.md).
    Q = paper_q_matrix(beam.P, 2)
    R = sympy.Matrix(sympy.BlockMatrix([[Q, -Q], [eye, eye]]).as_explicit()) / sympy.sqrt(2)
    W_B, W_C = ports.U * R.inv(), ports.Y * R.inv()
    assert sympy.simplify(W_C * ports.Sigma * W_B.T) == -eye


def test_paper_q_agrees_for_odd_orders_only():
    """(-1)^(i-1) and (-1)^(j-1) agree on a block iff i + j is even, i.e. for odd k = i+j-1."""
    P = generic_P(3, 2)
    ours, papers = q_matrix(P, 3), paper_q_matrix(P, 3)
    n = 2
    for i, j in itertools.product(range(3), repeat=2):
        k = i + j + 1
        block = (slice(i * n, (i + 1) * n), slice(j * n, (j + 1) * n))
        if k > 3:
            continue
        same = ours[block] == papers[block]
        assert same == (k % 2 == 1)


@pytest.mark.parametrize("name", builtin_names())
def test_builtin_models_pass_every_identity(name):
    model = load_builtin(name)
    ports = derive_ports(model)
    N, n = model.order, model.size
    assert ports.Q.shape == (N * n, N * n)
    assert ports.W_B.shape == ports.W_C.shape == (N * n, 2 * N * n)
    assert all(value == 0 for value in ports.identities.values())
    assert ports.W_B.rank() == ports.W_C.rank() == N * n
    # energy identity through the ports: uᵀy = ½ vᵀ diag(Q, -Q) v for every v
    v = sympy.Matrix(ports.trace_vector)
    u, y = ports.U * v, ports.Y * v
    Qd = sympy.diag(ports.Q, -ports.Q)
    assert sympy.expand((u.T * y)[0] - (v.T * Qd * v)[0] / 2) == 0


def test_trace_ordering():
    """v = (φ(b); φ(a)), φ = (e, e', ...): DESIGN.md's convention."""
    v = trace_vector(2, 2)
    assert [str(s) for s in v] == [
        "e1(b)",
        "e2(b)",
        "e1'(b)",
        "e2'(b)",
        "e1(a)",
        "e2(a)",
        "e1'(a)",
        "e2'(a)",
    ]
    assert all(
        str(v[trace_index(i, k, s, 2, 2)]) == f"e{i}{chr(39) * k}({s})"
        for i in (1, 2)
        for k in (0, 1)
        for s in "ab"
    )


def test_sigma_size_is_2Nn():
    assert sigma_matrix(4).shape == (8, 8)  # DESIGN.md: 2Nn, not the paper's 2n


def wave_with_ports(inputs, outputs):
    return BCPHS.define(
        name="w",
        interval=(0, 1),
        order=1,
        P={1: [[0, 1], [1, 0]]},
        H=[[1, 0], [0, 1]],
        inputs=inputs,
        outputs=outputs,
    )


@pytest.mark.parametrize(
    ("inputs", "outputs", "message"),
    [
        # outputs not conjugate: y = (e2(0), e1(1)) flips one sign, so W_C Σ W_Bᵀ = diag(-1, 1)
        (
            ["e1(0)", "e2(1)"],
            ["e2(0)", "e1(1)"],
            r"W_C Σ W_Bᵀ = I fails: largest residual \|entry\| = 2",
        ),
        # dependent inputs
        (
            ["e1(0)", "2*e1(0)"],
            ["-e2(0)", "e1(1)"],
            "inputs are linearly dependent: rank of W_B is 1",
        ),
        # both inputs at one end: W_B Σ W_Bᵀ ≠ 0 (e1(0) and e2(0) are conjugate)
        (["e1(0)", "e2(0)"], ["e1(1)", "e2(1)"], "W_B Σ W_Bᵀ = 0 fails"),
    ],
)
def test_port_identity_failures_say_which_and_by_how_much(inputs, outputs, message):
    with pytest.raises(PortError, match=message):
        wave_with_ports(inputs, outputs)


def test_coefficient_matrix_rows():
    beam = load_builtin("euler-bernoulli")
    Y = coefficient_matrix(beam.outputs, 2, 2, "outputs")
    # y2 = -e2(0): a single -1 at the position of e2(a)
    assert list(Y.row(1)) == [0, 0, 0, 0, 0, -1, 0, 0]
