"""The command lines whose JSON output is kept as golden files (the structure issue).

Recorded before the package moved into its pipeline folders, by
``OPENBLAS_NUM_THREADS=1 python tests/golden_cases.py --record`` (it writes
``tests/golden/*.json``; one BLAS thread, as the suite runs: more threads reorder sums
and move some figures by 1e-10); the test
``tests/test_golden.py`` runs them again and compares every number to 1e-12 (relative, or
absolute against 1 where a value is round-off about 0: floating point may reorder sums)
and the strings that say what a result is (verdicts, kinds, statuses).  Keys may be
added to an output (the CLI contract), never removed.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

HERE = Path(__file__).parent / "golden"

CASES: dict[str, list[str]] = {
    "ports_beam": ["ports", "euler-bernoulli", "--json"],
    "ports_airy": ["ports", "airy", "--json"],
    "classify_beam": ["classify", "euler-bernoulli", "--sensors", "3,4", "--gain", "0.1,1"],
    "classify_beam_symbolic": [
        "classify",
        "euler-bernoulli",
        "--sensors",
        "3,4",
        "--gain",
        "symbolic",
    ],
    "classify_timoshenko_all": ["classify", "timoshenko", "--all-sensors", "--gain", "1"],
    "spectrum_wave": ["spectrum", "wave", "--sensors", "2", "--gain", "0.5"],
    "spectrum_beam": ["spectrum", "euler-bernoulli", "--sensors", "3,4", "--gain", "0.1,1"],
    "spectrum_airy": ["spectrum", "airy", "--sensors", "1", "--gain", "1"],
    "spectrum_tip": ["spectrum", "beam-tip-damper"],
    "simulate_beam": [
        "simulate",
        "euler-bernoulli",
        "--sensors",
        "3,4",
        "--gain",
        "0.1,1",
        "--x0",
        "x1: 0, x2: z - 0.9",
        "--t-end",
        "1",
        "--samples",
        "11",
    ],
    "tune_wave": ["tune", "wave", "--sensors", "2"],
    "noise_wave": ["noise", "wave-damper", "--sensors", "1", "--gain", "0.4"],
    "tradeoff_wave": [
        "tradeoff",
        "wave-damper",
        "--sensors",
        "1",
        "--direction",
        "0.4",
        "--scales",
        "0.5:2:3",
        "--trace",
        "e1(1)",
    ],
    "export_beam": [
        "export",
        "euler-bernoulli",
        "--sensors",
        "3,4",
        "--gain",
        "0.1,1",
        "--dt",
        "1e-3",
        "--design",
        "given",  # the gain as given: the export's numbers before gain designs existed
        "--format",
        "json",
        "-o",
        "{tmp}/observer.json",
    ],
    "loop_spectrum_beam": [
        "loop",
        "spectrum",
        "euler-bernoulli",
        "--actuate",
        "3",
        "--feedback",
        "1",
        "--sensors",
        "4",
        "--gain",
        "1",
    ],
    "sweep_beam": [
        "sweep",
        "euler-bernoulli",
        "--sensors",
        "3,4",
        "--grid",
        "l1=0.05:0.2:2",
        "--grid",
        "l2=0.5:2:2",
        "--scheduler",
        "synchronous",
        "-o",
        "{tmp}/s.csv",
    ],
}

#: Keys whose values say how or where a run went, not what it computed.
VOLATILE = frozenset({"seconds", "compute_seconds", "elapsed", "output", "path", "scheduler"})
#: Numbers that round-off moves by more than 1e-12, compared to 1e-6 (relative): the
#: digits of an agreement (a logarithm of a round-off-level difference: 1e-14 becoming
#: 1e-13 moves it by 1) and the location of a smooth maximum (known to about √ε).
LOOSE = frozenset({"digits", "frequency", "frequencies", "peak_frequency"})
#: String values compared exactly: what a result is.
VERDICTS = frozenset({"verdict", "kind", "status", "model", "proposition", "method", "system"})


def run(argv: list[str]) -> dict:
    """Run a command line in this process (outputs in a fresh folder); its JSON output."""
    import contextlib
    import io
    import tempfile

    from phdesign.cli import main

    out, err = io.StringIO(), io.StringIO()
    with tempfile.TemporaryDirectory() as tmp:
        line = [a.replace("{tmp}", tmp) for a in argv] + ["--json"]
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(line)
    if code != 0:
        raise RuntimeError(f"{argv}: exit {code}: {err.getvalue()}")
    return json.loads(out.getvalue())


def differences(golden: object, found: object, where: str = "", tol: float = 1e-12) -> list[str]:
    """Where ``found`` differs from ``golden`` (numbers to 1e-12, see the module docstring)."""
    if isinstance(golden, dict):
        if not isinstance(found, dict):
            return [f"{where}: expected an object"]
        out = []
        for key, value in golden.items():
            if key in VOLATILE:
                continue
            if key not in found:
                out.append(f"{where}.{key}: missing")
            elif isinstance(value, str):
                if key in VERDICTS and found[key] != value:
                    out.append(f"{where}.{key}: {value!r} became {found[key]!r}")
            elif key in LOOSE:
                out += differences(value, found[key], f"{where}.{key}", tol=1e-6)
            else:
                out += differences(value, found[key], f"{where}.{key}", tol=tol)
        return out
    if isinstance(golden, list):
        if not isinstance(found, list) or len(found) != len(golden):
            return [f"{where}: expected a list of {len(golden)}"]
        numbers = [
            abs(v) for v in golden if isinstance(v, int | float) and not isinstance(v, bool)
        ]
        scale = max([1.0, *numbers])
        out = []
        for i, (g, f) in enumerate(zip(golden, found, strict=True)):
            if isinstance(g, int | float) and not isinstance(g, bool):
                out += _number(g, f, f"{where}[{i}]", scale, tol)
            elif not isinstance(g, str):
                out += differences(g, f, f"{where}[{i}]", tol=tol)
        return out
    if isinstance(golden, bool) or golden is None:
        return [] if found == golden else [f"{where}: {golden} became {found}"]
    if isinstance(golden, int | float):
        return _number(golden, found, where, max(1.0, abs(golden)), tol)
    return []


def _number(golden: float, found: object, where: str, scale: float, tol: float) -> list[str]:
    if not isinstance(found, int | float) or isinstance(found, bool):
        return [f"{where}: {golden} became {found!r}"]
    return [] if abs(found - golden) <= tol * scale else [f"{where}: {golden!r} became {found!r}"]


def main() -> int:
    if sys.argv[1:] != ["--record"]:
        print("usage: python tests/golden_cases.py --record", file=sys.stderr)
        return 2
    HERE.mkdir(exist_ok=True)
    for name, argv in CASES.items():
        (HERE / f"{name}.json").write_text(json.dumps(run(argv), indent=1, sort_keys=True) + "\n")
        print(name)
    return 0


if __name__ == "__main__":
    sys.exit(main())
