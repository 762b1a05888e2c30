"""Characteristic determinants in mpmath, an independent reference for constant-H models.

An eigenfunction of ``λ H⁻¹ e = Σ_k P_k ∂^k e`` is ``w(z) = Φ(z - a) w(a)`` for the
companion vector ``w = (e, e', ..., e^(N-1))`` with ``w' = M(λ) w``, the last block row
of ``M`` being ``P_N⁻¹ (λ H⁻¹ e - Σ_{k<N} P_k e^(k))``.  The trace vector is
``v = (w(b); w(a)) = (Φ(b - a); I) w(a)`` (the ordering of phdesign's ports), and the
boundary condition of the loop ``u = -K y`` is ``(U + K Y) v = 0``, so the eigenvalues are
the roots of ``Δ(λ) = det((U + K Y)(Φ(b - a); I))``.  Nothing here uses phdesign's
discretizations; the matrices U, Y come from the symbolic port derivation.
"""

from __future__ import annotations

import mpmath
import numpy as np


def _matmul(X, Y):
    return [
        [mpmath.fsum(a * b for a, b in zip(row, col, strict=True)) for col in zip(*Y, strict=True)]
        for row in X
    ]


def _expm(A):
    """exp(A) for a small mpmath-entry matrix: scaling and squaring with Taylor (||A|| <= 1/2)."""
    norm = max(mpmath.fsum(abs(x) for x in row) for row in A)
    s = max(0, int(mpmath.ceil(mpmath.log(norm, 2))) + 1) if norm > 0 else 0
    B = [[x / 2**s for x in row] for row in A]
    size = len(A)
    result = [[mpmath.mpf(int(i == j)) for j in range(size)] for i in range(size)]
    term = [row[:] for row in result]
    for k in range(1, 40):
        term = [[x / k for x in row] for row in _matmul(term, B)]
        result = [
            [r + t for r, t in zip(rr, tt, strict=True)]
            for rr, tt in zip(result, term, strict=True)
        ]
        if max(abs(x) for row in term for x in row) < mpmath.eps:
            break
    for _ in range(s):
        result = _matmul(result, result)
    return result


def characteristic_determinant(nm, K=None, dps=18):
    """Return Δ(λ) (an mpmath function) for the constant-H model ``nm``."""
    N, n = nm.order, nm.size
    length = nm.interval[1] - nm.interval[0]
    Hinv = np.linalg.inv(nm.H_at(np.array([nm.interval[0]]))[0])
    UK = nm.U if K is None else nm.U + np.asarray(K) @ nm.Y
    with mpmath.workdps(dps):
        PNinv = mpmath.inverse(mpmath.matrix(nm.P[N].tolist()))
        Hi = PNinv * mpmath.matrix(Hinv.tolist())
        fixed = [-PNinv * mpmath.matrix(nm.P[k].tolist()) for k in range(N)]
        UKm = mpmath.matrix(UK.tolist())

    def delta(lam):
        with mpmath.workdps(dps):
            M = [[mpmath.mpf(0)] * (N * n) for _ in range(N * n)]
            for k in range(N - 1):
                for i in range(n):
                    M[k * n + i][(k + 1) * n + i] = mpmath.mpf(length)
            for k in range(N):
                block = fixed[k] + lam * Hi if k == 0 else fixed[k]
                for i in range(n):
                    for j in range(n):
                        M[(N - 1) * n + i][k * n + j] = block[i, j] * length
            Phi = _expm(M)
            S = mpmath.zeros(2 * N * n, N * n)
            for i in range(N * n):
                for j in range(N * n):
                    S[i, j] = Phi[i][j]
                S[N * n + i, i] = 1
            try:
                return mpmath.det(UKm * S)
            except (ZeroDivisionError, TypeError):  # mpmath's LU on an exactly singular matrix
                return mpmath.mpf(0)

    return delta


def root_ratio(delta, lam, radius):
    """|Δ(λ)| / |Δ(λ + radius e^{iπ/3})|: ≪ 1 iff a root of Δ is near λ.

    For a root within ε of λ (multiplicity m) the ratio is about (ε/radius)^m; away from
    every root Δ is smooth and nonzero and the ratio is 1 + O(radius).
    """
    center = mpmath.mpc(lam.real, lam.imag)
    ring = abs(delta(center + radius * mpmath.expjpi(mpmath.mpf(1) / 3)))
    return float(abs(delta(center)) / ring) if ring else float("inf")


def zero_multiplicity(delta, radius=1e-3):
    """Order m of the zero of Δ at λ = 0, from |Δ(2r)| / |Δ(r)| = 2^m (m = 0: no root)."""
    small, double = abs(delta(mpmath.mpf(radius))), abs(delta(mpmath.mpf(2 * radius)))
    return round(float(mpmath.log(double / small, 2)))


def beam_determinant(lam, torque: float = 0.0, shear: float = 0.0, damping: float = 0.0):
    r"""Tip conditions of w_tt = -d w_t - w_zzzz (ρ = EI = 1), clamped at z = 0.

    w = φ(z) e^{λt}, μ⁴ = -(λ² + dλ) (μ = sqrt(iλ) when d = 0),
    φ = A (cosh - cos)(μz) + B (sinh - sin)(μz) meets φ(0) = φ'(0) = 0.  At z = 1:
    u3 = e2(1) = φ''(1) is fed -torque·y3 = -torque·λφ'(1), u4 = e2'(1) = φ'''(1) is fed
    -shear·y4 = shear·λφ(1) (y4 = -e1(1)); the system's e1 = w_t = λφ.

    For d > 0, μ = (-(λ² + dλ))^(1/4) (principal roots): any fourth root spans the same
    solutions, the determinant changes by a non-vanishing factor only.
    """
    mu = mpmath.sqrt(mpmath.sqrt(-(lam**2 + damping * lam))) if damping else mpmath.sqrt(1j * lam)
    ch, sh, c, s = mpmath.cosh(mu), mpmath.sinh(mu), mpmath.cos(mu), mpmath.sin(mu)
    phi = (ch - c, sh - s)
    d1 = (mu * (sh + s), mu * (ch - c))
    d2 = (mu**2 * (ch + c), mu**2 * (sh + s))
    d3 = (mu**3 * (sh - s), mu**3 * (ch + c))
    row1 = [d2[j] + torque * lam * d1[j] for j in range(2)]
    row2 = [d3[j] - shear * lam * phi[j] for j in range(2)]
    # divided by μ⁵ cos²μ: for d = 0 and Im λ > 0, μ lies near the imaginary axis where
    # cos μ grows like cosh|μ| and has no zero, so no root moves and the values stay of
    # order one; every root found is checked: |f| < 1e-20 at 30 digits
    return (row1[0] * row2[1] - row1[1] * row2[0]) / (mu**5 * mpmath.cos(mu) ** 2)
