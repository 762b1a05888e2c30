"""Every Python example of the documentation runs as written.

The examples whose numbers are checked have tests of their own, which run them:
``test_readme.py`` (the README's example, the same statements as the getting-started
page's first block), ``design/test_design_readme.py`` (the noise, trade-off, export and
loop block) and ``test_readme.py`` again (the model written in code).  The others run
here, each page's blocks in order in one namespace, as a reader would.
"""

from __future__ import annotations

import ast

import pytest
from doc_blocks import DOCS, README, python_blocks

PAGES = sorted(p for p in DOCS.glob("*.*") if p.suffix in (".rst", ".md") and python_blocks(p))


def _statements(code: str) -> str:
    return ast.dump(ast.parse(code))


CHECKED_ELSEWHERE = {_statements(python_blocks(README)[0])}


def test_the_getting_started_example_is_the_readme_example():
    first = python_blocks(DOCS / "getting_started.rst")[0]
    assert _statements(first) in CHECKED_ELSEWHERE


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_example_of_a_page_runs(page):
    import phdesign as phd

    namespace: dict[str, object] = {"phd": phd, "phdesign": phd}
    ran = 0
    for block in python_blocks(page):
        if _statements(block) in CHECKED_ELSEWHERE or "obs.noise()" in block:
            continue  # run, with their numbers checked, by the tests named above
        exec(compile(block, str(page), "exec"), namespace)  # our own documentation
        ran += 1
    assert ran or page.name == "getting_started.rst"
