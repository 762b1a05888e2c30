"""Sphinx configuration of phdesign's documentation (built offline, warnings as errors)."""

from __future__ import annotations

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS.parent))  # document this checkout
sys.path.insert(0, str(DOCS / "_ext"))

from notebook_cache import CACHE, CELL_TIMEOUT  # noqa: E402
from offline_math import MATHJAX2_CONFIG, MATHJAX_PATH  # noqa: E402

import phdesign  # noqa: E402

project = "phdesign"
author = "the phdesign authors"
copyright = "the phdesign authors, BSD-3-Clause"
release = version = phdesign.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_nb",  # Markdown pages (myst-parser) and the executed notebooks
    "phdesign_docs",
    "offline_math",
]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
myst_enable_extensions = ["dollarmath", "amsmath"]  # the notebooks write $...$ and $$...$$
myst_heading_anchors = 3  # "model_files.md#boundary-feedback-dampers-in-the-plant" links work
autosummary_generate = True
autodoc_typehints = "none"  # numpydoc's Parameters sections state the types
autodoc_default_options = {"members": True, "inherited-members": False}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
exclude_patterns = ["_build", "api/generated/*.inc"]
templates_path: list[str] = []
html_theme = "alabaster"
html_theme_options = {"description": "Boundary observers for 1D BC-PHS", "fixed_sidebar": True}
html_static_path: list[str] = []
master_doc = "index"
# prose keeps "--" and quotes as typed: an option copied from a page must run, and docutils
# would turn "--gain" into an en dash
smartquotes = False
# MathJax ships with the site (docs/_ext/offline_math.py): formulas render without a network
mathjax_path = MATHJAX_PATH
mathjax2_config = MATHJAX2_CONFIG
# the notebooks (docs/_ext/notebook_cache.py): executed once for the tests and the site,
# stored in jupyter-cache; myst-nb merges the stored outputs and never shows an error
nb_execution_mode = "cache"
nb_execution_cache_path = str(CACHE)
nb_execution_timeout = CELL_TIMEOUT
nb_execution_raise_on_error = True
nb_merge_streams = True
