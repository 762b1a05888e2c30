"""Benchmark: ``phdesign tune`` on the paper's beam against one ``phdesign spectrum`` command.

Targets (issue 10), measured in the same run:

* wall time of ``phdesign tune euler-bernoulli --sensors 3,4`` at most 3 times that of one
  ``phdesign spectrum euler-bernoulli --sensors 3,4 --gain 0.1,1`` (fresh processes,
  medians);
* the same optimum: the abscissa at the returned gain within 1e-3 of the triple-root
  optimum -5.8333507598 (three real eigenvalues coalesce there; the value solves
  F = F' = F'' = 0 for the characteristic function in mpmath,
  tests/numeric/tuning/test_numeric_tune.py,
  which also checks the true abscissa at the returned gain).

It also prints the evaluations (gains evaluated) and what the library's one-BLAS-thread
limit (``phdesign.numeric.threads``) buys: the same tune in this process with and without
it.  That comparison needs the default BLAS threads, so run this script WITHOUT
``OPENBLAS_NUM_THREADS=1`` (it says so when the variable is set).  Under load every time
is pessimistic; the ratios are what to read.

Run:  python benchmarks/tune.py   (exit 1 if a target fails)
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np
from _timing import PYTHON, time_command
from threadpoolctl import threadpool_info

from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.threads import small_dense_threads
from phdesign.numeric.tuning.search import tune

TRIPLE_ROOT = -5.833350759830179  # mpmath, tests/numeric/tuning/test_numeric_tune.py::triple_root
SPECTRUM = [PYTHON, "-m", "phdesign", "spectrum", "euler-bernoulli", "--sensors", "3,4"]
SPECTRUM += ["--gain", "0.1,1"]
TUNE = [PYTHON, "-m", "phdesign", "tune", "euler-bernoulli", "--sensors", "3,4", "--json"]


def in_process(limit: bool, runs: int = 2) -> tuple[float, float, int]:
    """Median wall and CPU seconds of tune() in this process, with or without the limit."""
    nm = to_numeric(load_builtin("euler-bernoulli"))
    C = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    walls, cpus = [], []
    evaluations = 0
    for _ in range(runs):
        w0, c0 = time.perf_counter(), time.process_time()
        with small_dense_threads(enabled=limit):
            result = tune(nm, C)
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
        evaluations = result.evaluations
    return statistics.median(walls), statistics.median(cpus), evaluations


def main() -> int:
    spectrum_times = time_command(SPECTRUM, runs=3)
    tune_times = time_command(TUNE, runs=3)
    out = subprocess.run(TUNE, check=True, capture_output=True, text=True).stdout
    result = json.loads(out)
    ratio = statistics.median(tune_times) / statistics.median(spectrum_times)
    alpha = result["spectral_abscissa"]
    same = alpha is not None and abs(alpha - TRIPLE_ROOT) < 1e-3
    fast = ratio <= 3.0
    print(
        f"one spectrum command: median {statistics.median(spectrum_times):.2f} s "
        f"(min {min(spectrum_times):.2f}, max {max(spectrum_times):.2f})"
    )
    print(
        f"tune command:         median {statistics.median(tune_times):.2f} s "
        f"(min {min(tune_times):.2f}, max {max(tune_times):.2f}); "
        f"{result['evaluations']} evaluations at resolutions {result['search_resolutions']}, "
        f"verified at {result['resolutions']}"
    )
    print(f"ratio tune / spectrum: {ratio:.2f}   target <= 3: {'met' if fast else 'MISSED'}")
    print(
        f"optimum: L = {result['gain']}, abscissa {alpha:.10f} "
        f"(triple root {TRIPLE_ROOT:.10f}, difference {alpha - TRIPLE_ROOT:+.1e}); "
        f"worst over ±5 % of the gains {result['robustness']['worst_abscissa']:.4f}   "
        f"target |difference| < 1e-3: {'met' if same else 'MISSED'}"
    )
    threads = max(i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas")
    if os.environ.get("OPENBLAS_NUM_THREADS") == "1":
        print("BLAS threads: OPENBLAS_NUM_THREADS=1 is set, so both runs below use one thread")
    wall_on, cpu_on, _ = in_process(limit=True)
    wall_off, cpu_off, _ = in_process(limit=False)
    print(
        f"BLAS threads ({threads} available): tune in-process with the one-thread limit "
        f"{wall_on:.2f} s wall / {cpu_on:.2f} s CPU; without it {wall_off:.2f} s wall / "
        f"{cpu_off:.2f} s CPU: {wall_off / wall_on:.1f}x the wall time, "
        f"{cpu_off / cpu_on:.1f}x the CPU time"
    )
    print("targets:", "met" if fast and same else "MISSED")
    return 0 if fast and same else 1


if __name__ == "__main__":
    sys.exit(main())
