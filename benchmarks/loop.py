"""Benchmark: the converged spectrum of the assembled observer-based loop on the beam.

Target (issue 16): the loop's converged spectrum for the paper's beam, tip torque
u3 = -K ŷ3 with only the tip velocity y4 measured (K = L = 1), at most 1 s, including the
converged spectra of its two blocks that the report carries.  Baseline, in the same
process: one converged ``spectrum`` of the observer error system alone (the loop does that
one, the controlled plant's, and the assembled pencil's refinement).

Run:  python benchmarks/loop.py        (exit status 1 if the target is missed)
The machine is shared: under load wall times are pessimistic; CPU times are printed too.
"""

from __future__ import annotations

import statistics
import sys

import numpy as np
from _timing import timed

from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.control.assembly import NumericLoop
from phdesign.numeric.control.spectrum import loop_spectrum
from phdesign.numeric.spectrum.converged import spectrum

TARGET = 1.0  # seconds, wall, median


def main() -> int:
    ok = True
    for d in (0.0, 0.2):
        nm = to_numeric(load_builtin("euler-bernoulli"), {"d": d})
        loop = NumericLoop((2,), np.array([[1.0]]), np.array([[0, 0, 0, 1.0]]), np.array([[1.0]]))
        _, base_w, _ = timed(lambda nm=nm, loop=loop: spectrum(nm, loop.C_m, loop.L))
        rep, walls, cpus = timed(lambda nm=nm, loop=loop: loop_spectrum(nm, loop))
        wall, base = statistics.median(walls), statistics.median(base_w)
        good = rep.converged and wall <= TARGET
        ok &= good
        print(
            f"beam d = {d}: loop abscissa {rep.spectral_abscissa:.12f} (plant "
            f"{rep.plant_abscissa:.12f}, error {rep.error_abscissa:.12f}), digits "
            f"{rep.digits:.1f}, resolutions {rep.resolutions}; median {wall:.3f} s wall "
            f"({statistics.median(cpus):.3f} s cpu), {wall / base:.1f}x the error spectrum "
            f"alone ({base:.3f} s); target <= {TARGET:g} s: {'met' if good else 'MISSED'}"
        )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
