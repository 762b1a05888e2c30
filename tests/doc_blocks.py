"""The Python examples of the README and of the documentation's pages, as they are written."""

from __future__ import annotations

import re
import textwrap
from pathlib import Path

from paths import ROOT

README = ROOT / "README.md"
DOCS = ROOT / "docs"


def python_blocks(path: Path) -> list[str]:
    """The ``python`` code blocks of a Markdown or reStructuredText page, in order."""
    text = path.read_text(encoding="utf-8")
    if path.suffix == ".md":
        return re.findall(r"```python\n(.*?)```", text, flags=re.S)
    blocks = re.findall(r"\.\. code-block:: python\n\n((?:(?:   .*)?\n)+)", text)
    return [textwrap.dedent(block).strip() + "\n" for block in blocks]
