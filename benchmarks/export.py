"""Benchmark: exporting the beam's sampled observer, and the speed of the generated C step.

Targets (issue 15): exporting the paper's beam observer (sensors y3, y4, L = diag(0.1, 1),
dt = 1 ms, averaged samples) *with verification* takes at most 5 s, as a library call and
as a fresh ``phdesign export`` process (imports included); the generated C step of the
order-34 observer (Legendre degree 16) runs at least 1e5 steps per second.

Baselines, measured in the same process: one converged ``spectrum`` of the same error
system (what the order selection builds on), and the same observer stepped in Python
with numpy (``SampledObserver.step``).

Run:  python benchmarks/export.py            (exit status 1 if a target is missed)
The machine is shared: under load wall times are pessimistic; CPU times are printed too.
"""

from __future__ import annotations

import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _timing import PYTHON, report, time_command

from phdesign.models import load_builtin
from phdesign.numeric.bridge import to_numeric
from phdesign.numeric.sampled.export import export_observer
from phdesign.numeric.spectrum.converged import spectrum

SENSORS = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
GAIN = np.diag([0.1, 1.0])
STEPS = 2_000_000

DRIVER = r"""
#include <stdio.h>
#include <time.h>
#include "observer.h"

int main(void)
{
    phd_observer obs;
    double v[PHD_OBSERVER_NV], out[PHD_OBSERVER_NOUT], check = 0.0;
    long k, steps = %(steps)d;
    int i;
    clock_t start;
    phd_observer_init(&obs);
    start = clock();
    for (k = 0; k < steps; ++k) {
        for (i = 0; i < PHD_OBSERVER_NV; ++i) {
            v[i] = (double)((k + i) %% 7) - 3.0;
        }
        phd_observer_step(&obs, v, out);
        check += out[PHD_OBSERVER_NOUT - 1];
    }
    printf("%%.6f %%.17g\n", (double)(clock() - start) / CLOCKS_PER_SEC, check);
    return 0;
}
"""


def timed(fn, repeat):
    walls, cpus, out = [], [], None
    for _ in range(repeat):
        w, c = time.perf_counter(), time.process_time()
        out = fn()
        walls.append(time.perf_counter() - w)
        cpus.append(time.process_time() - c)
    return out, walls, cpus


def c_steps_per_second(observer, folder: Path) -> float | None:
    compiler = shutil.which("cc")
    if compiler is None:
        print("C step: no C compiler (cc) on this machine; not measured")
        return None
    observer.write(str(folder / "c"), "c")
    (folder / "c" / "bench.c").write_text(DRIVER % {"steps": STEPS})
    binary = folder / "c" / "bench"
    subprocess.run(
        [compiler, "-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", "observer.c", "bench.c",
         "-o", str(binary)],
        cwd=folder / "c", check=True,
    )  # fmt: skip
    seconds = min(
        float(subprocess.run([str(binary)], capture_output=True, text=True, check=True)
              .stdout.split()[0])
        for _ in range(3)
    )  # fmt: skip
    return STEPS / seconds


def main() -> int:
    nm = to_numeric(load_builtin("euler-bernoulli"))
    ok = True

    def baseline():
        return spectrum(nm, SENSORS, GAIN)

    def export_default():
        return export_observer(nm, SENSORS, GAIN, dt=1e-3, verify=True)

    def export_34():
        return export_observer(nm, SENSORS, GAIN, dt=1e-3, order=34, verify=True)

    baseline()  # warm caches (Gauss rules) for every measurement alike
    _, base, base_cpu = timed(baseline, 5)
    chosen, walls, cpus = timed(export_default, 5)
    print(f"default order: {chosen.order} states (degree {chosen.selection.degree})")
    ok &= report("export_observer(verify=True), default order", walls, base, 5.0)
    print(f"  cpu median {statistics.median(cpus):.3f} s (baseline cpu "
          f"{statistics.median(base_cpu):.3f} s)")  # fmt: skip
    observer, walls, cpus = timed(export_34, 5)
    ok &= report("export_observer(verify=True), order 34", walls, base, 5.0)

    with tempfile.TemporaryDirectory() as tmp:
        argv = [PYTHON, "-m", "phdesign", "export", "euler-bernoulli", "--sensors", "3,4",
                "--gain", "0.1,1", "--dt", "1e-3", "--verify", "--format", "json", "-o",
                str(Path(tmp) / "o.json"), "--force"]  # fmt: skip
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        command = time_command(argv, runs=3)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        ok &= report("phdesign export --verify (fresh process)", command, base, 5.0)
        cpu = (after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime) / 4
        print(f"  cpu per process {cpu:.3f} s (mean of the warm-up and 3 runs; imports included)")

        rng = np.random.default_rng(0)
        V = rng.standard_normal((20_000, len(observer.inputs)))
        _, py_walls, _ = timed(lambda: observer.run(V), 3)
        python_rate = len(V) / min(py_walls)
        rate = c_steps_per_second(observer, Path(tmp))
        print(f"Python/numpy step (order {observer.order}): {python_rate:,.0f} steps/s (baseline)")
        if rate is not None:
            met = rate >= 1e5
            ok &= met
            print(
                f"C step (order {observer.order}, -O2): {rate:,.0f} steps/s, "
                f"{rate / python_rate:.0f}x the Python step; target >= 1e5: "
                f"{'met' if met else 'MISSED'}"
            )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
