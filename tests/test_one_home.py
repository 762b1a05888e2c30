"""Ideas that were written several times have one home each (issue 23)."""

from __future__ import annotations

import ast

import pytest
from paths import ROOT

PACKAGE = ROOT / "phdesign"

#: Lists of choices, each written at most once (core/checks.py today; the discretization
#: methods may come from their registry instead); everyone else reads the one list.
CHOICES = {
    ("galerkin", "fd"): "DISCRETIZATION_METHODS",
    ("average", "point"): "SAMPLERS",
    ("none", "modal", "balanced"): "REDUCTIONS",
    ("json", "c", "npz", "statespace"): "EXPORT_FORMATS",
}


def _modules():
    return sorted(PACKAGE.rglob("*.py"))


def _literal_tuples(path):
    """The tuples of string constants written in a module (not in docstrings)."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Tuple | ast.List) and node.elts:
            values = [e.value for e in node.elts if isinstance(e, ast.Constant)]
            if len(values) == len(node.elts) and all(isinstance(v, str) for v in values):
                yield node.lineno, tuple(values)


@pytest.mark.parametrize("choices", sorted(CHOICES))
def test_a_list_of_choices_is_written_once(choices):
    written = [
        f"{path.relative_to(ROOT)}:{line}"
        for path in _modules()
        for line, values in _literal_tuples(path)
        if values == choices
    ]
    assert len(written) <= 1, written


def test_html_tables_come_from_one_builder():
    # core.text.html_table escapes every cell; a table written by hand forgot to
    written = [
        f"{path.relative_to(ROOT)}"
        for path in _modules()
        if "<table" in path.read_text() and path.name != "text.py"
    ]
    assert not written, written


def test_the_scan_sees_a_tuple_of_choices(tmp_path):
    module = tmp_path / "m.py"
    module.write_text('METHODS = ("galerkin", "fd")\nX = ("galerkin", 1)\n')
    assert [values for _, values in _literal_tuples(module)] == [("galerkin", "fd")]
