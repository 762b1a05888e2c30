"""Sphinx extension of phdesign's documentation: pages generated at build time.

* ``_generated/cli.rst``: the command-line reference, read from the argument parser
  itself (``phdesign.cli.build_parser``), so that it never disagrees with ``--help``.
* ``_generated/notebooks/NN_*.ipynb``: each design notebook (every ``notebooks/NN_*.py``,
  jupytext percent format, picked up by name), which myst-nb renders executed, with its
  figures.  Each is executed once for the tests and the site (``notebook_cache.py``): the
  build executes only what the tests have not stored.
* ``_generated/gallery.rst`` with ``_generated/gallery/NN_*.png``: the gallery, one card
  per notebook (its first figure, linked to its page, and its title).

They are written when the builder starts (``builder-inited``) for the site's own sources
(a page built elsewhere with this conf.py, as tests/test_docs_offline.py does, gets none),
and are not committed.
"""

from __future__ import annotations

import argparse
import base64
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


# --------------------------------------------------------------------------- gallery
def first_figure(notebook: Any) -> bytes | None:
    """Return the first PNG an executed notebook displays, or None."""
    for cell in notebook.cells:
        for output in cell.get("outputs", []):
            png = output.get("data", {}).get("image/png")
            if png:
                return base64.b64decode(png)
    return None


def gallery_page(cards: list[tuple[str, bool]]) -> str:
    """Return the gallery: a card per notebook, ``(name, whether it has a thumbnail)``."""
    lines = [
        "Gallery",
        "=======",
        "",
        "The design notebooks, executed when this site was built, with their outputs and",
        "figures: each card is a notebook's first figure and its title.  They are jupytext",
        "scripts in ``notebooks/``; ``notebooks/README.md`` says how to open and run them.",
        "The figures of the paper's beam are on :doc:`../getting_started`.",
        "",
    ]
    for name, has_figure in cards:
        link = f":doc:`notebooks/{name}`"
        if has_figure:
            lines += [f".. figure:: gallery/{name}.png", "   :width: 70%",
                      f"   :target: notebooks/{name}.html", "", f"   {link}", ""]  # fmt: skip
        else:
            lines += [f"- {link}", ""]
    lines += [".. toctree::", "   :hidden:", "", *(f"   notebooks/{n}" for n, _ in cards), ""]
    return "\n".join(lines)


# --------------------------------------------------------------------------- sphinx
def _write(path: Path, content: str | bytes) -> None:
    """Write ``path`` unless it holds ``content`` already (no needless rebuilds)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    data = content.encode("utf-8") if isinstance(content, str) else content
    if not path.exists() or path.read_bytes() != data:
        path.write_bytes(data)


def notebooks() -> list[tuple[str, bool]]:
    """Write each notebook's page source and thumbnail; return the gallery's cards.

    Every notebook is executed here unless the cache holds it as it is now, so that the
    thumbnails exist before the pages are read and myst-nb only merges stored outputs.
    """
    import nbformat
    import notebook_cache
    from sphinx.util import logging

    log = logging.getLogger(__name__)
    cards = []
    paths = notebook_cache.notebook_paths()
    names = {f"{p.stem}{suffix}" for p in paths for suffix in (".ipynb", ".png")}
    for folder in ("notebooks", "gallery"):  # pages of notebooks renamed or removed
        for stale in (GENERATED / folder).glob("*"):
            if stale.name not in names:
                stale.unlink()
    for path in paths:
        source = nbformat.writes(notebook_cache.read(path))
        _write(GENERATED / "notebooks" / f"{path.stem}.ipynb", source)
        ran = notebook_cache.cached(path)
        if ran is None:
            log.info(f"executing notebooks/{path.name} (not in the cache as it is now)")
            ran, seconds = notebook_cache.execute(path)
            log.info(f"executed notebooks/{path.name} in {seconds:.0f} s")
        figure = first_figure(ran)
        if figure is not None:
            _write(GENERATED / "gallery" / f"{path.stem}.png", figure)
        cards.append((path.stem, figure is not None))
    return cards


def generate(app: Any = None) -> None:
    """Write the generated pages of the site's own sources (unchanged files are left alone)."""
    if app is not None and Path(app.srcdir).resolve() != DOCS:
        return
    for stale in GENERATED.glob("*.rst"):  # pages of an earlier layout (notebooks.rst)
        if stale.name not in ("cli.rst", "gallery.rst"):
            stale.unlink()
    _write(GENERATED / "cli.rst", cli_page())
    _write(GENERATED / "gallery.rst", gallery_page(notebooks()))


def setup(app: Any) -> dict[str, Any]:
    """Register the page generation with Sphinx."""
    app.connect("builder-inited", generate)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
