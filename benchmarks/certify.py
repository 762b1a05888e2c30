"""Benchmark: the certified spectrum of the paper's beam and its independent re-check (issue 25).

Targets (this machine, one BLAS thread):
* ``Observer.certify(band=1000)`` for the paper's beam (sensors y3, y4, design 2,
  L = diag(0.1, 1)) in <= 30 s, the converged spectrum it starts from included;
* ``phdesign check`` of that proof file (mpmath's interval arithmetic, no flint) in
  <= 60 s, twice the certificate's budget.

The baseline is the converged spectrum of the same design, run in this process first:
the ratios say what the proof costs over the estimate it proves.

Run:  python benchmarks/certify.py   (exit 1 if a target fails)
"""

from __future__ import annotations

import sys
import time

import phdesign as phd
from phdesign.models import load_builtin
from phdesign.proofcheck import check_proof

CERTIFY_TARGET = 30.0
CHECK_TARGET = 60.0
BAND = 1000.0


def main() -> int:
    """Run the benchmark; return 0 when both targets hold."""
    beam = phd.Observer(load_builtin("euler-bernoulli"), sensors=[3, 4], gain=[0.1, 1])
    start = time.perf_counter()
    beam.spectrum()
    baseline = time.perf_counter() - start
    beam = phd.Observer(load_builtin("euler-bernoulli"), sensors=[3, 4], gain=[0.1, 1])
    start = time.perf_counter()
    cert = beam.certify(band=BAND)
    certify_time = time.perf_counter() - start
    band = cert.proof["band"]
    start = time.perf_counter()
    failures = check_proof(cert.to_dict())
    check_time = time.perf_counter() - start
    lo, hi = cert.abscissa_interval or (float("nan"),) * 2
    print(f"beam, design 2, band |Im λ| <= {BAND:g}: abscissa in [{lo:.12g}, {hi:.12g}]")
    print(f"  contour segments {len(band['path'])}, squares {len(band['enclosures'])}")
    print(f"  converged spectrum (baseline) {baseline:6.2f} s")
    print(
        f"  certify {certify_time:6.2f} s ({certify_time / baseline:.1f} x baseline; "
        f"target <= {CERTIFY_TARGET:g} s)"
    )
    print(
        f"  check   {check_time:6.2f} s ({check_time / certify_time:.1f} x certify; "
        f"target <= {CHECK_TARGET:g} s)"
    )
    ok = not failures and certify_time <= CERTIFY_TARGET and check_time <= CHECK_TARGET
    if failures:
        print("  the checker rejected the proof:", failures)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
