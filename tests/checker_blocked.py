"""Run the proof checker in a subprocess with flint, numpy, sympy and scipy blocked.

Shared by tests/numeric/certified/test_checker_independence.py and test_rate_z.py.
"""

from __future__ import annotations

import subprocess
import sys

from paths import ROOT

BLOCKED = """
import sys
class Block:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in ("flint", "numpy", "sympy", "scipy"):
            raise ImportError(f"{name} is blocked for the checker")
        return None
sys.meta_path.insert(0, Block())
from phdesign.proofcheck import check_file
failures = [f for path in sys.argv[1:] for f in check_file(path)]
loaded = sorted(m for m in sys.modules if m.split(".")[0] in ("flint", "numpy", "sympy"))
print(repr((failures, loaded)))
"""


def run_blocked(paths: list[str]) -> subprocess.CompletedProcess:
    """Check the proof files ``paths``; stdout is ``repr((failures, blocked modules loaded))``."""
    return subprocess.run(
        [sys.executable, "-c", BLOCKED, *paths],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"},
        check=False,
    )
