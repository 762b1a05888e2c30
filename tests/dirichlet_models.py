"""Every choice of Dirichlet-type boundary inputs for N = 1, 2, 3 (models for the tests).

At each end the power ``u^T y`` splits into pairs of conjugate traces; a port choice
picks, for every pair, which trace is the input (the other, with the sign of the
pairing, is the output).  Choices where a component has all its traces among the
inputs at both ends create the spurious unobservable modes of the weak Galerkin.
"""

from __future__ import annotations

import itertools

from phdesign.symbolic.model import BCPHS

STRING_P1 = [[0, 1], [1, 0]]
TIMOSHENKO_P0 = [[0, 0, 0, -1], [0, 0, 0, 0], [0, 0, 0, 0], [1, 0, 0, 0]]
TIMOSHENKO_P1 = [[0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 1], [0, 0, 1, 0]]


def _pairs_model(name, order, P, H, pairs, choice):
    """``pairs[end]``: list of (trace_a, trace_b, sign) with power sign * a * b at that end."""
    inputs, outputs = [], []
    for end in (0, 1):
        for (a, b, sign), c in zip(pairs[end], choice[end], strict=True):
            x, y = (a, b) if c == 0 else (b, a)
            inputs.append(x)
            outputs.append(f"{sign}{y}")
    return BCPHS.define(
        name=name, interval=[0, 1], order=order, P=P, H=H, inputs=inputs, outputs=outputs
    )


def _first_order_pairs(components):
    # power e_i e_j at z = 1 and -e_i e_j at z = 0 for P1 swapping i and j
    return (
        [(f"e{i}(0)", f"e{j}(0)", "-") for i, j in components],
        [(f"e{i}(1)", f"e{j}(1)", "") for i, j in components],
    )


def string(choice, H=((1, 0), (0, 1))):
    """String (P1 swaps e1, e2); ``choice`` = (end 0, end 1), 0: input e1, 1: input e2."""
    return _pairs_model(
        f"string {choice}",
        1,
        {1: STRING_P1},
        [list(r) for r in H],
        _first_order_pairs([(1, 2)]),
        ((choice[0],), (choice[1],)),
    )


def timoshenko(choice, H=None):
    """Timoshenko beam; ``choice`` = 4 bits (end 0: pairs (1,2), (3,4); end 1 likewise)."""
    H = H or [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
    return _pairs_model(
        f"timoshenko {choice}",
        1,
        {0: TIMOSHENKO_P0, 1: TIMOSHENKO_P1},
        H,
        _first_order_pairs([(1, 2), (3, 4)]),
        (choice[:2], choice[2:]),
    )


def beam(choice, d="0"):
    """Euler-Bernoulli beam (P2 = [[0, -1], [1, 0]], P0 = -d on e1), 4 bits of choice.

    Power at z = 1: e2 e1' - e1 e2'; at z = 0: e1 e2' - e1' e2.
    """
    pairs = (
        [("e1(0)", "e2'(0)", ""), ("e1'(0)", "e2(0)", "-")],
        [("e2(1)", "e1'(1)", ""), ("e2'(1)", "e1(1)", "-")],
    )
    return _pairs_model(
        f"beam {choice} d={d}",
        2,
        {0: [[f"-{d}", 0], [0, 0]], 2: [[0, -1], [1, 0]]},
        [[1, 0], [0, 1]],
        pairs,
        (choice[:2], choice[2:]),
    )


def airy(choice):
    """Airy e_t = e_zzz: power e e'' - e'^2/2 at 1, -(e e'' - e'^2/2) at 0; 3 bits."""
    inputs, outputs = [], []
    for (a, b, sign), c in zip(
        [("e1(0)", "e1''(0)", "-"), ("e1(1)", "e1''(1)", "")], choice[:2], strict=True
    ):
        x, y = (a, b) if c == 0 else (b, a)
        inputs.append(x)
        outputs.append(f"{sign}{y}")
    plus, minus = "(e1'(0) + e1'(1))/sqrt(2)", "(e1'(0) - e1'(1))/sqrt(2)"
    x, y = (plus, minus) if choice[2] == 0 else (minus, plus)
    inputs.append(x)
    outputs.append(y)
    return BCPHS.define(
        name=f"airy {choice}",
        interval=[0, 1],
        order=3,
        P={3: [[1]]},
        H=[[1]],
        inputs=inputs,
        outputs=outputs,
    )


def transport():
    """Two-way transport (P1 = diag(1, -1), speeds 1 and 1/2) with e1 - e2 imposed at both ends.

    In f = (e1 - e2)/√2, g = (e1 + e2)/√2 it is a string with f Dirichlet at both ends,
    so the spurious mode is the top mode of f: not a coordinate vector.
    """
    f0, g0 = "(e1(0) - e2(0))/sqrt(2)", "(e1(0) + e2(0))/sqrt(2)"
    f1, g1 = "(e1(1) - e2(1))/sqrt(2)", "(e1(1) + e2(1))/sqrt(2)"
    return BCPHS.define(
        name="two-way transport",
        interval=[0, 1],
        order=1,
        P={1: [[1, 0], [0, -1]]},
        H=[[1, 0], [0, 2]],
        inputs=[f0, f1],
        outputs=[f"-{g0}", g1],
    )


def _first_order_kernel(choice, pairs):
    # a component is Dirichlet at both ends when its pair makes the same choice at both
    return any(choice[k] == choice[k + pairs] for k in range(pairs))


def _beam_kernel(choice):
    # traces of e1 among the inputs: e1(0), e1'(0) for choice 0 at end 0; e1'(1), e1(1)
    # for choice 1 at end 1; a spurious mode needs three of one component's four
    e1 = (1 - choice[0]) + (1 - choice[1]) + choice[2] + choice[3]
    return e1 >= 3 or e1 <= 1


def every_combination():
    """(label, model) for every Dirichlet-type port choice that creates spurious modes.

    N = 1: a component with its trace among the inputs at both ends (string 2 of 4,
    Timoshenko 12 of 16); N = 2: three or four of a component's four traces (10 of 16, two
    of them again with damping d = 1/5); N = 3: all eight airy choices (each has a
    spurious mode at one parity of the degree); the two-way transport line.
    """
    bits = itertools.product
    out = [(f"string-{c}", string(c)) for c in bits((0, 1), repeat=2) if c[0] == c[1]]
    out += [
        (f"timoshenko-{c}", timoshenko(c))
        for c in bits((0, 1), repeat=4)
        if _first_order_kernel(c, 2)
    ]
    out += [(f"beam-{c}", beam(c)) for c in bits((0, 1), repeat=4) if _beam_kernel(c)]
    out += [(f"damped-beam-{c}", beam(c, "1/5")) for c in ((0, 0, 1, 1), (0, 0, 0, 1))]
    out += [(f"airy-{c}", airy(c)) for c in bits((0, 1), repeat=3)]
    out.append(("transport", transport()))
    return out
