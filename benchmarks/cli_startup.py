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

The command line pauses Python's garbage collector while it starts up
(:func:`phdesign.cli.common.pause_collection`); ``import sympy`` with the collector paused
is printed beside as well, so that the share of the pause can be read off.  Counts that do
not depend on the machine's load are printed with the times: the modules each command
imports after ``import sympy`` and its first addition, and, with ``--instructions`` (needs
valgrind; about a minute per command), the instructions each process executes
(``valgrind --tool=callgrind``) against ``import sympy``'s.

Run: ``python benchmarks/cli_startup.py`` (all), ``python benchmarks/cli_startup.py
against-sympy [ROUNDS] [--instructions]`` (issue 24's target only).
"""

from __future__ import annotations

import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

from _timing import (
    PYTHON,
    fresh_environment,
    interleaved,
    load,
    ratio_report,
    report,
    time_command,
)

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


#: Issue 24's commands: the built-in beam, as the issue names them.
PORTS = ["ports", "euler-bernoulli", "--json"]
CLASSIFY = ["classify", "euler-bernoulli", "--sensors", "3,4", "--gain", "0.1,1"]


def against_sympy(rounds: int = 15, instructions: bool = False) -> bool:
    """Issue 24: ``ports`` and ``classify`` against ``import sympy``, interleaved CPU seconds."""
    print(load())
    commands = {
        "import sympy": [PYTHON, "-c", "import sympy"],
        "import sympy + one addition": [PYTHON, "-c", "import sympy; sympy.Symbol('x') + 1"],
        "import sympy, collector paused": [PYTHON, "-c", "import gc; gc.disable(); import sympy"],
        "ports": [PYTHON, "-m", "phdesign", *PORTS],
        "classify": [PYTHON, "-m", "phdesign", *CLASSIFY],
    }
    cpu = interleaved(commands, rounds=rounds, cpu=True)
    sympy_cpu = cpu.pop("import sympy")
    for reference in ("import sympy + one addition", "import sympy, collector paused"):
        ratio = statistics.median(cpu.pop(reference)) / statistics.median(sympy_cpu)
        print(f"{reference}: {ratio:.2f}x import sympy (not a target)")
    ok = True
    for name, timings in cpu.items():
        ok = ratio_report(name, timings, sympy_cpu, "import sympy", AGAINST_SYMPY) and ok
    print(load())
    for argv in (PORTS, CLASSIFY):
        print(f"modules imported by phdesign {' '.join(argv)} after sympy: {modules_after(argv)}")
    if instructions:
        print_instructions(
            {name: commands[name] for name in ("import sympy", "ports", "classify")}
        )
    return ok


def modules_after(argv: list[str]) -> int:
    """How many modules ``phdesign ARGV`` imports beyond ``import sympy`` and one addition."""
    probe = (
        "import contextlib, io, sys, sympy\n"
        "sympy.Symbol('x') + 1\n"
        "before = set(sys.modules)\n"
        "from phdesign.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    assert main({argv!r}) == 0\n"
        "print(len(set(sys.modules) - before))\n"
    )
    out = subprocess.run([PYTHON, "-c", probe], capture_output=True, text=True, check=True)
    return int(out.stdout)


def instructions_of(argv: list[str]) -> int:
    """Instructions a fresh process executes (``valgrind --tool=callgrind``; load-free)."""
    with tempfile.TemporaryDirectory() as folder:
        log = os.path.join(folder, "callgrind.log")
        subprocess.run(
            [
                "valgrind",
                "--tool=callgrind",
                f"--callgrind-out-file={folder}/out",
                f"--log-file={log}",
                *argv,
            ],
            check=True,
            capture_output=True,
            env=fresh_environment(),
        )
        with open(log, encoding="utf-8") as stream:
            found = re.search(r"Collected : (\d+)", stream.read())
    if found is None:
        raise RuntimeError("valgrind printed no instruction count")
    return int(found.group(1))


def print_instructions(commands: dict[str, list[str]]) -> None:
    """Print each command's instructions against the first command's (after a warm-up run)."""
    if shutil.which("valgrind") is None:
        print("instructions: valgrind is not installed")
        return
    for argv in commands.values():  # the first run writes bytecode caches
        subprocess.run(argv, check=True, capture_output=True, env=fresh_environment())
    counts = {name: instructions_of(argv) for name, argv in commands.items()}
    base_name, base = next(iter(counts.items()))
    for name, count in counts.items():
        print(f"instructions, {name}: {count / 1e6:.0f} M, {count / base:.3f}x {base_name}")


if __name__ == "__main__":
    if sys.argv[1:2] == ["against-sympy"]:
        rounds = [int(a) for a in sys.argv[2:] if a.isdigit()]
        sys.exit(0 if against_sympy(*rounds, instructions="--instructions" in sys.argv) else 1)
    sys.exit(main())
