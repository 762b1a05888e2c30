"""Benchmark: converged error-system spectral abscissa of the paper's beam, and the FD trap.

Targets: the error-system abscissa of each Table I design converged to 1e-10 (agreement
between the two finest resolutions) in at most 2 s (wall, whole adaptive refinement).
Also prints, for the damped wave (k = 0.5, exact -0.5493061443), the largest real part
over ALL finite-difference eigenvalues (tends to 0 like h^2) against the drift-filtered
abscissa, and the throughput of the AbscissaEvaluator (a resolution pair prepared once:
shift and invert, eigenvalues only) against the per-gain QZ with left and right
eigenvectors that tuning used before, on a 12 x 12 grid of beam gains, same process.

Run:  python benchmarks/spectrum.py   (exit 1 if a target fails)
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np
import scipy.linalg as sl

from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import discretize, feedback_matrix
from phdesign.numeric.spectrum.abscissa import estimate_abscissa
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.numeric.spectrum.drift import pair_spectrum
from phdesign.numeric.spectrum.evaluator import AbscissaEvaluator
from phdesign.numeric.threads import small_dense_threads


def evaluator_throughput(beam, C_m) -> None:
    """Gains per second: the evaluator against QZ with eigenvectors at every gain."""
    gains = [np.diag([a, b]) for a in np.logspace(-2, 0, 12) for b in np.logspace(-1, 1, 12)]
    systems = [discretize(beam, "galerkin", p) for p in (20, 30)]

    def baseline(L):
        K = feedback_matrix(C_m, L, 4)
        coarse = sl.eigvals(systems[0].closed_matrix(K), systems[0].E)
        A = systems[1].closed_matrix(K)
        fine = sl.eig(A, systems[1].E, left=True, right=True)[0]
        # the drift test and the abscissa rule at Galerkin's tolerances, as tuning did
        pair = pair_spectrum(
            fine, coarse, resolutions=(20, 30), rtol=1e-6, scale=1.0, dissipative=True
        )
        return estimate_abscissa(pair, 1e-10).value

    with small_dense_threads():
        w0 = time.perf_counter()
        old = [baseline(L) for L in gains]
        base = time.perf_counter() - w0
        ev = AbscissaEvaluator(beam, C_m, (20, 30))
        w0 = time.perf_counter()
        new = [ev(L) for L in gains]
        fast = time.perf_counter() - w0
    agree = max(abs(a - b) for a, b in zip(old, new, strict=True) if a is not None)
    print(
        f"AbscissaEvaluator: {len(gains) / fast:.0f} gains/s against {len(gains) / base:.0f} "
        f"gains/s for QZ with eigenvectors ({base / fast:.1f}x); largest difference of the "
        f"two abscissas {agree:.1e} (QZ against shift and invert)"
    )


def main() -> int:
    beam = to_numeric(load_builtin("euler-bernoulli"))
    C_m = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    ok = True
    for l1, l2 in ((0.03, 0.3), (0.1, 1.0), (0.2, 2.0)):
        w0, c0 = time.perf_counter(), time.process_time()
        rep = spectrum(beam, C_m, np.diag([l1, l2]), tol=1e-10)
        wall, cpu = time.perf_counter() - w0, time.process_time() - c0
        good = rep.converged and wall <= 2.0
        ok &= good
        print(
            f"beam L = diag({l1}, {l2}): abscissa {rep.spectral_abscissa:.12f}  digits "
            f"{rep.digits:.1f}  converged {rep.converged}  resolutions {rep.resolutions}  "
            f"{wall:.3f} s wall ({cpu:.3f} s cpu)  {'met' if good else 'MISSED'}"
        )
    wave = to_numeric(load_builtin("wave"))
    exact = 0.5 * math.log(1 / 3)
    print(f"damped wave k = 0.5, exact abscissa {exact:.10f}")
    for m in (35, 70, 140, 280):
        rep = spectrum(
            wave,
            np.array([[0.0, 1.0]]),
            np.array([[0.5]]),
            method="fd",
            resolution=m,
            max_resolution=int(1.5 * m) + 1,
        )
        print(
            f"  FD {m:4d} nodes/group: all-eigenvalue max Re {rep.all_eigenvalues_max_real:+.3e}"
            f"   filtered abscissa {rep.spectral_abscissa:.8f} "
            f"(error {abs(rep.spectral_abscissa - exact):.1e}, {rep.n_resolved} resolved)"
        )
    rep = spectrum(wave, np.array([[0.0, 1.0]]), np.array([[0.5]]))
    print(
        f"  Galerkin: abscissa {rep.spectral_abscissa:.14f} (error "
        f"{abs(rep.spectral_abscissa - exact):.1e}), all-eigenvalue max Re "
        f"{rep.all_eigenvalues_max_real:+.2e}"
    )
    evaluator_throughput(beam, C_m)
    print("targets:", "met" if ok else "MISSED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
