"""The README's Python examples run as written, and its first commands name real commands.

The first block is the API of issue 11, line by line as a notebook runs it: every
expression's value is kept and checked against numbers that do not come from the code
under test (the paper's corrected §IV-D constant, the spectrum tests' converged abscissa).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest
import sympy
from doc_blocks import python_blocks as doc_python_blocks

README = Path(__file__).resolve().parents[1] / "README.md"
DOCS = README.parent / "docs"


def python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)


def run_like_a_notebook(code: str, namespace: dict) -> list[object]:
    """Execute ``code`` statement by statement; return the value of each expression line."""
    values = []
    for statement in ast.parse(code).body:
        if isinstance(statement, ast.Expr):
            expression = ast.Expression(statement.value)
            values.append(eval(compile(expression, str(README), "eval"), namespace))
        else:
            module = ast.Module([statement], type_ignores=[])
            exec(compile(module, str(README), "exec"), namespace)  # our own README
    return values


@pytest.mark.slow  # obs.tune() is a global search (6 starts)
def test_readme_api_block_runs_and_its_numbers_hold():
    import control

    namespace: dict[str, object] = {}
    values = run_like_a_notebook(python_blocks()[0], namespace)
    classification, report, run, tuned, error_system, search = values
    # paper §IV-D corrected: 3.4 variant 3 holds with κ* = min(l2, l1/(1 + l1²)) = 10/101
    assert classification.verdict == "exponential"
    assert classification.result("3.4", 3).kappa == sympy.Rational(10, 101)
    # converged abscissa of the error system (tests/numeric/spectrum/test_numeric_spectrum.py, 13
    # digits)
    assert report.converged
    assert abs(report.spectral_abscissa - (-2.9106562986)) < 1e-8
    # H̃/H̃(0) < 1e-2 after about 0.92 s (the README states it; 2-digit claim)
    assert abs(run.time_below(1e-2) - 0.92) < 0.01
    # tune returns a new observer with the report; the tuned abscissa beats design 2's
    assert type(tuned).__name__ == "Observer"
    assert tuned is not namespace["obs"]
    assert tuned.tuning is not None
    assert tuned.tuning.spectral_abscissa < report.spectral_abscissa - 1.0
    assert sympy.diag(sympy.Rational(1, 10), 1) == namespace["obs"].L  # unchanged
    assert isinstance(error_system, control.StateSpace)
    # the minimal exponential sensor sets of the beam (derived in tests/symbolic/test_search.py)
    assert search.minimal["exponential"] == ((2,), (4,))
    for value in (classification, run, tuned, search):
        assert len(repr(value)) <= 300, type(value).__name__
        assert callable(getattr(value, "_repr_html_", None)), type(value).__name__
    RESULTS.update(report=report, tuning=tuned.tuning)


RESULTS: dict[str, object] = {}


@pytest.mark.slow
def test_readme_spectrum_and_tuning_reports_print_themselves():
    if not RESULTS:
        pytest.skip("runs after test_readme_api_block_runs_and_its_numbers_hold")
    for value in RESULTS.values():
        assert len(repr(value)) <= 300, type(value).__name__
        assert callable(getattr(value, "_repr_html_", None)), type(value).__name__


def test_the_model_in_code_is_the_builtin_beam():
    # the getting-started page's second block (the README points to it)
    import phdesign

    (block,) = [b for b in doc_python_blocks(DOCS / "getting_started.rst") if "define(" in b]
    namespace: dict[str, object] = {"phd": phdesign}
    exec(compile(block, "getting_started.rst", "exec"), namespace)  # our own docs
    beam = namespace["beam"]
    builtin = __import__("phdesign").load("euler-bernoulli")
    assert (beam.P, beam.H, beam.inputs, beam.outputs) == (
        builtin.P,
        builtin.H,
        builtin.inputs,
        builtin.outputs,
    )


def test_readme_starts_with_install_and_test_commands():
    text = README.read_text(encoding="utf-8")
    first_block = re.search(r"```bash\n(.*?)```", text, flags=re.S).group(1).splitlines()
    assert first_block[0].startswith("pip install -e . && phdesign classify euler-bernoulli")
    assert "python -m pytest" in first_block[1]
    assert "python -m sphinx -W" in first_block[1]
    # the README points at no design notes outside the repository
    assert "DESIGN.md" not in text
    assert "steering" not in text


def test_getting_started_installs_what_the_readme_installs():
    # issue 28: the getting-started page gave fewer extras than the README's test command
    readme = re.search(r"```bash\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)
    page = (DOCS / "getting_started.rst").read_text(encoding="utf-8")
    block = re.search(r"\.\. code-block:: bash\n\n(.*?)\n\n", page, flags=re.S)
    commands = [line.strip() for line in block.group(1).splitlines()]
    assert commands == readme.group(1).strip().splitlines()


def test_readme_is_a_front_page_whose_links_exist():
    # the structure issue: at most 6000 characters (python-control's is 4.9k, py-pde's 4.0k);
    # the manual lives in docs/, and every page the README links to exists
    text = README.read_text(encoding="utf-8")
    assert len(text) <= 6000, len(text)
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text)
    assert links
    for link in links:
        assert (README.parent / link).exists(), link
