"""Every figure is drawn in phdesign/plots: one place makes the axes, titles and files."""

from __future__ import annotations

import ast

import numpy as np
import pytest
from paths import ROOT

from phdesign import plots
from phdesign.core.errors import OutputFileError


def _drawing_sites(path):
    """Lines of a module that import matplotlib or write a figure (``.savefig``)."""
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Import | ast.ImportFrom):
            names = [node.module or ""] if isinstance(node, ast.ImportFrom) else []
            names += [a.name for a in node.names] if isinstance(node, ast.Import) else []
            if any(n.startswith("matplotlib") for n in names):
                yield node.lineno, "imports matplotlib"
        elif isinstance(node, ast.Attribute) and node.attr == "savefig":
            yield node.lineno, "writes a figure"


def _type_checking_lines(path):
    tree = ast.parse(path.read_text())
    lines = set()
    for node in tree.body:
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            lines.update(range(node.lineno, node.end_lineno + 1))
    return lines


def test_no_module_outside_plots_draws():
    # TYPE_CHECKING imports of matplotlib's classes are annotations, not drawing
    package = ROOT / "phdesign"
    found = []
    for path in sorted(package.rglob("*.py")):
        if path.relative_to(package).parts[0] == "plots":
            continue
        typing_only = _type_checking_lines(path)
        found += [
            f"{path.relative_to(ROOT)}:{line}: {what}"
            for line, what in _drawing_sites(path)
            if line not in typing_only
        ]
    assert not found, "\n".join(found)


def test_savefig_is_called_in_one_place():
    sites = [
        f"{path.name}:{line}"
        for path in sorted((ROOT / "phdesign" / "plots").rglob("*.py"))
        for line, what in _drawing_sites(path)
        if what == "writes a figure"
    ]
    assert len(sites) == 1, sites
    assert sites[0].startswith("_figures.py:"), sites


def test_drawing_checks_the_path_first_and_titles_literally(tmp_path):
    taken = tmp_path / "taken.png"
    taken.write_bytes(b"mine")
    drawn = []
    with pytest.raises(OutputFileError, match="exists"), plots.drawing(taken) as (_, ax):
        drawn.append(ax)  # never reached: nothing is drawn for a path that is refused
    assert drawn == []
    assert taken.read_bytes() == b"mine"
    path = tmp_path / "new.svg"
    with plots.drawing(path, title="$\\frac{1}{$ beam") as (fig, ax):
        ax.plot(np.arange(3), np.arange(3))
    assert fig.get_suptitle() == "\\$\\frac{1}{\\$ beam"  # drawable: never mathtext
    assert path.read_text().lstrip().startswith("<?xml")
