"""Start-up of the command line: what building the parser and the light commands import."""

from __future__ import annotations

import ast
import subprocess
import sys

from phdesign.cli import COMMAND_MODULES, build_parser

# Packages that ``ports`` and ``classify`` never need: the sweep (its job registry gives
# ``sweep`` its options only when that command is parsed), the figures, generated code
# and the numeric layer (benchmarks/cli_startup.py times the same commands).
NOT_IMPORTED = ("phdesign.sweep", "phdesign.plots", "phdesign.codegen", "phdesign.numeric")

# What reading a model and classifying it never need (issue 24): the writers of model
# files, output files and JSON, and the notebook view's HTML escaping.
NOT_IMPORTED_BY_CLASSIFY = ("tomli_w", "phdesign.core.files", "json", "html")


def test_ports_and_classify_import_no_sweep_plots_or_numeric_package():
    probe = (
        "import contextlib, io, sys\n"
        "from phdesign.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    assert main(['ports', 'euler-bernoulli', '--json']) == 0\n"
        "    assert main(['classify', 'wave', '--sensors', '2']) == 0\n"
        f"packages = {NOT_IMPORTED!r}\n"
        "print(sorted(p for p in packages if any(m == p or m.startswith(p + '.') "
        "for m in sys.modules)))\n"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]", out.stdout


def test_the_sweep_options_are_added_when_sweep_is_used():
    parser = build_parser()
    sweep = next(a for a in parser._actions if a.dest == "command").choices["sweep"]
    help_text = sweep.format_help()
    assert "--max-resolution N" in help_text  # an option of the spectrum job
    assert "--job {classify,gain,spectrum}" in help_text
    args = parser.parse_args(["sweep", "wave", "-o", "m.csv", "--tol", "-1e-3"])
    assert (args.job, args.option_tol) == ("spectrum", -1e-3)  # a negative value is taken


def _commands(parser) -> dict:
    return next(a for a in parser._actions if a.dest == "command").choices


def test_the_command_table_names_the_module_that_registers_each_command():
    # the full parser's commands, in help order, are exactly the table's keys
    assert list(_commands(build_parser())) == list(COMMAND_MODULES)
    for command, module in COMMAND_MODULES.items():
        alone = _commands(build_parser(command))
        siblings = [c for c, m in COMMAND_MODULES.items() if m == module]
        assert list(alone) == siblings, command  # its module's commands and no other's


def test_a_run_builds_only_its_own_commands_and_parses_as_the_full_parser():
    argv = ["classify", "wave", "--sensors", "2", "--gain", "0.5"]
    assert (
        vars(build_parser("classify").parse_args(argv)).keys()
        == vars(build_parser().parse_args(argv)).keys()
    )
    probe = (
        "import contextlib, io, sys\n"
        "from phdesign.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    assert main(['ports', 'wave', '--json']) == 0\n"
        "print(sorted(m for m in sys.modules if m.startswith('phdesign.cli.')))\n"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    loaded = ast.literal_eval(out.stdout)
    assert "phdesign.cli.model_commands" in loaded
    assert not {"phdesign.cli.numeric_commands", "phdesign.cli.loop_command"} & set(loaded)


def test_classify_imports_no_writer_json_or_html():
    probe = (
        "import contextlib, io, sys\n"
        "from phdesign.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    assert main(['classify', 'euler-bernoulli', '--sensors', '3,4', '--gain', "
        "'0.1,1']) == 0\n"
        f"packages = {NOT_IMPORTED_BY_CLASSIFY!r}\n"
        "print(sorted(p for p in packages if any(m == p or m.startswith(p + '.') "
        "for m in sys.modules)))\n"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]", out.stdout


# Records whether the garbage collector runs when the model is loaded, then runs the
# command line as the console script does (``run``) or as a library call (``main``).
_GC_PROBE = """
import contextlib, gc, io, sys
import phdesign.models as models
states, real = [], models.load
def load(*args, **kwargs):
    states.append(gc.isenabled())
    return real(*args, **kwargs)
models.load = load
from phdesign.cli import main, run
sys.argv = ["phdesign", *sys.argv[2:]]
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
    try:
        code = run() if {entry!r} == "run" else main()
    except SystemExit as stop:
        code = stop.code
print(states, gc.isenabled(), gc.get_freeze_count() > 0, code)
"""


def _gc_states(entry: str, *argv: str) -> str:
    probe = _GC_PROBE.format(entry=entry)
    out = subprocess.run([sys.executable, "-c", probe, "-", *argv], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


def test_the_console_script_pauses_the_garbage_collector_until_the_model_is_loaded():
    # paused while sympy and the model load, collecting again afterwards with the
    # start-up's objects frozen; a failing command ends with the collector running too
    assert _gc_states("run", "ports", "wave", "--json") == "[False] True True 0"
    assert _gc_states("run", "ports", "no-such-model") == "[False] True True 2"
    assert _gc_states("run", "models") == "[] True True 0"  # resumed when the run ends


def test_the_library_entry_point_never_pauses_the_garbage_collector():
    assert _gc_states("main", "ports", "wave", "--json") == "[True] True False 0"
