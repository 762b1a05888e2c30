"""Cold start of ``phdesign ports euler-bernoulli --json`` against ``python -c pass``.

Target (issue 3): at most 0.8 s on the project machine, which requires control and
matplotlib to be imported lazily. Run: ``python benchmarks/cli_startup.py``.
"""

from __future__ import annotations

import subprocess
import sys

from _timing import PYTHON, report, time_command


def main() -> int:
    baseline = time_command([PYTHON, "-c", "pass"])
    command = [PYTHON, "-m", "phdesign", "ports", "euler-bernoulli", "--json"]
    timings = time_command(command)
    ok = report("phdesign ports euler-bernoulli --json", timings, baseline, target=0.8)
    probe = (
        "import sys\n"
        "from phdesign.cli import main\n"
        "main(['ports', 'euler-bernoulli', '--json'])\n"
        "heavy = ('control', 'matplotlib', 'scipy', 'phdesign.numeric')\n"
        "print(' '.join(m for m in heavy if m in sys.modules), file=sys.stderr)\n"
    )
    modules = subprocess.run(
        [PYTHON, "-c", probe], capture_output=True, text=True, check=True
    ).stderr.strip()
    print(f"heavy modules imported by the command: {modules or 'none'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
