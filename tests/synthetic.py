"""Synthetic valid BC-PHS models for property tests and benchmarks (not a test module).

Ports: with Q the (symmetric) matrix of the ports layer, ``u = A Q (phi(b) - phi(a))``
and ``y = A^{-T} (phi(b) + phi(a)) / 2`` satisfy ``u^T y = 1/2 v^T diag(Q, -Q) v``,
the energy identity, for every invertible ``A``: they are ``sqrt(2) A f_d`` and
``A^{-T} e_d / sqrt(2)``.  An integer unimodular ``A`` keeps every coefficient an
integer or a half.
"""

from __future__ import annotations

import random

import sympy

from phdesign.symbolic.model import BCPHS
from phdesign.symbolic.ports import q_matrix, trace_vector


def random_P(order: int, size: int, rnd: random.Random) -> list[sympy.Matrix]:
    """P_0 (dissipative), P_1..P_N with P_k^T = (-1)^(k-1) P_k and P_N invertible."""
    P = []
    d = sympy.zeros(size)
    d[0, 0] = -rnd.randint(0, 2)
    P.append(d)
    for k in range(1, order + 1):
        while True:
            M = sympy.Matrix(size, size, lambda i, j: rnd.randint(-2, 2))
            M = M + M.T if k % 2 == 1 else M - M.T
            if k < order or M.det() != 0:
                break
            if size % 2 == 1 and k % 2 == 0:
                # an odd skew matrix is singular: use a symmetric-looking invertible fallback
                raise ValueError("order even and size odd: P_N cannot be invertible")
        P.append(M)
    return P


def unimodular(n: int, rnd: random.Random) -> sympy.Matrix:
    """An integer matrix with determinant ±1 (product of elementary operations)."""
    A = sympy.eye(n)
    for _ in range(2 * n):
        i, j = rnd.sample(range(n), 2) if n > 1 else (0, 0)
        if i != j:
            A[i, :] = A[i, :] + rnd.choice([-1, 1]) * A[j, :]
    if rnd.random() < 0.5:
        A[0, :] = -A[0, :]
    return A


def ports_for(P: list[sympy.Matrix], order: int, size: int, A: sympy.Matrix):
    """Inputs and outputs (trace expressions) of the module docstring."""
    Q = q_matrix([sympy.ImmutableMatrix(M) for M in P], order)
    v = sympy.Matrix(trace_vector(order, size))
    nn = order * size
    phi_b, phi_a = v[:nn, 0], v[nn:, 0]
    u = A * Q * (phi_b - phi_a)
    y = A.inv().T * (phi_b + phi_a) / 2
    return [sympy.expand(x) for x in u], [sympy.expand(x) for x in y]


def random_model(order: int, size: int, seed: int) -> BCPHS:
    """A random valid model of order N and size n (needs n even when N is even)."""
    rnd = random.Random(seed)
    P = random_P(order, size, rnd)
    A = unimodular(order * size, rnd)
    inputs, outputs = ports_for(P, order, size, A)
    H = sympy.diag(*[rnd.randint(1, 3) for _ in range(size)])
    return BCPHS.define(
        name=f"random-N{order}-n{size}-{seed}",
        interval=(0, 1),
        order=order,
        P=P,
        H=H,
        inputs=inputs,
        outputs=outputs,
    )


def coupled_beams(copies: int = 3, seed: int = 0) -> BCPHS:
    """N = 2, n = 2*copies: Euler-Bernoulli-like beams coupled through Q1 and Q2.

    The state is scrambled by a random permutation, so Assumption 3.1 holds only after
    the permutation search finds the blocks.
    """
    rnd = random.Random(seed)
    h = copies
    while True:
        Q2 = sympy.Matrix(h, h, lambda i, j: 0)
        for i in range(h):
            for j in range(i, h):
                Q2[i, j] = Q2[j, i] = rnd.randint(-1, 2) if i != j else rnd.randint(1, 3)
        if Q2.det() != 0:
            break
    Q1 = sympy.Matrix(h, h, lambda i, j: 0)
    for i in range(h):
        for j in range(i, h):
            Q1[i, j] = Q1[j, i] = rnd.randint(-1, 1)
    zero = sympy.zeros(h)
    P1 = sympy.Matrix(sympy.BlockMatrix([[zero, Q1], [Q1, zero]]))
    P2 = sympy.Matrix(sympy.BlockMatrix([[zero, -Q2], [Q2, zero]]))
    P0 = sympy.zeros(2 * h)
    P0[0, 0] = -1
    perm = list(range(2 * h))
    rnd.shuffle(perm)

    def scramble(M: sympy.Matrix) -> sympy.Matrix:
        return sympy.Matrix(2 * h, 2 * h, lambda i, j: M[perm[i], perm[j]])

    P = [scramble(P0), scramble(P1), scramble(P2)]
    n = 2 * h
    inputs, outputs = ports_for(P, 2, n, sympy.eye(2 * n))
    H = scramble(sympy.diag(*[1 + (i % 3) for i in range(n)]))
    return BCPHS.define(
        name=f"coupled-beams-{copies}",
        interval=(0, 1),
        order=2,
        P=P,
        H=H,
        inputs=inputs,
        outputs=outputs,
    )
