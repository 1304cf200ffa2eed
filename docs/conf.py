"""Sphinx configuration of the brakesqueal documentation (build: ``make docs``).

Sphinx rather than MkDocs: autodoc + napoleon read the package's numpydoc
docstrings directly, ``-W`` turns every warning (broken reference, malformed
docstring, a module that fails to import, a page outside the toc tree) into an
error, and myst-parser (through myst-nb) renders the Markdown pages.  The API
pages and the CLI reference are generated at build time by ``_ext/bsdocs.py``
(walking the package and ``brakesqueal.cli.app``), so new modules and commands
appear without editing these files; its docstring says why not autosummary's
``:recursive:`` pages and sphinx-click.  The tutorial notebooks of ``examples/``
are rendered by myst-nb and executed at build time (``_ext/notebooks.py``).

Navigation: five sections (Getting started, User guide, Tutorials, Reference,
Gallery) in the top bar; the left sidebar lists the pages of the current section.
``make docs`` checks the layout at 1280 px and on a phone in a browser
(``_ext/check_layout.py``) and that nothing is loaded from the network
(``_ext/check_offline.py``).
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
    "myst_nb",  # MyST Markdown (it loads myst_parser) and Jupyter notebooks
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",  # MathJax 3 bundled into _static/mathjax: no CDN (sets mathjax_path)
    "bsdocs",
    "gallery_run",  # runs the gallery's commands at build time (docs/_generated/gallery)
    "notebooks",  # copies examples/*.ipynb into docs/examples, the kernel and cache myst-nb executes them with
]

source_suffix = {".md": "myst-nb", ".rst": "restructuredtext", ".ipynb": "myst-nb"}  # myst-nb parses MyST Markdown too
root_doc = "index"
exclude_patterns = ["_build", "_ext", "_generated", "figures/**", "**/.ipynb_checkpoints", "README.md"]
templates_path: list[str] = []

# MyST: Markdown pages with $...$ / $$...$$ mathematics (dollarmath) and ::: fences.
myst_enable_extensions = ["colon_fence", "dollarmath"]
myst_heading_anchors = 3

# myst-nb: the notebooks (copied from examples/ by _ext/notebooks.py) are executed at build time; outputs are cached
# per notebook and per source of the package (docs/_build/.jupyter_cache/<hash>), so a rebuild with neither changed
# does not run them again.  A failing cell fails the build.  Measured on the 2-core development machine: the five
# notebooks add about 100 s to a build without a cache (05-fe-matrices alone about 55 s) and nothing with one.
nb_execution_mode = "cache"
nb_execution_timeout = 900  # s per cell
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_kernel_rgx_aliases = {"python3": "brakesqueal-docs"}  # the kernel of _ext/notebooks.py: this interpreter
nb_merge_streams = True
nb_ipywidgets_js: dict[str, dict[str, str]] = {}  # never RequireJS/ipywidgets from a CDN (the site is offline)

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
# Layout (checked by _ext/check_layout.py in ``make docs``): the top bar holds the five sections of index.md's
# toctree in one row at 1280 px; the left sidebar lists the current section's pages (collapsed below each page) and
# is left out on the pages of a section without sub-pages (Getting started, Gallery) rather than shown empty.
html_theme_options = {
    "search_as_you_type": True,
    "navbar_align": "left",
    "header_links_before_dropdown": 6,
    "show_nav_level": 1,
    "navigation_depth": 3,
    "collapse_navigation": False,
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
html_sidebars: dict[str, list[str]] = {"index": [], "getting-started": [], "gallery": []}
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

# Pages placed by hand in index.md, guides.md and reference.md; every other top-level page is listed under "Guides".
bsdocs_fixed_pages = ["index", "getting-started", "guides", "reference", "gallery",  # the sections
                      "tour", "glossary", "theory", "paper-errata",  # placed in guides.md
                      "api", "cli", "benchmarks", "status"]  # placed in reference.md
