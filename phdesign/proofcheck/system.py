r"""Re-deriving :math:`\Delta` and the energy identity's signs from the exact system.

From the proof's ``system`` (the model's :math:`P_k`, :math:`H`, interval, ports
:math:`U, Y` and closing gain :math:`G`) the checker derives, in exact rationals and
without reading the certifier's ``characteristic`` section:

* the closed boundary rows :math:`B = U + GY`, each divided by its first nonzero entry;
* the companion matrix of :math:`\lambda H^{-1} e = \sum_k P_k e^{(k)}`:
  :math:`A_{k,k+1} = I`, :math:`A_{N-1,k} = -P_N^{-1}P_k`, plus
  :math:`\lambda P_N^{-1}H^{-1}` in the block :math:`(N-1, 0)`;
* the Cauchy-Binet weights of :math:`\Delta = \det(B_a + B_b E) = \sum_S
  \det B_{:,S} \det \binom{I}{E}_{S,:}`, where the rows S of :math:`\binom{I}{E}` are
  unit rows (those of :math:`S_a`) and rows of E: that determinant is the parity of the
  column order times a minor of E;
* :math:`\operatorname{sym}(G) \succeq 0` and :math:`\operatorname{sym}(P_0) \preceq 0`
  (so :math:`\operatorname{Re}\lambda \le 0` for every eigenvalue).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from itertools import combinations

from phdesign.proofcheck.exact import (
    Matrix,
    determinant,
    inverse,
    matmul,
    number,
    read_matrix,
    semidefinite,
)
from phdesign.proofcheck.intervals import parity

__all__ = ["Delta", "derive"]


@dataclass(frozen=True)
class Delta:
    """What :func:`.intervals.delta` needs: exact data of Δ and its expansion."""

    order: int
    size: int
    length: Fraction
    A0: Matrix
    A1: Matrix
    boundary: Matrix
    terms: tuple  # (k, subsets, {(row, col): weight})
    weight_blocks: dict
    dissipative: bool
    conservative: bool
    real_speed: list | None = None

    @property
    def dimension(self) -> int:
        """Nn."""
        return self.order * self.size

    @property
    def blocks(self) -> list[int]:
        """The block (derivative order) of each trace."""
        return [i // self.size for i in range(self.dimension)]


def derive(system: dict, failures: list[str]) -> Delta | None:
    """Derive :class:`Delta` from the proof's ``system``; record what fails."""
    N, n = int(system["order"]), int(system["size"])
    nn = N * n
    a, b = (number(x) for x in system["interval"])
    P = [read_matrix(M) for M in system["P"]]
    H, U, Y, G = (read_matrix(system[key]) for key in ("H", "U", "Y", "G"))
    GY = matmul(G, Y)
    B = [[u + g for u, g in zip(ru, rg, strict=True)] for ru, rg in zip(U, GY, strict=True)]
    if read_matrix(system["boundary"]) != B:
        failures.append("system: the boundary rows are not U + G Y")
    PN_inv, H_inv = inverse(P[N]), inverse(H)
    if PN_inv is None or H_inv is None:
        failures.append("system: P_N or H is singular")
        return None
    A0 = [[Fraction(0)] * nn for _ in range(nn)]
    A1 = [[Fraction(0)] * nn for _ in range(nn)]
    for k in range(N - 1):
        for i in range(n):
            A0[k * n + i][(k + 1) * n + i] = Fraction(1)
    for k in range(N):
        block = matmul(PN_inv, P[k])
        for i in range(n):
            for j in range(n):
                A0[(N - 1) * n + i][k * n + j] = -block[i][j]
    top = matmul(PN_inv, H_inv)
    for i in range(n):
        for j in range(n):
            A1[(N - 1) * n + i][j] = top[i][j]
    rows = []
    for row in B:
        lead = next((x for x in row if x), None)
        if lead is None:
            failures.append("system: a boundary row is zero")
            return None
        rows.append([x / lead for x in row])
    sym_G = [[(G[i][j] + G[j][i]) / 2 for j in range(nn)] for i in range(nn)]
    sym_P0 = [[-(P[0][i][j] + P[0][j][i]) / 2 for j in range(n)] for i in range(n)]
    dissipative = semidefinite(sym_G) and semidefinite(sym_P0)
    conservative = not any(any(r) for r in sym_G) and not any(any(r) for r in sym_P0)
    # v = (φ(b); φ(a)): Δ = det(B_a + B_b E) = det((B_a B_b) (I; E))
    terms, weight_blocks = _expansion([row[nn:] + row[:nn] for row in rows], nn, n)
    return Delta(N, n, b - a, A0, A1, rows, terms, weight_blocks, dissipative, conservative)


def _expansion(B: Matrix, nn: int, n: int) -> tuple[tuple, dict]:
    """Return the Cauchy-Binet terms: for each k, the weights of the k x k minors of E."""
    by_k: dict[int, dict[tuple[tuple[int, ...], tuple[int, ...]], Fraction]] = {}
    for S in combinations(range(2 * nn), nn):
        coefficient = determinant([[row[c] for c in S] for row in B])
        if not coefficient:
            continue
        unit = [c for c in S if c < nn]  # unit rows e_c of the identity part
        e_rows = tuple(c - nn for c in S if c >= nn)
        e_cols = tuple(c for c in range(nn) if c not in unit)
        # det of [e_unit; E[e_rows, :]]: put the unit columns first, then the others
        sign = parity(tuple(unit) + e_cols)
        k = len(e_rows)
        by_k.setdefault(k, {})
        key = (e_rows, e_cols)
        by_k[k][key] = by_k[k].get(key, Fraction(0)) + sign * coefficient
    terms = []
    weight_blocks = {}
    for k in sorted(by_k):
        subsets = list(combinations(range(nn), k))
        where = {s: i for i, s in enumerate(subsets)}
        weights = {(where[r], where[c]): w for (r, c), w in by_k[k].items() if w}
        if weights:
            terms.append((k, subsets, weights))
            weight_blocks[k] = [sum(i // n for i in s) for s in subsets]
    return tuple(terms), weight_blocks
