"""Propositions as data, and the Assumption 3.1 checker with its permutation search."""

from __future__ import annotations

import pytest
import sympy

from phdesign.models import load_builtin
from phdesign.symbolic.assumption import check_assumption
from phdesign.symbolic.expressions import Z
from phdesign.symbolic.propositions import VARIANTS, applicable_variants
from phdesign.symbolic.traces import Trace


def labels(variant, order, size, partition=None):
    return [t.label((0, 1)) for t in variant.traces(order, size, partition)]


def test_variant_table_in_paper_order():
    names = [f"{v.proposition}.{v.variant}" for v in VARIANTS]
    assert names == [
        "3.1.1", "3.1.2", "3.2.1", "3.2.2",
        "3.3.1", "3.3.2", "3.3.3", "3.3.4",
        "3.4.1", "3.4.2", "3.4.3", "3.4.4",
    ]  # fmt: skip
    assert [v.proposition for v in applicable_variants(1)] == ["3.1"] * 2 + ["3.2"] * 2
    assert {v.proposition for v in applicable_variants(3)} == {"3.1"}


def test_selected_traces_beam():
    # Prop 3.1 (N = 2): variant 1 sums ||e(a)||^2 + ||e'(a)||^2, variant 2 the same at b
    v311, v312 = VARIANTS[0], VARIANTS[1]
    assert labels(v311, 2, 2) == ["e1(0)", "e2(0)", "e1'(0)", "e2'(0)"]
    assert labels(v312, 2, 2) == ["e1(1)", "e2(1)", "e1'(1)", "e2'(1)"]
    # Prop 3.3 variant 3: ||e(b)||^2 + ||e'(b)||^2 + ||e(a)||^2 (paper's third line)
    assert labels(VARIANTS[6], 2, 2) == ["e1(1)", "e2(1)", "e1'(1)", "e2'(1)", "e1(0)", "e2(0)"]
    # Prop 3.4 variant 3 with x1 = (x1), x2 = (x2):
    # ||e(b)||^2 + ||(H1 x1)'(b)||^2 + ||(H1 x1)(a)||^2
    assert labels(VARIANTS[10], 2, 2, ((1,), (2,))) == ["e1(1)", "e2(1)", "e1'(1)", "e1(0)"]
    # variant 4: ||e(b)||^2 + ||(H2 x2)'(b)||^2 + ||(H1 x1)'(a)||^2
    assert labels(VARIANTS[11], 2, 2, ((1,), (2,))) == ["e1(1)", "e2(1)", "e2'(1)", "e1'(0)"]
    # the same variant with the blocks swapped selects the other component
    assert labels(VARIANTS[11], 2, 2, ((2,), (1,))) == ["e1(1)", "e2(1)", "e1'(1)", "e2'(0)"]


def test_indices_follow_the_contract_ordering():
    # v = (phi(b); phi(a)), phi = (e1, e2, e1', e2'): e2(a) is at N*n + 0*n + 1 = 5
    assert VARIANTS[6].indices(2, 2) == (0, 1, 2, 3, 4, 5)
    assert VARIANTS[2].traces(1, 2) == (Trace(1, 0, "a"), Trace(2, 0, "a"))


def test_partition_required_for_3_4():
    with pytest.raises(ValueError, match="needs the partition"):
        VARIANTS[8].traces(2, 2)


def test_assumption_beam_both_block_orders():
    beam = load_builtin("euler-bernoulli")
    check = check_assumption(beam.P[1], beam.P[2], beam.H, beam.parameter_defaults)
    assert check.holds
    # paper §IV-D: Q1 = 0, Q2 = 1 with x1 = momentum; swapping the blocks gives Q2 = -1,
    # which is still symmetric and invertible, so the assumption holds for both orders
    (p, q) = check.partitions
    assert (p.x1, p.x2, p.Q1, p.Q2) == ((1,), (2,), sympy.Matrix([[0]]), sympy.Matrix([[1]]))
    assert (q.x1, q.x2, q.Q2) == ((2,), (1,), sympy.Matrix([[-1]]))


def _permuted(M, perm):
    return sympy.Matrix(len(perm), len(perm), lambda i, j: M[perm[i], perm[j]])


def test_assumption_finds_a_permutation():
    # Two coupled beams, x = (p1, p2, k1, k2) written in the scrambled order (k2, p1, k1, p2).
    # Q1 = [[0, 1], [1, 0]] couples them through P1; Q2 = [[1, 2], [2, 1]] (symmetric,
    # det = -3). The block form holds for x1 = (p1, p2), x2 = (k1, k2).
    Q1 = sympy.Matrix([[0, 1], [1, 0]])
    Q2 = sympy.Matrix([[1, 2], [2, 1]])
    zero = sympy.zeros(2)
    P1 = sympy.Matrix(sympy.BlockMatrix([[zero, Q1], [Q1, zero]]))
    P2 = sympy.Matrix(sympy.BlockMatrix([[zero, -Q2], [Q2, zero]]))
    H = sympy.diag(1, 2 + Z, 3, 4)
    scramble = [3, 0, 2, 1]  # new component i is old component scramble[i]
    check = check_assumption(
        _permuted(P1, scramble), _permuted(P2, scramble), _permuted(H, scramble)
    )
    assert check.holds
    # old p1, p2 are new components 2 and 4; old k1, k2 are new 3 and 1
    x1_sets = {tuple(sorted(p.x1)) for p in check.partitions}
    assert (2, 4) in x1_sets
    first = next(p for p in check.partitions if sorted(p.x1) == [2, 4])
    # the reported blocks satisfy the assumption exactly in the reported order
    perm = [i - 1 for i in first.permutation]
    P1s, P2s = _permuted(P1, scramble), _permuted(P2, scramble)
    P1p, P2p = _permuted(P1s, perm), _permuted(P2s, perm)
    assert P1p == sympy.Matrix(sympy.BlockMatrix([[zero, first.Q1], [first.Q1, zero]]))
    assert P2p == sympy.Matrix(sympy.BlockMatrix([[zero, -first.Q2], [first.Q2, zero]]))
    assert first.Q1 == first.Q1.T
    assert first.Q2 == first.Q2.T
    assert first.Q2.det() != 0


def test_assumption_needs_a_pairing_not_only_a_split():
    # P1 couples components 1 and 4; P2 = [[0, -I], [I, 0]]. With x1 = (1, 2), x2 = (3, 4) in
    # the natural pairing, Q1 = P1[(1, 2), (3, 4)] = [[0, 1], [0, 0]] is not symmetric.
    # Pairing 2 with 3 and 1 with 4, i.e. x1 = (2, 1), gives Q1 = [[0, 0], [0, 1]] and
    # Q2 = P2[(3, 4), (2, 1)] = [[0, 1], [1, 0]]: symmetric, det Q2 = -1. The search must
    # find the pairing, not only the split.
    P1 = sympy.zeros(4)
    P1[0, 3] = P1[3, 0] = 1
    I2, O2 = sympy.eye(2), sympy.zeros(2)
    P2 = sympy.Matrix(sympy.BlockMatrix([[O2, -I2], [I2, O2]]))
    assert P1.extract([0, 1], [2, 3]) != P1.extract([0, 1], [2, 3]).T
    check = check_assumption(P1, P2, sympy.eye(4))
    assert check.holds
    first = check.partitions[0]
    assert (first.x1, first.x2) == ((2, 1), (3, 4))
    assert sympy.diag(0, 1) == first.Q1
    assert sympy.Matrix([[0, 1], [1, 0]]) == first.Q2


@pytest.mark.parametrize(
    ("P1", "P2", "H", "reason"),
    [
        (sympy.zeros(1), sympy.Matrix([[0]]), sympy.eye(1), "n must be even; found n = 1"),
        (
            sympy.zeros(2),
            sympy.Matrix([[0, -1], [1, 0]]),
            sympy.Matrix([[2, 1], [1, 2]]),
            "H not block diagonal",
        ),
        (sympy.eye(2), sympy.Matrix([[0, -1], [1, 0]]), sympy.eye(2), "diagonal blocks"),
    ],
)
def test_assumption_failures_name_the_condition(P1, P2, H, reason):
    check = check_assumption(P1, P2, H)
    assert not check.holds
    assert reason in check.reason


def test_assumption_singular_Q2():
    # P2 = [[0, 0], [0, 0]] has zero diagonal blocks and symmetric Q2 = 0, but Q2 is singular
    check = check_assumption(sympy.zeros(2), sympy.zeros(2), sympy.eye(2))
    assert not check.holds
    assert "Q2 singular" in check.reason
