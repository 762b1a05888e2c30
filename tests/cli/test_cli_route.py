"""One route: the command line asks the design objects, never the numeric layer itself."""

from __future__ import annotations

import ast

from paths import ROOT


def _imports(path):
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module:
            yield node.lineno, node.module
        elif isinstance(node, ast.Import):
            yield from ((node.lineno, alias.name) for alias in node.names)


def test_no_command_imports_the_numeric_layer():
    # spectrum, simulate, tune, noise, tradeoff, export and loop go through Plant, Observer
    # and Loop, so the library and the command line are one route
    found = [
        f"{path.relative_to(ROOT)}:{line}: {module}"
        for path in sorted((ROOT / "phdesign" / "cli").glob("*.py"))
        for line, module in _imports(path)
        if module == "phdesign.numeric" or module.startswith("phdesign.numeric.")
    ]
    assert not found, "\n".join(found)


def test_the_scan_sees_an_import_inside_a_function(tmp_path):
    module = tmp_path / "m.py"
    module.write_text("def f():\n    from phdesign.numeric.bridge import to_numeric\n")
    assert list(_imports(module)) == [(2, "phdesign.numeric.bridge")]
