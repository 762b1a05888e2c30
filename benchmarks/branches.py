"""Benchmark: the cost of the spectrum's high-frequency structure (issue 22).

Targets:
* the built-in models' spectra (plant and a standard error system each) no slower than
  without the structure: median ratio <= 1.10, the baseline being the same spectrum with
  the structure switched off (``Discretizations.branches`` returning None, the previous
  refinement), interleaved in this process on one BLAS thread.  The structure of a
  (model, gain) is kept while the model lives, so a repeated call pays nothing; the first
  call's cost (the structure derived anew, ``cold``) is printed beside it, not a target;
* the steel Timoshenko beam of the issue (whose thickness-shear branch needs the pair
  (153, 230)) converged in <= 5 s.

It also tunes the tip angular-velocity gain of the 2 m beam (shear damper in the plant,
the moment free and measured) and prints where the tuned abscissa lies: near the
thickness-shear cut-off, not among the bending modes (minutes: not a test; the suite
tunes a 0.5 m bar of the same section).

Run:  python benchmarks/branches.py   (exit 1 if a target fails)
"""

from __future__ import annotations

import os
import statistics
import sys
import time

import numpy as np

from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.spectrum.converged import spectrum
from phdesign.numeric.spectrum.refinement import _STRUCTURES, Discretizations
from phdesign.numeric.threads import small_dense_threads
from phdesign.symbolic.model import BCPHS

CASES = [
    ("wave", [2], [0.5]),
    ("wave-damper", None, None),
    ("timoshenko", [3, 4], [1.0, 1.0]),
    ("euler-bernoulli", None, None),
    ("euler-bernoulli", [3, 4], [0.1, 1.0]),
    ("airy", [1], [1.0]),
    ("beam-tip-damper", None, None),
]


def steel_beam(closed: tuple[int, ...] = (3, 4)) -> BCPHS:
    area, inertia = 0.02 * 0.05, 0.02 * 0.05**3 / 12
    gains = {3: "k1", 4: "k2"}
    return BCPHS.define(
        name="steel timoshenko",
        interval=[0, 2],
        order=1,
        P={
            0: [[0, 0, 0, -1], [0, 0, 0, 0], [0, 0, 0, 0], [1, 0, 0, 0]],
            1: [[0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 1], [0, 0, 1, 0]],
        },
        H=[["K", 0, 0, 0], [0, "1/rho", 0, 0], [0, 0, "EI", 0], [0, 0, 0, "1/I_rho"]],
        parameters={
            "K": 5 / 6 * 210e9 / 2.6 * area,
            "rho": 7850 * area,
            "EI": 210e9 * inertia,
            "I_rho": 7850 * inertia,
            "k1": 300.0,
            "k2": 3.0,
        },
        inputs=["e2(0)", "e4(0)", "e1(2)", "e3(2)"],
        outputs=["-e1(0)", "-e3(0)", "e2(2)", "e4(2)"],
        feedback={
            "inputs": list(closed),
            "gain": [[gains[i] if i == j else 0 for j in closed] for i in closed],
        },
    )


def call(name: str, sensors: list[int] | None, gain: list[float] | None):  # type: ignore[no-untyped-def]
    nm = to_numeric(load_builtin(name))
    if sensors is None:
        return lambda: spectrum(nm)
    C = np.zeros((len(sensors), nm.n_ports))
    C[np.arange(len(sensors)), np.array(sensors) - 1] = 1.0
    return lambda: spectrum(nm, C, np.diag(gain))


def interleaved(fn, rounds: int = 9) -> tuple[list[float], list[float], list[float]]:  # type: ignore[no-untyped-def]
    """Walls with the structure (kept, and derived anew) and without it, interleaved."""
    original = Discretizations.branches
    with_it, cold, without = [], [], []
    for _ in range(rounds):
        for mode, out in (("kept", with_it), ("cold", cold), ("off", without)):
            if mode == "off":
                Discretizations.branches = lambda self, K: None  # type: ignore[method-assign,assignment,return-value]
            if mode == "cold":
                _STRUCTURES.clear()
            start = time.perf_counter()
            fn()
            out.append(time.perf_counter() - start)
            Discretizations.branches = original  # type: ignore[method-assign]
    return with_it, cold, without


def main() -> int:
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    ok = True
    ratios = []
    with small_dense_threads():
        for name, sensors, gain in CASES:
            fn = call(name, sensors, gain)
            fn()  # warm caches (sympy, discretization code paths)
            new, cold, old = interleaved(fn)
            ratio = statistics.median(new) / statistics.median(old)
            ratios.append(ratio)
            print(
                f"{name:16s} {sensors!s:10s}: {statistics.median(new) * 1e3:7.1f} ms with the "
                f"structure, {statistics.median(old) * 1e3:7.1f} ms without ({ratio:.2f}x); "
                f"first call {statistics.median(cold) * 1e3:7.1f} ms "
                f"({statistics.median(cold) / statistics.median(old):.2f}x)"
            )
        overall = statistics.median(ratios)
        ok &= overall <= 1.10
        print(f"median ratio over the built-ins {overall:.2f}x: {'met' if ok else 'MISSED'}")
        nm = to_numeric(steel_beam())
        walls = []
        for _ in range(3):
            start = time.perf_counter()
            rep = spectrum(nm)
            walls.append(time.perf_counter() - start)
    wall = statistics.median(walls)
    good = wall <= 5.0 and rep.converged
    ok &= good
    print(
        f"steel Timoshenko: abscissa {rep.spectral_abscissa:.10f} converged {rep.converged} at "
        f"{rep.resolutions}, median {wall:.2f} s of 3 (target <= 5 s: "
        f"{'met' if good else 'MISSED'})"
    )
    tuned_beam()
    print("targets:", "met" if ok else "MISSED")
    return 0 if ok else 1


def tuned_beam() -> None:
    """Tune the 2 m beam's tip angular-velocity gain; say where the tuned abscissa lies."""
    from phdesign.numeric.tuning.search import tune

    nm = to_numeric(steel_beam(closed=(3,)))
    cutoff = (5 / 6 * 210e9 / 2.6 * 1e-3 / (7850 * 0.02 * 0.05**3 / 12)) ** 0.5
    start = time.perf_counter()
    result = tune(nm, np.array([[0.0, 0.0, 1.0]]))
    wall = time.perf_counter() - start
    lead = result.report.rightmost[0]
    print(
        f"tuned 2 m beam: L = {float(np.asarray(result.gain)[0, 0]):.6g}, abscissa "
        f"{result.report.spectral_abscissa:.10f} ({result.status}, {result.report.kind}), "
        f"rightmost {lead:.6g} at |Im| = {abs(lead.imag) / cutoff:.3f} x the cut-off, "
        f"{wall:.0f} s"
    )


if __name__ == "__main__":
    sys.exit(main())
