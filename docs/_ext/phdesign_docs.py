"""Sphinx extension of phdesign's documentation: pages generated at build time.

* ``_generated/cli.rst``: the command-line reference, read from the argument parser
  itself (``phdesign.cli.build_parser``), so that it never disagrees with ``--help``.
* ``_generated/notebooks/*.rst``: each design notebook (``notebooks/*.py``, jupytext
  percent format) as a page: its narrative (Markdown, converted here: headings,
  paragraphs, lists, inline and display math, code, emphasis, links) and its code cells.
  The notebooks are executed by the test suite, not by the documentation build, so the
  build stays offline and fast.

Both are written when the builder starts (``builder-inited``) and are not committed.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
DOCS = HERE.parent
ROOT = DOCS.parent
GENERATED = DOCS / "_generated"

#: Underline characters of rst section levels, outermost first.
LEVELS = "=-~^"


# --------------------------------------------------------------------------- CLI
#: The keys of each command's ``--json`` output (keys may be added, never renamed).
JSON_KEYS = {
    "models": "a list of ``{name, order, size, description}``, one per built-in model",
    "show": "the model file's content as JSON (``name``, ``interval``, ``order``, "
    "``matrices``, ``ports``, ...), exact values as strings",
    "ports": "``model``, ``order``, ``size``, ``traces`` (the trace vector v), ``Q``, ``W_B``, "
    "``W_C`` (rows of exact sympy strings) and ``identities``: the largest residual of "
    "``WB_Sigma_WBt``, ``WC_Sigma_WCt`` and ``WC_Sigma_WBt_minus_I``",
    "classify": "``model``, ``order``, ``size``, ``sensors`` (C_m rows), ``gain`` (L rows), "
    "``gain_exact``, ``partitioned``, ``partitions``, ``results`` (one per variant: "
    "``proposition``, ``variant``, ``applicable``, ``holds``, ``kappa``, ``kappa_exact``, "
    "``unbounded``, ``rhs``, ``reason``, ``path``, and ``conditions``, ``partition``, "
    "``witness``, ``free`` where they apply), ``verdict`` and ``best``.  ``kappa`` is null "
    "only when the variant does not apply or κ* is unbounded, 0 for a failing variant, a "
    "number for numeric gains and the exact expression for symbolic gains.  With "
    "``--all-sensors``: ``model``, ``order``, ``size``, ``gain``, ``decision_path``, "
    "``kappa_path``, ``required`` (the sensors each variant needs), ``subsets`` "
    "(``sensors``, ``verdict``, ``best``, ``kappa``, ``unbounded``, ``holding``) and "
    "``minimal`` (the minimal sets of each verdict)",
    "spectrum": "``model``, ``spectral_abscissa`` (null when unbounded below), ``rightmost`` "
    "(``[re, im]`` pairs), ``converged``, ``digits``, ``n_resolved``, ``n_total``, "
    "``resolutions``, ``unbounded_below``, ``ill_conditioned``, ``condition_numbers``, "
    "``warnings`` and the refinement ``history``",
    "simulate": "``model``, ``method``, ``resolution``, the time series ``t``, ``H``, "
    "``H_hat``, ``H_err``, ``y``, ``y_hat`` (with ``output_labels``), the displacement "
    "``z_w``, ``w``, ``w_hat`` for models that have one, the run's details (``scheme``, "
    "``states``, the energy-balance residuals, ``sensors``, ``gain``) and ``warnings``",
    "tune": "``model``, ``gain`` (L rows), ``spectral_abscissa``, ``converged``, "
    "``at_coalescence``, ``active``, ``rightmost``, ``digits``, ``resolutions``, "
    "``starts`` (every start with its local optimum) and ``warnings``",
}


def _option_row(parser: argparse.ArgumentParser, action: argparse.Action) -> tuple[str, str]:
    names = ", ".join(action.option_strings) or action.metavar or action.dest
    if action.option_strings and action.nargs != 0:
        metavar = action.metavar or action.dest.upper()
        names = ", ".join(f"{name} {metavar}" for name in action.option_strings)
    return names, option_help(parser, action)


def option_help(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    """Return an option's help as ``--help`` prints it, then its choices.

    ``%(default)g`` and ``%%`` are expanded by argparse's own formatter.
    """
    if not action.help or action.help == argparse.SUPPRESS:
        text = ""
    else:
        text = parser._get_formatter()._expand_help(action)
    if action.choices and not isinstance(action, argparse._SubParsersAction):
        text += f" (one of: {', '.join(map(str, action.choices))})"
    return text


def commands(
    parser: argparse.ArgumentParser, prefix: str = "phdesign"
) -> list[tuple[str, argparse.ArgumentParser, str]]:
    """Return every command, nested ones too (``phdesign loop classify``), in help order.

    Each as ``(name, parser, one-line help)``.
    """
    found = []
    for action in parser._actions:
        if not isinstance(action, argparse._SubParsersAction):
            continue
        helps = {a.dest: a.help for a in action._choices_actions}
        for name, sub in action.choices.items():
            sub.complete()  # the options a command adds when it is first used (sweep's jobs)
            found.append((f"{prefix} {name}", sub, helps.get(name) or ""))
            found += commands(sub, f"{prefix} {name}")
    return found


def _escape(text: str) -> str:
    return text.replace("\\", "\\\\").replace("*", "\\*").replace("|", "\\|").replace("`", "\\`")


def cli_page() -> str:
    """Return the command-line reference as reStructuredText."""
    from phdesign.cli import build_parser

    parser = build_parser()
    lines = [
        "Command-line reference",
        "=" * 22,
        "",
        "Generated from the argument parser of ``phdesign`` (the same text as",
        "``phdesign COMMAND --help``).  Every command exits with status 2 and one line on",
        "standard error on bad input.  A negative value may be written as it is",
        "(``--gain -1,1``) or glued to its option (``--gain=-1,1``).",
        "",
        ".. code:: text",
        "",
        *("   " + line for line in parser.format_usage().splitlines()),
        "",
    ]
    for title, sub, summary in commands(parser):
        lines += [title, "-" * len(title), ""]
        lines += [_escape(sub.description or summary), ""]
        lines += [".. code:: text", ""]
        lines += ["   " + line for line in sub.format_usage().removeprefix("usage: ").splitlines()]
        lines += ["", ".. list-table::", "   :widths: 30 70", ""]
        for action in sub._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            option, text = _option_row(sub, action)
            lines += [f"   * - ``{option}``", f"     - {_escape(text) or ' '}"]
        lines.append("")
        name = title.removeprefix("phdesign ")
        if name in JSON_KEYS:
            lines += [f"*JSON* (``--json``): {JSON_KEYS[name]}.", ""]
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- notebooks
def notebook_cells(text: str) -> list[tuple[str, str]]:
    """Split a jupytext percent script into ``(kind, source)`` cells (header dropped)."""
    lines = text.splitlines()
    if lines and lines[0].startswith("# ---"):
        end = next(i for i in range(1, len(lines)) if lines[i].startswith("# ---"))
        lines = lines[end + 1 :]
    cells: list[tuple[str, list[str]]] = []
    for line in lines:
        if line.startswith("# %%"):
            cells.append(("markdown" if "[markdown]" in line else "code", []))
        elif cells:
            cells[-1][1].append(line)
    out = []
    for kind, body in cells:
        if kind == "markdown":
            body = [re.sub(r"^# ?", "", line) for line in body]
        source = "\n".join(body).strip("\n")
        if source.strip():
            out.append((kind, source))
    return out


def _inline(text: str) -> str:
    """Markdown inline markup to rst: math, code, links, emphasis; rst specials escaped."""
    pieces: list[str] = []
    pattern = re.compile(
        r"\$(?P<math>[^$]+)\$|`(?P<code>[^`]+)`|\[(?P<text>[^\]]+)\]\((?P<url>[^)]+)\)"
    )
    position = 0
    for match in pattern.finditer(text):
        pieces.append(_plain(text[position : match.start()]))
        if match["math"] is not None:
            pieces.append(f"\\ :math:`{' '.join(match['math'].split())}`\\ ")
        elif match["code"] is not None:
            pieces.append(f"\\ ``{match['code']}``\\ ")
        else:
            pieces.append(f"\\ `{match['text']} <{match['url']}>`__\\ ")
        position = match.end()
    pieces.append(_plain(text[position:]))
    return "".join(pieces)


def _plain(text: str) -> str:
    text = text.replace("\\", "\\\\").replace("|", "\\|")
    text = re.sub(r"(?<![\w*])_(\S[^_]*?)_(?!\w)", r"*\1*", text)  # _emphasis_
    return re.sub(r"(\w)_(?=\s|$)", r"\1\\_", text)  # a trailing _ is not a reference


def _table(rows: list[str]) -> list[str]:
    cells = [[c.strip() for c in row.strip().strip("|").split("|")] for row in rows]
    cells = [r for r in cells if not all(re.fullmatch(r":?-+:?", c) for c in r)]
    out = [".. list-table::", "   :header-rows: 1", ""]
    for row in cells:
        out.append(f"   * - {_inline(row[0]) or ' '}")
        out += [f"     - {_inline(c) or ' '}" for c in row[1:]]
    return [*out, ""]


def markdown_to_rst(text: str) -> str:
    """Convert the Markdown of a notebook's narrative cell to reStructuredText."""
    out: list[str] = []
    blocks = re.split(r"\n\s*\n", text)
    for block in blocks:
        lines = block.split("\n")
        if block.strip().startswith("$$"):
            body = block.strip().strip("$").strip()
            out += [".. math::", "", *("   " + line for line in body.split("\n")), ""]
            continue
        if all(line.strip().startswith("|") for line in lines if line.strip()):
            out += _table([line for line in lines if line.strip()])
            continue
        heading = re.match(r"(#+)\s+(.*)", lines[0])
        if heading and len(lines) == 1:
            title = _inline(heading[2]).strip()
            level = min(len(heading[1]), len(LEVELS)) - 1
            out += [title, LEVELS[level] * max(len(title), 3), ""]
            continue
        paragraph: list[str] = []
        in_list = False
        for line in lines:
            item = re.match(r"(\s*)([-*]|\d+\.)\s+(.*)", line)
            if item:
                if paragraph:
                    out += [_inline("\n".join(paragraph)), ""]
                    paragraph = []
                out.append(f"{item[1]}{'-' if item[2] in '-*' else item[2]} {_inline(item[3])}")
                in_list = True
            elif in_list and line.startswith((" ", "\t")):
                out.append("  " + _inline(line.strip()))
            else:
                if in_list:
                    out.append("")
                    in_list = False
                paragraph.append(line)
        if paragraph:
            out.append(_inline("\n".join(paragraph)))
        out.append("")
    return "\n".join(out)


def notebook_page(path: Path) -> str:
    """Return a notebook as an rst page: the narrative converted, the code as code blocks."""
    lines = [f".. Generated from notebooks/{path.name}; edit the notebook, not this page.", ""]
    titled = False
    for kind, source in notebook_cells(path.read_text(encoding="utf-8")):
        if kind == "markdown":
            text = markdown_to_rst(source)
            titled = titled or bool(re.match(r"#\s", source))
            lines.append(text)
        else:
            lines += [
                ".. code:: python",
                "",
                *("   " + line for line in source.split("\n")),
                "",
            ]
    if not titled:
        lines[2:2] = [path.stem, "=" * len(path.stem), ""]
    lines += [
        "",
        f"*Run it:* ``jupytext --to notebook --execute notebooks/{path.name}``, or as a script,",
        f"``python notebooks/{path.name}``.",
        "",
    ]
    return "\n".join(lines)


# --------------------------------------------------------------------------- sphinx
def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


def generate(app: Any = None) -> None:
    """Write the generated pages (unchanged files are left alone: no needless rebuilds)."""
    _write(GENERATED / "cli.rst", cli_page())
    notebooks = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.py"))
    names = []
    for path in notebooks:
        _write(GENERATED / "notebooks" / f"{path.stem}.rst", notebook_page(path))
        names.append(path.stem)
    index = [
        "Notebooks",
        "=========",
        "",
        "The design notebooks, as pages: their narrative and code.  They are jupytext",
        "scripts in ``notebooks/``, executed by the test suite (``tests/test_notebooks.py``);",
        "``notebooks/README.md`` says how to open and run them.",
        "",
        ".. toctree::",
        "   :maxdepth: 1",
        "",
        *(f"   notebooks/{name}" for name in names),
        "",
    ]
    _write(GENERATED / "notebooks.rst", "\n".join(index))


def setup(app: Any) -> dict[str, Any]:
    """Register the page generation with Sphinx."""
    app.connect("builder-inited", generate)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
