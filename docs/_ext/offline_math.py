r"""Sphinx extension of phdesign's documentation: MathJax shipped with the site.

Every formula of the site is typeset by MathJax in the reader's browser.  Sphinx loads
MathJax from a CDN by default, so that without a network every formula stays raw TeX
(``\(\kappa^*\)``).  Here the MathJax installed on the building machine is copied into the
built site (``_static/mathjax``) when the build finishes, and ``mathjax_path`` (set in
``conf.py``) points there: the site renders its formulas offline, from any folder.

MathJax is not part of the repository.  It is read from the first folder of
:data:`SEARCHED` that holds a ``MathJax.js`` (MathJax 2): ``$PHDESIGN_MATHJAX``, then
Debian's ``libjs-mathjax`` package (``apt-get install libjs-mathjax fonts-mathjax``; CI
installs it, ``.ci/run``).  npm's ``mathjax@2`` has the same layout:
``PHDESIGN_MATHJAX=node_modules/mathjax``.  Without it the build stops and says what to
install.  Only what the configuration ``TeX-AMS_CHTML`` loads is copied (:data:`PARTS`,
about 6 MB of the package's 54 MB).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any

#: Where MathJax 2 is looked for, in order (``PHDESIGN_MATHJAX`` first when set).
SEARCHED = ("/usr/share/javascript/mathjax", "/usr/share/mathjax")
#: The configuration the site loads: TeX input, CommonHTML output (web fonts, no images).
CONFIG = "TeX-AMS_CHTML"
#: The files and folders of the package that configuration reads.
PARTS = (
    "MathJax.js",
    f"config/{CONFIG}.js",
    "extensions",
    "jax/element",
    "jax/input/TeX",
    "jax/output/CommonHTML",
    "fonts/HTML-CSS/TeX/woff",
    "localization/en",
)
#: ``mathjax_path`` for conf.py: relative to the site's ``_static``.
MATHJAX_PATH = f"mathjax/MathJax.js?config={CONFIG}"
#: MathJax 2 reads the spans Sphinx writes (``\(...\)``, ``\[...\]``) and nothing else.
MATHJAX2_CONFIG = {
    "tex2jax": {
        "inlineMath": [["\\(", "\\)"]],
        "displayMath": [["\\[", "\\]"]],
        "processEscapes": True,
        "ignoreClass": "document",
        "processClass": "math|output_area",
    },
}


class MathJaxMissing(RuntimeError):
    """No MathJax 2 on the building machine."""


def mathjax_folder() -> Path:
    """Return the installed MathJax 2 folder (the one holding ``MathJax.js``).

    Raises
    ------
    MathJaxMissing
        Naming the folders searched and what to install.
    """
    given = os.environ.get("PHDESIGN_MATHJAX")
    candidates = ([given] if given else []) + list(SEARCHED)
    for folder in map(Path, candidates):
        if (folder / "MathJax.js").is_file():
            return folder
    raise MathJaxMissing(
        f"MathJax 2 not found (no MathJax.js in {', '.join(candidates)}): the site ships "
        "MathJax so that formulas render offline; install Debian's libjs-mathjax and "
        "fonts-mathjax, or npm's mathjax@2 and set PHDESIGN_MATHJAX to its folder"
    )


def copy_mathjax(static: Path, source: Path | None = None) -> Path:
    """Copy :data:`PARTS` of MathJax into ``static/mathjax`` and return that folder.

    Symbolic links (Debian links its fonts from fonts-mathjax) are copied as files.
    """
    source = mathjax_folder() if source is None else source
    target = static / "mathjax"
    for part in PARTS:
        origin, copy = source / part, target / part
        if origin.is_dir():
            shutil.copytree(origin, copy, dirs_exist_ok=True)
        else:
            copy.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(origin, copy)
    return target


def _check(app: Any) -> None:
    """Fail early, before any page is read, when MathJax is missing or not configured."""
    from sphinx.errors import ExtensionError

    if app.builder.format != "html":
        return
    if app.config.mathjax_path != MATHJAX_PATH:
        raise ExtensionError(f"conf.py: mathjax_path must be {MATHJAX_PATH!r} (offline_math)")
    try:
        mathjax_folder()
    except MathJaxMissing as error:
        raise ExtensionError(str(error)) from None


def _copy(app: Any, exception: Exception | None) -> None:
    if exception is None and app.builder.format == "html":
        copy_mathjax(Path(app.outdir) / "_static")


def setup(app: Any) -> dict[str, Any]:
    """Check for MathJax when the build starts; copy it into the site when it ends."""
    app.connect("builder-inited", _check)
    app.connect("build-finished", _copy)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
