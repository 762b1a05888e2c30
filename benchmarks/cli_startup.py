"""Cold start of ``import phdesign``, ``phdesign ports`` and ``phdesign classify``.

Targets: each command at most 0.8 s on the project machine (issue 3: control and matplotlib
imported lazily; issue 23: building the parser no longer imports the sweep package, whose
job registry gives ``sweep`` its options only when that command is parsed; 0.53 s for
ports and 0.59 s for classify, the fastest of 15 runs on a loaded machine, before it,
0.46 s and 0.53 s after); ``import phdesign`` no slower than before the flat namespace
of issue 11 (0.82 s median on the project machine, when it imported sympy and the io layer eagerly;
now it imports nothing heavy) and ``import phdesign.plots`` without sympy.  Everything is
timed as a fresh process against ``python -c pass``.

Issue 24's target: ``ports`` and ``classify`` start at most 1.2x ``python -c "import sympy"``,
fresh processes in interleaved rounds, compared by their CPU seconds (user + system: the
machine is shared, and a start-up is CPU work).  Beside it the floor that no sympy program
passes: ``import sympy`` followed by one addition, whose first ``Add`` imports
``sympy.tensor.tensor`` and with it ``sympy.combinatorics`` (sympy 1.14's ``Add.flatten``).
Run: ``python benchmarks/cli_startup.py``.
"""

from __future__ import annotations

import statistics
import subprocess
import sys

from _timing import PYTHON, interleaved, load, ratio_report, report, time_command

#: Issue 24: the CLI's start against ``import sympy``, CPU seconds of fresh processes.
AGAINST_SYMPY = 1.2

#: ``import phdesign`` before issue 11 (median on the project machine, eager sympy and io).
IMPORT_BEFORE = 0.82


def main() -> int:
    baseline = time_command([PYTHON, "-c", "pass"])
    imported = time_command([PYTHON, "-c", "import phdesign"])
    ok_import = report("import phdesign", imported, baseline, target=IMPORT_BEFORE)
    plots = time_command([PYTHON, "-c", "import phdesign.plots"])
    report("import phdesign.plots", plots, baseline, target=None)
    probe_plots = (
        "import sys, phdesign.plots\n"
        "print(' '.join(m for m in ('sympy', 'matplotlib', 'scipy') if m in sys.modules))\n"
    )
    heavy = subprocess.run(
        [PYTHON, "-c", probe_plots], capture_output=True, text=True, check=True
    ).stdout.strip()
    print(f"heavy modules imported by import phdesign.plots: {heavy or 'none'}")
    command = [PYTHON, "-m", "phdesign", "ports", "euler-bernoulli", "--json"]
    timings = time_command(command)
    ok = report("phdesign ports euler-bernoulli --json", timings, baseline, target=0.8)
    classify = [PYTHON, "-m", "phdesign", "classify", "euler-bernoulli", "--sensors", "3,4"]
    timings = time_command(classify)
    ok = report("phdesign classify euler-bernoulli --sensors 3,4", timings, baseline, 0.8) and ok
    probe = (
        "import sys\n"
        "from phdesign.cli import main\n"
        "main(['ports', 'euler-bernoulli', '--json'])\n"
        "heavy = ('control', 'matplotlib', 'scipy', 'phdesign.numeric', 'phdesign.sweep')\n"
        "print(' '.join(m for m in heavy if m in sys.modules), file=sys.stderr)\n"
    )
    modules = subprocess.run(
        [PYTHON, "-c", probe], capture_output=True, text=True, check=True
    ).stderr.strip()
    print(f"heavy modules imported by the command: {modules or 'none'}")
    return 0 if ok and ok_import and "sympy" not in heavy and against_sympy() else 1


def against_sympy(rounds: int = 15) -> bool:
    """Issue 24: ``ports`` and ``classify`` against ``import sympy``, interleaved CPU seconds."""
    print(load())
    commands = {
        "import sympy": [PYTHON, "-c", "import sympy"],
        "import sympy + one addition": [PYTHON, "-c", "import sympy; sympy.Symbol('x') + 1"],
        "ports": [PYTHON, "-m", "phdesign", "ports", "euler-bernoulli", "--json"],
        "classify": [PYTHON, "-m", "phdesign", "classify", "euler-bernoulli", "--sensors", "3,4"],
    }
    cpu = interleaved(commands, rounds=rounds, cpu=True)
    sympy_cpu = cpu.pop("import sympy")
    floor = statistics.median(cpu.pop("import sympy + one addition"))
    print(
        f"import sympy + one addition (sympy's own floor): "
        f"{floor / statistics.median(sympy_cpu):.2f}x import sympy"
    )
    ok = True
    for name, timings in cpu.items():
        ok = ratio_report(name, timings, sympy_cpu, "import sympy", AGAINST_SYMPY) and ok
    print(load())
    return ok


if __name__ == "__main__":
    sys.exit(main())
