"""Whole-process timing helpers shared by the benchmark scripts (standard library only)."""

from __future__ import annotations

import os
import resource
import statistics
import subprocess
import sys
import time
from collections.abc import Mapping, Sequence


def fresh_environment() -> dict[str, str]:
    """The environment of the timed processes: bytecode may be cached, as in an install.

    With ``PYTHONDONTWRITEBYTECODE`` set every fresh process compiles phdesign's modules
    again (the peers' site-packages are compiled already), which is no user's start-up.
    """
    return {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def load() -> str:
    """The machine's load averages (1, 5, 15 minutes) and its processors, as text."""
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f}, {five:.2f}, {fifteen:.2f} on {os.cpu_count()} processors"


def interleaved(
    commands: Mapping[str, Sequence[str]], rounds: int = 7, warmup: int = 1, cpu: bool = False
) -> dict[str, list[float]]:
    """Seconds of each command as a fresh process, in interleaved rounds.

    Each round runs every command once (A B A B ...), so that a drift of the machine's
    speed touches all alike; the first ``warmup`` rounds are not counted.  Wall-clock
    seconds, or with ``cpu`` the process's user + system seconds (less sensitive to the
    other processes of a loaded machine).
    """
    env = fresh_environment()
    timings: dict[str, list[float]] = {name: [] for name in commands}
    for index in range(warmup + rounds):
        for name, argv in commands.items():
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            start = time.perf_counter()
            subprocess.run(argv, check=True, capture_output=True, env=env)
            wall = time.perf_counter() - start
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            used = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
            if index >= warmup:
                timings[name].append(used if cpu else wall)
    return timings


def ratio_report(
    label: str, timings: Sequence[float], peer: Sequence[float], peer_label: str, target: float
) -> bool:
    """Print the medians and the ratio of medians to the peer; return whether it is <= target."""
    ratio = statistics.median(timings) / statistics.median(peer)
    ok = ratio <= target
    print(
        f"{label}: median {statistics.median(timings):.3f} s (min {min(timings):.3f}, max "
        f"{max(timings):.3f}); {peer_label}: median {statistics.median(peer):.3f} s; ratio "
        f"{ratio:.2f}x, target <= {target:g}x: {'met' if ok else 'MISSED'}"
    )
    return ok


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
