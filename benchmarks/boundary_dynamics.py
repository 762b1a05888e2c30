"""Benchmark: the spectrum of a cantilever with a tip body against the bare cantilever's.

Target (issue 26): the plant spectrum of ``beam-tip-body`` (the paper's beam, clamped at 0,
with a tip body of mass M, rotary inertia J and a damper on it: two boundary states appended
to the Galerkin system) costs at most 1.5 times that of the bare cantilever
``euler-bernoulli`` on the same refinement plan (the resolution pair (30, 45)), median
over interleaved rounds in this process, on one BLAS thread, each round with freshly
substituted models (nothing cached between rounds).

Also printed, not a target: each model's default adaptive spectrum.  The tip body's real
parts rise to 0 (no uniform decay), so its refinement goes on to the pair (45, 68) where the
bare cantilever (every mode at Re = -d/2) stops at (20, 30): that is the cost of the honest
answer, not of the appended states.

Run:  python benchmarks/boundary_dynamics.py   (exit 1 if the target fails)
"""

from __future__ import annotations

import statistics
import sys
import time
from typing import Any

from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.numeric.threads import small_dense_threads

TARGET = 1.5
ROUNDS = 7
MODELS = ("euler-bernoulli", "beam-tip-body")
SAME_PLAN = {"resolution": 30, "max_resolution": 45}


def seconds(name: str, plan: dict[str, Any]) -> tuple[float, Any]:
    nm = to_numeric(load_builtin(name))  # a new numeric model: its discretizations are new
    start = time.perf_counter()
    report = spectrum(nm, **plan)
    return time.perf_counter() - start, report


def medians(plan: dict[str, Any]) -> dict[str, tuple[float, Any]]:
    times: dict[str, list[float]] = {name: [] for name in MODELS}
    reports = {}
    for name in MODELS:  # warm-up: imports and the shared Legendre tables
        seconds(name, plan)
    for _ in range(ROUNDS):
        for name in MODELS:
            elapsed, reports[name] = seconds(name, plan)
            times[name].append(elapsed)
    return {name: (statistics.median(times[name]), reports[name]) for name in MODELS}


def main() -> int:
    with small_dense_threads():
        same = medians(SAME_PLAN)
        adaptive = medians({})
    (bare, _), (body, _) = (same[n] for n in MODELS)
    ratio = body / bare
    print(
        f"plant spectrum at the pair (30, 45): beam-tip-body {body * 1e3:.1f} ms, "
        f"euler-bernoulli {bare * 1e3:.1f} ms (median of {ROUNDS}); ratio {ratio:.2f} "
        f"(target <= {TARGET})"
    )
    for name, (elapsed, report) in adaptive.items():
        print(
            f"  adaptive {name}: {elapsed * 1e3:.1f} ms, last pair {report.resolutions}, "
            f"abscissa {report.spectral_abscissa:.3g} ({report.kind})"
        )
    return 0 if ratio <= TARGET else 1


if __name__ == "__main__":
    sys.exit(main())
