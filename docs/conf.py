"""Sphinx configuration of phdesign's documentation (built offline, warnings as errors)."""

from __future__ import annotations

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS.parent))  # document this checkout
sys.path.insert(0, str(DOCS / "_ext"))

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
    "myst_parser",
    "phdesign_docs",
    "offline_math",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
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
