"""Benchmark: every design notebook executed headless, against the 5-minute budget (issue 6).

The notebooks' budget is a speed figure, so it lives here and not in a test (a test never
depends on wall-clock time: tests/test_notebooks.py checks that each notebook runs and
what it asserts).  Each ``notebooks/NN_*.py`` is executed once, as the tests and the
documentation build execute it (``docs/_ext/notebook_cache.py``), into a temporary cache so
that the stored executions of the docs build are not touched.  The baseline run in the same
process is ``python -c "import phdesign"`` in a fresh interpreter, so the printed ratios say
how many start-ups each notebook costs; the budget is read against the wall-clock total
(run it on a quiet machine: the kernel's time is shared with whatever else runs).

Run:  python benchmarks/notebooks.py          (exit status 1 if the total exceeds 300 s)
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _timing import load

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs" / "_ext"))
import notebook_cache  # noqa: E402  (docs/_ext: the one way notebooks are executed)

BUDGET = 300.0  # seconds, all notebooks together (issue 6)


def start_up_seconds() -> float:
    """Wall-clock seconds of ``import phdesign`` in a fresh interpreter (the baseline)."""
    began = time.perf_counter()
    subprocess.run([sys.executable, "-c", "import phdesign"], check=True)
    return time.perf_counter() - began


def main() -> int:
    print(load())
    baseline = start_up_seconds()
    total = 0.0
    with tempfile.TemporaryDirectory() as folder:
        for path in notebook_cache.notebook_paths():
            _, seconds = notebook_cache.execute(path, cache=Path(folder) / "cache")
            total += seconds
            print(f"{path.stem:32s} {seconds:7.1f} s  {seconds / baseline:7.0f}x import phdesign")
    verdict = "met" if total <= BUDGET else "MISSED"
    print(f"all notebooks: {total:.1f} s against a budget of {BUDGET:.0f} s ({verdict})")
    return 0 if total <= BUDGET else 1


if __name__ == "__main__":
    sys.exit(main())
