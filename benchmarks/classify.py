"""Speed of ``phdesign classify`` (issue 4), against ``python -c pass`` in the same run.

Targets: one beam classification at most 0.8 s cold from the CLI; ``--all-sensors`` on
``timoshenko`` at most 1 s; a synthetic N = 2, n = 6 model (4095 subsets) at most 20 s.
The last one is timed in-process for the search itself (the model is built from
Python code, not from a file) and also as a whole process that builds the model.

Run: ``python benchmarks/classify.py``.
"""

from __future__ import annotations

import resource
import subprocess
import sys
import time
from pathlib import Path

from _timing import PYTHON, report, time_command

ROOT = Path(__file__).resolve().parent.parent

SYNTHETIC = f"""
import sys, time
sys.path.insert(0, {str(ROOT / "tests")!r})
from synthetic import coupled_beams
from phdesign.symbolic.search import search_sensors
t0 = time.perf_counter()
model = coupled_beams(3)
t1 = time.perf_counter()
found = search_sensors(model)
t2 = time.perf_counter()
print(f"{{len(found.subsets)}} {{t1 - t0:.3f}} {{t2 - t1:.3f}}")
"""


def cpu_of(argv: list[str], runs: int = 5) -> float:
    """Median-free mean CPU seconds (user + sys) of ``argv`` as a child process.

    Wall-clock figures on a shared, loaded machine overstate the cost; CPU time does not.
    """
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    for _ in range(runs):
        subprocess.run(argv, check=True, capture_output=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    used = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return used / runs


def main() -> int:
    baseline = time_command([PYTHON, "-c", "pass"])
    ok = True
    beam = [PYTHON, "-m", "phdesign", "classify", "euler-bernoulli", "--sensors", "3,4"]
    ok &= report(
        "classify euler-bernoulli --sensors 3,4 (exact)", time_command(beam), baseline, 0.8
    )
    symbolic = [*beam, "--gain", "symbolic"]
    report(
        "classify euler-bernoulli --sensors 3,4 --gain symbolic",
        time_command(symbolic, runs=3),
        baseline,
        None,
    )
    load_only = [
        PYTHON,
        "-c",
        "from phdesign.models import load_builtin; load_builtin('euler-bernoulli')",
    ]
    report(
        "  of which: import + load the beam model only", time_command(load_only), baseline, None
    )
    for label, argv in (("beam classify", beam), ("beam load only", load_only)):
        print(f"  CPU (user + sys) {label}: {cpu_of(argv):.3f} s")
    timo = [PYTHON, "-m", "phdesign", "classify", "timoshenko", "--all-sensors", "--json"]
    ok &= report("classify timoshenko --all-sensors --json", time_command(timo), baseline, 1.0)
    print(f"  CPU (user + sys) timoshenko --all-sensors: {cpu_of(timo):.3f} s")
    print(f"  CPU (user + sys) python -c pass: {cpu_of([PYTHON, '-c', 'pass']):.3f} s")
    start = time.perf_counter()
    line = subprocess.run([PYTHON, "-c", SYNTHETIC], capture_output=True, text=True, check=True)
    total = time.perf_counter() - start
    subsets, build, search = line.stdout.split()
    print(
        f"synthetic N = 2, n = 6 ({subsets} subsets): whole process {total:.3f} s "
        f"(model build {build} s, search {search} s); target <= 20 s: "
        f"{'met' if total <= 20 else 'MISSED'}"
    )
    ok &= total <= 20
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
