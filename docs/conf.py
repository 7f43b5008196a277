"""Sphinx configuration of the API reference (``make docs``; built with warnings as errors).

The reference (``docs/api/``) is made from the numpydoc docstrings by autodoc; the guide pages
(``docs/*.md``) are read as they are by myst-parser, so the files GitHub shows are the same
pages.  The build goes to ``docs/_build/`` (git-ignored).
"""
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
os.environ.setdefault("MPLBACKEND", "Agg")      # autodoc imports matplotlib users: never open a window

from bearing_lab._version import __version__  # noqa: E402

project = "bearing_lab"
author = "the bearing_lab authors"
copyright = "the bearing_lab authors (MIT licence)"
version = release = __version__

root_doc = "api/index"
extensions = [
    "sphinx.ext.autodoc",        # the reference from the docstrings
    "sphinx.ext.autosummary",    # the table of the public face (no generated pages)
    "numpydoc",                  # numpydoc sections (Parameters, See Also, Examples ...)
    "myst_parser",               # the guide pages, docs/*.md, as GitHub shows them
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build"]
templates_path = []
html_theme = "alabaster"
html_static_path = []

autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"               # the numpydoc Parameters say the types
autosummary_generate = False
numpydoc_show_class_members = False      # members are documented by autodoc itself
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# the guide pages are written for GitHub: their links out of docs/ (../data/README.md ...) are
# files of the repository, not pages of this site.  Every markdown link is checked to resolve by
# tests/test_docs.py instead.
myst_heading_anchors = 3
suppress_warnings = ["myst.xref_missing"]
