"""No module over 500 lines, no function over 60 lines of code (the docstring aside).

Lines of code are the non-blank lines of a function that are neither comments nor its
docstring: a long function becomes named stages, a long module a folder or modules by idea.
"""

from __future__ import annotations

import ast

from paths import ROOT

PACKAGE = ROOT / "phdesign"
MAX_MODULE_LINES = 500
MAX_FUNCTION_CODE = 60


def code_lines(node: ast.FunctionDef | ast.AsyncFunctionDef, lines: list[str]) -> int:
    """Non-blank, non-comment lines of ``node`` outside its docstring."""
    body = node.body
    doc: set[int] = set()
    first = body[0] if body else None
    if isinstance(first, ast.Expr) and isinstance(getattr(first.value, "value", None), str):
        doc = set(range(first.lineno, (first.end_lineno or first.lineno) + 1))
    end = node.end_lineno or node.lineno
    return sum(
        1
        for i in range(node.lineno, end + 1)
        if i not in doc and lines[i - 1].strip() and not lines[i - 1].strip().startswith("#")
    )


def test_no_module_is_over_500_lines():
    long = {
        str(p.relative_to(ROOT)): n
        for p in PACKAGE.rglob("*.py")
        if (n := p.read_text(encoding="utf-8").count("\n")) > MAX_MODULE_LINES
    }
    assert not long, long


def test_no_function_is_over_60_lines_of_code():
    long = {}
    for p in PACKAGE.rglob("*.py"):
        text = p.read_text(encoding="utf-8")
        lines = text.splitlines()
        for node in ast.walk(ast.parse(text)):
            is_function = isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
            if is_function and (n := code_lines(node, lines)) > MAX_FUNCTION_CODE:
                long[f"{p.relative_to(ROOT)}:{node.lineno} {node.name}"] = n
    assert not long, long


def test_the_count_skips_docstrings_comments_and_blank_lines():
    source = 'def f():\n    """Doc.\n\n    More.\n    """\n    # why\n\n    return 1\n'
    (node,) = ast.parse(source).body
    assert isinstance(node, ast.FunctionDef)
    assert code_lines(node, source.splitlines()) == 2  # the def line and the return
