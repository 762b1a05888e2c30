"""Benchmark: converged error-system spectral abscissa of the paper's beam, and the FD trap.

Targets: the error-system abscissa of each Table I design converged to 1e-10 (agreement
between the two finest resolutions) in at most 2 s (wall, whole adaptive refinement).
Also prints, for the damped wave (k = 0.5, exact -0.5493061443), the largest real part
over ALL finite-difference eigenvalues (tends to 0 like h^2) against the drift-filtered
abscissa.

Run:  python benchmarks/spectrum.py   (exit 1 if a target fails)
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.spectrum import spectrum


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
    print("targets:", "met" if ok else "MISSED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
