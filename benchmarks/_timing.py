"""Whole-process timing helpers shared by the benchmark scripts (standard library only)."""

from __future__ import annotations

import statistics
import subprocess
import sys
import time
from collections.abc import Sequence


def time_command(argv: Sequence[str], runs: int = 7, warmup: int = 1) -> list[float]:
    """Wall-clock seconds of ``argv`` run as a fresh process, ``runs`` times after a warm-up."""
    timings = []
    for index in range(warmup + runs):
        start = time.perf_counter()
        subprocess.run(argv, check=True, capture_output=True)
        if index >= warmup:
            timings.append(time.perf_counter() - start)
    return timings


def timed(fn, repeat: int = 5):  # type: ignore[no-untyped-def]
    """Call ``fn()`` ``repeat`` times in this process; return (last result, walls, cpus)."""
    walls, cpus, out = [], [], None
    for _ in range(repeat):
        wall, cpu = time.perf_counter(), time.process_time()
        out = fn()
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    return out, walls, cpus


def report(
    label: str, timings: Sequence[float], baseline: Sequence[float], target: float | None
) -> bool:
    """Print median, spread and ratio to the baseline; return whether the target holds."""
    median, base = statistics.median(timings), statistics.median(baseline)
    verdict = ""
    ok = True
    if target is not None:
        ok = median <= target
        verdict = f"  target <= {target:g} s: {'met' if ok else 'MISSED'}"
    print(
        f"{label}: median {median:.3f} s (min {min(timings):.3f}, max {max(timings):.3f}); "
        f"{median / base:.1f}x the baseline ({base:.3f} s){verdict}"
    )
    return ok


PYTHON = sys.executable
