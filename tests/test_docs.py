"""The documentation's generated pages are valid reStructuredText and say what they must.

The Sphinx build itself (``python -m sphinx -W``) runs in CI after the tests; these checks
are the fast part: the command-line reference covers every command and option, and every
notebook converts without a docutils warning (a warning fails the ``-W`` build).
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
sys.path.insert(0, str(DOCS / "_ext"))

docutils_core = pytest.importorskip("docutils.core", reason="install the docs extra")
phdesign_docs = pytest.importorskip("phdesign_docs")


def parse(text: str) -> object:
    # halt on warnings: what Sphinx -W would refuse
    return docutils_core.publish_doctree(
        text, settings_overrides={"report_level": 2, "halt_level": 2, "warning_stream": False}
    )


def test_cli_reference_lists_every_command_and_option():
    from phdesign.cli import build_parser

    page = phdesign_docs.cli_page()
    parse(page)
    for command in ("models", "show", "ports", "classify", "spectrum", "simulate", "tune"):
        assert f"phdesign {command}\n" in page
    for option in ("``--gain L``", "``--t-end T``", "``--all-sensors``", "``--starts STARTS``"):
        assert option in page
    assert "final time; default: 5.0" in page  # defaults are stated
    assert "DESIGN.md" not in page
    assert build_parser().prog == "phdesign"


def test_markdown_conversion_of_the_constructs_the_notebooks_use():
    text = (
        "# Title\n\nSome $x_1$ and `code`, |λ| and a [link](https://example.org).\n"
        "A list:\n- one $a$\n- two\n\n$$\nE = mc^2\n$$\n\n| a | b |\n|---|---|\n| 1 | 2 |"
    )
    rst = phdesign_docs.markdown_to_rst(text)
    tree = parse(rst)
    assert "Title\n=====" in rst
    assert ":math:`x_1`" in rst
    assert "``code``" in rst
    assert "\\|λ\\|" in rst
    assert ".. math::" in rst
    assert ".. list-table::" in rst
    assert tree.astext().count("one") == 1


@pytest.mark.parametrize("path", sorted((DOCS.parent / "notebooks").glob("[0-9][0-9]_*.py")))
def test_every_notebook_becomes_a_valid_page(path):
    page = phdesign_docs.notebook_page(path)
    parse(page)
    code = [c for kind, c in phdesign_docs.notebook_cells(path.read_text()) if kind == "code"]
    assert code
    assert all(line in page for line in code[0].splitlines() if line.strip())


def _flat(text: str) -> str:
    return " ".join(text.split())


def test_cli_reference_is_each_commands_help_nested_commands_included(monkeypatch):
    # issue 28: the page showed "(default %(default)g)" and "'5%%'" and no loop subcommands.
    # Each option's text must be what ``--help`` prints; on a terminal as wide as the text
    # argparse does not wrap (it would break "--min-decay" after its hyphen)
    import argparse

    monkeypatch.setenv("COLUMNS", "100000")

    from phdesign.cli import build_parser

    page = phdesign_docs.cli_page()
    assert "%(" not in page
    assert "%%" not in page
    found = phdesign_docs.commands(build_parser())
    names = [name for name, _, _ in found]
    for nested in ("classify", "spectrum", "simulate", "tune"):
        assert f"phdesign loop {nested}" in names
    for name, parser, _ in found:
        assert f"\n{name}\n{'-' * len(name)}\n" in page
        printed = _flat(parser.format_help())
        for action in parser._actions:
            if isinstance(action, argparse._HelpAction) or not action.help:
                continue
            text = parser._get_formatter()._expand_help(action)
            assert _flat(text) in printed, (name, action.dest)
            assert phdesign_docs._escape(phdesign_docs.option_help(parser, action)) in page


def test_the_site_keeps_double_dashes_as_typed():
    # docutils' smart quotes turn "--gain" in prose into an en dash, which fails when copied
    import importlib.util

    spec = importlib.util.spec_from_file_location("conf", DOCS / "conf.py")
    conf = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(conf)
    assert conf.smartquotes is False
