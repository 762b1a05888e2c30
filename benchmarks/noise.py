"""Benchmark: noise figures of the paper's beam, and a 40-point speed/noise trade-off.

Targets (wall time, in this process):
- one converged noise report (tip-deflection variance, L2-gain, the diverging error energy)
  for the beam with L = diag(0.1, 1) in at most 1 s;
- a 40-point trade-off along s * diag(0.1, 1), s log-spaced in [0.1, 10] (spectrum and noise
  report at every gain), in at most 20 s.

Baseline, same process: scipy.linalg.solve_continuous_lyapunov on the standard form
E^-1 A at the report's finest resolution (one plain solve, no convergence check, no
L2-gain); the figures it gives are compared with the report's.

Run:  python benchmarks/noise.py   (exit 1 if a target fails)
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np
import scipy.linalg as sl

from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.discretization.registry import discretize
from phdesign.numeric.noise.figures import noise
from phdesign.numeric.noise.statistics import noise_input
from phdesign.numeric.noise.tradeoff import tradeoff

SENSORS = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
GAIN = np.diag([0.1, 1.0])


def plain_scipy(nm, resolution: int) -> tuple[float, float, float]:
    """(seconds, tip variance, error energy) from one scipy Lyapunov solve on E^-1 A."""
    d = discretize(nm, "galerkin", resolution)
    tip = d.displacement_basis(np.array([1.0]))[0]
    start = time.perf_counter()
    A, G, _ = noise_input(d, SENSORS, GAIN, np.ones(2))
    F, H = np.linalg.solve(d.E, A), np.linalg.solve(d.E, G)
    P = sl.solve_continuous_lyapunov(F, -H @ H.T)
    seconds = time.perf_counter() - start
    return seconds, float(tip @ P @ tip), 0.5 * float(np.sum(d.E * P))


def main() -> int:
    nm = to_numeric(load_builtin("euler-bernoulli"))
    ok = True
    noise(nm, SENSORS, GAIN)  # warm-up (imports, caches)
    walls = []
    for _ in range(5):
        start = time.perf_counter()
        report = noise(nm, SENSORS, GAIN)
        walls.append(time.perf_counter() - start)
    wall = statistics.median(walls)
    (tip,) = report.performance
    good = tip.converged and report.l2_gain.converged and wall <= 1.0
    ok &= good
    print(report)
    print(
        f"noise report: median {wall:.3f} s over 5 runs (min {min(walls):.3f}), resolutions "
        f"{report.resolutions}; target <= 1 s: {'met' if good else 'MISSED'}"
    )
    finest = report.resolutions[-1]
    base = [plain_scipy(nm, finest) for _ in range(5)]
    base_wall = statistics.median(b[0] for b in base)
    _, var, energy = base[0]
    print(
        f"baseline: one scipy solve_continuous_lyapunov on E^-1 A at degree {finest}: "
        f"{base_wall:.4f} s; the report costs {wall / base_wall:.0f}x that (it solves "
        f"{len(report.resolutions)} resolutions, checks convergence and sweeps the L2-gain)"
    )
    print(
        f"  tip variance: report {tip.values[-1]:.12g}, scipy {var:.12g} "
        f"(relative difference {abs(var - tip.values[-1]) / var:.1e}); "
        f"error energy at degree {finest}: report {report.error_energy.values[-1]:.10g}, "
        f"scipy {energy:.10g}"
    )
    start = time.perf_counter()
    curve = tradeoff(nm, SENSORS, direction=[0.1, 1.0], scales=np.geomspace(0.1, 10.0, 40))
    wall = time.perf_counter() - start
    good = wall <= 20.0 and len(curve.points) == 40
    ok &= good
    best = max(curve.points, key=lambda p: p.decay_rate or 0.0)
    print(
        f"trade-off: 40 gains in {wall:.2f} s ({wall / 40:.3f} s a gain); "
        f"{len(curve.pareto_points)} Pareto-optimal; fastest {describe(best)}; "
        f"target <= 20 s: {'met' if good else 'MISSED'}"
    )
    print("targets:", "met" if ok else "MISSED")
    return 0 if ok else 1


def describe(point) -> str:
    return (
        f"s = {point.scale:.4g}: decay rate {point.decay_rate:.4g}, tip-error rms {point.rms:.4g}"
    )


if __name__ == "__main__":
    sys.exit(main())
