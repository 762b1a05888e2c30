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


def test_the_gallery_has_a_card_for_every_notebook_picked_up_by_name(tmp_path):
    """Notebooks 08 and 09 will appear without an edit: the list is ``notebooks/NN_*.py``."""
    import notebook_cache

    for name in ("01_first.py", "09_later.py", "README.md", "helper.py"):
        (tmp_path / name).write_text("# %%\n")
    assert [p.name for p in notebook_cache.notebook_paths(tmp_path)] == [
        "01_first.py",
        "09_later.py",
    ]
    names = [p.stem for p in notebook_cache.notebook_paths()]
    page = phdesign_docs.gallery_page([(name, name != names[0]) for name in names])
    body = page.split(".. toctree::")[0].replace(":doc:", ":code:")
    parse(body)  # valid rst; docutils alone knows no :doc: role and no toctree
    for name in names:
        assert f":doc:`notebooks/{name}`" in page
        assert f"   notebooks/{name}\n" in page  # in the (hidden) toctree
    assert f"gallery/{names[0]}.png" not in page  # no figure: a link, no thumbnail
    assert f".. figure:: gallery/{names[1]}.png" in page


@pytest.mark.parametrize("path", sorted((DOCS.parent / "notebooks").glob("[0-9][0-9]_*.py")))
def test_the_page_source_of_a_notebook_hashes_as_the_execution_the_tests_store(path):
    """myst-nb looks the page's notebook up in jupyter-cache by this hash: equal, no rerun."""
    nbformat = pytest.importorskip("nbformat", reason="install the notebooks extra")
    pytest.importorskip("jupytext", reason="install the notebooks extra")
    cache_main = pytest.importorskip("jupyter_cache.cache.main", reason="install the docs extra")
    import notebook_cache

    stored = notebook_cache.read(path)  # what tests/test_notebooks.py executes and stores
    page = nbformat.reads(nbformat.writes(stored), as_version=4)  # what myst-nb reads
    cache = cache_main.JupyterCacheBase(str(DOCS / "_build" / "unused-cache"))
    assert cache.create_hashed_notebook(page)[1] == cache.create_hashed_notebook(stored)[1]
    assert stored.metadata["kernelspec"]["name"] == notebook_cache.KERNEL


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
