"""Cost of loading valid models and of refusing hostile ones (issue 12), in CPU seconds.

Targets: a valid model of order <= 6 and size <= 6 (``tests/synthetic.py``) loads in at
most 5 s (it took 178 s for N = 6, n = 4 before the exact domains); H = diag((z+1)**64, 1)
is checked exactly in at most 5 s (87 s before the real-root isolation). Each figure is
the CPU time of a child process (user + sys, so a loaded machine does not inflate it),
printed with its ratio to ``import phdesign`` in the same run, the baseline.

Run: ``python benchmarks/model_load.py``.
"""

from __future__ import annotations

import resource
import subprocess
import sys
from pathlib import Path

from _timing import PYTHON

ROOT = Path(__file__).resolve().parent.parent

SYNTHETIC = f"""
import sys
sys.path.insert(0, {str(ROOT / "tests")!r})
from synthetic import random_model
random_model({{order}}, {{size}}, 0)
"""

GRADED = """
from phdesign.symbolic.model import BCPHS
BCPHS.define(name="graded", interval=(0, 1), order=1, P={1: [[0, 1], [1, 0]]},
             H=[["(z+1)**64", 0], [0, "1/(1 + z**2)**30"]],
             inputs=["e1(0)", "e2(1)"], outputs=["-e2(0)", "e1(1)"])
"""


def cpu_of(code: str, runs: int = 3) -> float:
    """Smallest CPU seconds (user + sys) of ``python -c code`` over ``runs`` runs."""
    best = float("inf")
    for _ in range(runs):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([PYTHON, "-c", code], check=True, capture_output=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        best = min(best, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return best


def main() -> int:
    baseline = cpu_of("import phdesign")
    print(f"baseline: import phdesign {baseline:.2f} s CPU")
    ok = True
    cases = [
        (f"synthetic N = {N}, n = {n}", SYNTHETIC.format(order=N, size=n), 5.0)
        for N, n in ((2, 6), (4, 4), (6, 4), (6, 6))
    ]
    cases.append(("H = diag((z+1)**64, 1/(1+z^2)^30), exact", GRADED, 5.0))
    for label, code, target in cases:
        seconds = cpu_of(code) - baseline
        met = seconds <= target
        ok &= met
        ratio = (seconds + baseline) / baseline
        print(
            f"{label}: {seconds:.2f} s CPU beyond the import ({ratio:.1f}x the baseline); "
            f"target <= {target:g} s: {'met' if met else 'MISSED'}"
        )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
