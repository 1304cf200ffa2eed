"""Sphinx configuration of the brakesqueal documentation (build: ``make docs``).

Sphinx rather than MkDocs: autodoc + napoleon read the package's numpydoc
docstrings directly, ``-W`` turns every warning (broken reference, malformed
docstring, a module that fails to import, a page outside the toc tree) into an
error, and myst-parser renders the existing Markdown pages unchanged.  The API
pages and the CLI reference are generated at build time by ``_ext/bsdocs.py``
(walking the package and ``brakesqueal.cli.app``), so new modules and commands
appear without editing these files.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(HERE.parent / "src"))
os.environ.setdefault("MPLBACKEND", "Agg")

import brakesqueal  # noqa: E402

project = "brakesqueal"
author = "brakesqueal contributors"
copyright = "brakesqueal contributors"  # noqa: A001
release = version = brakesqueal.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",  # MathJax 3 bundled into _static/mathjax: no CDN (sets mathjax_path)
    "bsdocs",
    "gallery_run",  # runs the gallery's commands at build time (docs/_generated/gallery)
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "_ext", "_generated", "figures/**", "**/.ipynb_checkpoints", "README.md"]
templates_path: list[str] = []

# MyST: Markdown pages with $...$ / $$...$$ mathematics (dollarmath) and ::: fences.
myst_enable_extensions = ["colon_fence", "dollarmath"]
myst_heading_anchors = 3

# autodoc / napoleon: numpydoc-style docstrings, signatures with type hints in the description.
autodoc_default_options = {"show-inheritance": True}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_typehints_description_target = "documented"
autodoc_preserve_defaults = True
autosummary_generate = False  # the API pages are written by _ext/bsdocs.py
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
napoleon_use_ivar = True

# pydata-sphinx-theme (NumPy, SciPy, pandas, xarray): light/dark switch, search as you type. Its CSS,
# JavaScript and icon font ship with the package; nothing here may point off the machine (no icon links,
# analytics, version switcher or announcement URL), and ``make docs`` checks it after the build
# (``_ext/check_offline.py``).
html_theme = "pydata_sphinx_theme"
html_title = f"brakesqueal {release}"
html_static_path: list[str] = ["_static"]
html_css_files = ["brakesqueal.css"]
html_show_sourcelink = False
html_theme_options = {
    "search_as_you_type": True,
    "navbar_align": "left",
    "header_links_before_dropdown": 6,
    "show_toc_level": 2,
    "navigation_with_keys": False,
    "icon_links": [],
    "external_links": [],
    "analytics": {},
    "footer_start": ["copyright"],
    "footer_center": [],
    "footer_end": [],
    "secondary_sidebar_items": ["page-toc"],
    "pygments_light_style": "tango",
    "pygments_dark_style": "monokai",
}
html_context = {"default_mode": "auto"}  # follow the reader's system setting until the switch is used

# Mathematics: $...$ / $$...$$ (MyST dollarmath) rendered by the bundled MathJax 3 (see the extension above).
# Equation numbers are the paper's: display equations carry ``\tag{N}`` and a target ``(eq-N)=``, so that any
# page or docstring can link to them (``{ref}`eq. (44) <eq-44>```, ``:ref:`eq. (44) <eq-44>```).
mathjax3_config = {"chtml": {"displayAlign": "center"}}

# The README's ``console`` blocks hold comments with apostrophes, which Pygments' console lexer
# cannot tokenize; Sphinx then falls back to plain text.  Only the colouring is affected.
# Attribute fields named ``n``/``m`` (sizes) exist on several classes; napoleon's ``:ivar:`` turns each
# into an unqualified cross-reference that Sphinx calls ambiguous ("ref.python").  The link resolves to
# one of the candidates; the text is right either way.
suppress_warnings = ["misc.highlighting_failure", "ref.python"]

# Pages placed by hand in index.md; every other top-level page is listed under "Guides".
bsdocs_fixed_pages = ["index", "getting-started", "theory", "paper-errata", "api", "cli", "benchmarks", "gallery"]
