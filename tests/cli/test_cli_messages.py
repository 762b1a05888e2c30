"""Library messages name arguments; the command line prints them with its option names."""

from __future__ import annotations

import ast
import re

import pytest
from paths import ROOT

import phdesign as phd
from phdesign.cli import main
from phdesign.cli.messages import with_options
from phdesign.core.errors import NumericError

#: A command-line flag: two dashes and a letter (``--reduce``, ``--force``).
FLAG = re.compile(r"--[A-Za-z]")


def _message_strings(path):
    """The string constants of a module that are not docstrings (messages, warnings, notes)."""
    tree = ast.parse(path.read_text())
    docstrings = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef) and body:
            first = body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                docstrings.add(id(first.value))
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Constant)
            and isinstance(node.value, str)
            and id(node) not in docstrings
        ):
            yield node.lineno, node.value


def test_no_library_message_names_a_command_line_flag():
    package = ROOT / "phdesign"
    found = [
        f"{path.relative_to(ROOT)}:{line}: {text[:80]!r}"
        for path in sorted(package.rglob("*.py"))
        if path.relative_to(package).parts[0] != "cli"
        for line, text in _message_strings(path)
        if FLAG.search(text)
    ]
    assert not found, "\n".join(found)


def test_the_scan_finds_a_flag_in_a_message_not_in_a_docstring(tmp_path):
    module = tmp_path / "m.py"
    module.write_text(
        '"""``phdesign simulate --plot``."""\n'
        "def f():\n"
        '    """Draw (``--plot``)."""\n'
        '    raise ValueError("a -- b; " f"use --reduce {1}")\n'
    )
    flagged = [text for _, text in _message_strings(module) if FLAG.search(text)]
    assert flagged == ["a -- b; use --reduce "]  # the f-string's text, not the docstrings


def test_the_library_names_the_argument_and_the_cli_the_flag(capsys, tmp_path):
    observer = phd.Observer(phd.load("wave"), sensors=[2], gain=1)
    with pytest.raises(NumericError, match=r"use `reduction='none'` or `reduction='balanced'`"):
        observer.export(dt=1e-3, order=12, reduction="modal")
    argv = ["export", "wave", "--sensors", "2", "--gain", "1", "--dt", "1e-3", "--order", "12"]
    argv += ["--reduce", "modal", "--format", "json", "-o", str(tmp_path / "o.json")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.endswith("use --reduce none or --reduce balanced\n"), err


def test_an_argument_is_named_as_the_running_command_spells_it(capsys):
    # at the head of a library message (t_end must ...) and as code (`u`: ...)
    assert main(["simulate", "wave", "--sensors", "2", "--t-end", "1.7e308"]) == 2
    assert "error: --t-end must be a positive number at most" in capsys.readouterr().err
    assert main(["simulate", "wave", "--u", "u9: t"]) == 2
    assert "error: --u: unknown input 'u9'" in capsys.readouterr().err
    options = {"noise_intensity": "--noise-intensity", "force": "--force"}
    assert with_options("`noise_intensity`: 2 values", options) == "--noise-intensity: 2 values"
    assert with_options("pass `force=True`", options) == "pass --force"
    # a model file's errors name its keys: order is no --order there
    assert with_options("order must be an integer", {"order": "--order"}, leading=False) == (
        "order must be an integer"
    )
    assert with_options("order must be an integer", {"order": "--order"}) == (
        "--order must be an integer"
    )
