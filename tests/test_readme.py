"""The README's Python examples run as written, and its first commands name real commands."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)


def test_readme_examples_run(capsys):
    namespace: dict[str, object] = {}
    for block in python_blocks():
        exec(compile(block, str(README), "exec"), namespace)  # our own README, not user input
    printed = capsys.readouterr().out.split("\n")
    # paper §IV-D corrected: κ* = min(l2, l1/(1 + l1²)); abscissa from the spectrum tests
    assert printed[0] == "exponential Min(l2, l1/(l1**2 + 1))"
    assert abs(float(printed[1].split()[0]) - (-2.9106562986)) < 1e-8
    assert printed[1].split()[1] == "True"
    assert abs(float(printed[2]) - 0.92) < 0.01
    assert type(namespace["error_system"]).__name__ == "StateSpace"


def test_readme_starts_with_install_and_test_commands():
    text = README.read_text(encoding="utf-8")
    first_block = re.search(r"```bash\n(.*?)```", text, flags=re.S).group(1).splitlines()
    assert first_block[0].startswith("pip install -e . && phdesign classify euler-bernoulli")
    assert "python -m pytest" in first_block[1]
