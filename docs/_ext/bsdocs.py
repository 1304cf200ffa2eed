"""Sphinx extension of the brakesqueal docs: API pages, CLI reference, figure gallery.

* **API pages** (``builder-inited``): every public module of the package
  (found with :func:`pkgutil.walk_packages`; private ``_modules`` and
  ``__main__`` skipped) gets ``api/<module>.rst``, regenerated on every build.
  Each public name (the module's ``__all__``, else its public functions and
  classes) is documented once, in its canonical module (where it is defined,
  or the nearest public package re-exporting a private module's name); other
  modules list it under "Re-exported".  A module that fails to import is a
  warning, hence an error under ``-W``.
* ``.. brakesqueal-cli::`` renders the help of every command and option of
  :data:`brakesqueal.cli.app` (through typer's vendored click objects).
* ``.. brakesqueal-gallery::`` shows every ``figures/*.png`` (sorted by name).
* ``.. brakesqueal-guides::`` is a toctree of the top-level pages that are not
  in ``bsdocs_fixed_pages`` (the guides colleagues add to ``docs/``).
* ``.. brakesqueal-equations::`` is the table "equation of the theory page →
  function" of ``_ext/equations.py``; each module's API page lists its own rows
  under "Theory", linking back to the equations.

Why not sphinx-click and autosummary's generated pages (tried with Sphinx 9.0,
sphinx-click 6.2, typer 0.28):

* **sphinx-click** documents ``click`` objects, and typer vendors its own copy
  of click since 0.26 (``typer._click``): ``typer.main.get_command(app)`` is
  not a ``click.Command``, and sphinx-click refuses it ("is not
  click.Command or click.Group"); it would also find no options (it tests
  ``isinstance(param, click.Option)``).  The installed typer is inside the
  pin ``typer>=0.12,<0.29``, so the CLI reference reads typer's click objects
  here.
* **autosummary** (``autosummary_generate`` with ``:recursive:``) imports every
  submodule, private ones and ``brakesqueal.__main__`` included: importing the
  latter runs the command line and ends the build ("No such option: -E").
  With that module stubbed out, ``__all__`` respected and templates giving every
  function and class its page, it reached 36 of the 117 public modules (a
  package's submodules not named in its ``__all__`` are not recursed into) and
  202 objects, against the 677 names documented here; the top-level page listed none
  of the package's entry points (lazily loaded re-exports), and one class got
  two descriptions (a ``-W`` error).  What bsdocs adds is the walk over every
  public module and :func:`canonical_locations`: each object documented once,
  where it is defined (or, for the 29 defined in private modules, in the public
  package re-exporting it), the 206 re-exports listed as links to it.  The
  summary tables are autosummary's; the per-module "Theory" rows are bsdocs'.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import re
import shutil
from pathlib import Path
from typing import Any

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles

logger = logging.getLogger(__name__)

try:  # the docs' own table; bsdocs also works without it
    from equations import EQUATIONS
except ImportError:  # pragma: no cover
    EQUATIONS = []

PACKAGE = "brakesqueal"
API_DIR = "api"


# ------------------------------------------------------------------ API pages
#: Packages of kernel source templates (``codegen/templates``): the code generator reads them as text and
#: fills them in; on their own they neither import (numba types their free names) nor form an API.
TEXT_PACKAGES = ("brakesqueal.codegen.templates.",)

def public_modules(package: str = PACKAGE) -> tuple[list[str], dict[str, str]]:
    """Names of the public modules of ``package`` and ``{module: import error}``."""
    pkg = importlib.import_module(package)
    names, errors = [package], {}

    def onerror(name: str) -> None:
        errors[name] = "cannot be imported while walking the package"

    for info in pkgutil.walk_packages(pkg.__path__, f"{package}.", onerror=onerror):
        if any(part.startswith("_") for part in info.name.split(".")):
            continue
        if info.name.startswith(TEXT_PACKAGES):  # numba source read as text by the code generator
            continue
        try:
            importlib.import_module(info.name)
        except Exception as exc:  # noqa: BLE001 - reported as a Sphinx warning
            errors[info.name] = f"{type(exc).__name__}: {exc}"
            continue
        names.append(info.name)
    return sorted(names), errors


def public_names(module: Any) -> list[str]:
    """``__all__``, else the public functions and classes defined in the module."""
    if hasattr(module, "__all__"):
        return [n for n in module.__all__ if not (n.startswith("__") and n.endswith("__")) or n == "__version__"]
    out = []
    for name, obj in vars(module).items():
        if not name.startswith("_") and (inspect.isfunction(obj) or inspect.isclass(obj)):
            if getattr(obj, "__module__", None) == module.__name__:
                out.append(name)
    return out


def _assigned_names(module: Any) -> set[str]:
    """Names assigned at the top level of the module's source (where data is defined)."""
    try:
        tree = ast.parse(inspect.getsource(module))
    except (OSError, TypeError, SyntaxError):
        return set()
    names: set[str] = set()
    for node in tree.body:
        targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(node, ast.AnnAssign) else []
        for t in targets:
            if isinstance(t, ast.Name):
                names.add(t.id)
    return names


def _common_prefix(a: str, b: str) -> int:
    n = 0
    for x, y in zip(a.split("."), b.split(".")):
        if x != y:
            break
        n += 1
    return n


def canonical_locations(modules: list[str]) -> dict[tuple[str, str], str]:
    """``{(module, name): canonical module}`` for every public name of every module."""
    exporters: dict[int, list[tuple[str, str]]] = {}
    objects: dict[int, Any] = {}
    table: dict[tuple[str, str], str] = {}
    for m in modules:
        mod = importlib.import_module(m)
        for name in public_names(mod):
            obj = getattr(mod, name, None)
            key = id(obj) if (inspect.isroutine(obj) or inspect.isclass(obj)) else hash((m, name))
            exporters.setdefault(key, []).append((m, name))
            objects[key] = obj
    # data may be exported by several modules: key it by (name, value identity) instead
    data_groups: dict[tuple[str, int], list[tuple[str, str]]] = {}
    for key, locs in exporters.items():
        obj = objects[key]
        if inspect.isroutine(obj) or inspect.isclass(obj):
            home = getattr(obj, "__module__", "") or ""
            best = max(locs, key=lambda loc: (loc[0] == home, _common_prefix(loc[0], home), len(loc[0])))
            for loc in locs:
                table[loc] = best[0]
        else:
            for loc in locs:
                data_groups.setdefault((loc[1], id(getattr(importlib.import_module(loc[0]), loc[1], None))), []).append(loc)
    for (name, _), locs in data_groups.items():
        defining = [loc for loc in locs if name in _assigned_names(importlib.import_module(loc[0]))]
        best = max(defining or locs, key=lambda loc: len(loc[0]))
        for loc in locs:
            table[loc] = best[0]
    return table


_BARS = re.compile(r"(?<![\\|`])\|(?=[^\s|])([^|`]*?[^\s\\|])\|(?![|`])")


def clean_docstring(app: Sphinx, what: str, name: str, obj: Any, options: Any, lines: list[str]) -> None:
    """``autodoc-process-docstring``: project conventions for docstrings.

    * Data without its own ``#:`` comment would show its *type's* docstring
      (``dict``, ``Typer``, ...): drop it.
    * ``|v_r|`` means an absolute value, never a reST substitution: escape it.
    """
    if what in ("data", "attribute") and not (inspect.isroutine(obj) or inspect.isclass(obj) or inspect.ismodule(obj)):
        own = inspect.getdoc(type(obj)) or ""
        if own and "\n".join(lines).strip() == own.strip():
            lines[:] = []
            return
    for i, line in enumerate(lines):
        parts = line.split("``")
        parts[::2] = [_BARS.sub(r"\\|\1\\|", seg) for seg in parts[::2]]
        lines[i] = "``".join(parts)


def _directive(obj: Any) -> str:
    if inspect.isclass(obj):
        return "autoexception" if issubclass(obj, BaseException) else "autoclass"
    if inspect.isroutine(obj):
        return "autofunction"
    return "autodata"


def _equation_ref(label: str, eqs: str) -> str:
    return f":ref:`eq. {eqs} <{label}>`" if eqs[:1] == "(" else f":ref:`{eqs} <{label}>`"


def equation_rows(modname: str | None = None) -> list[tuple[str, str, str, str]]:
    """Rows of :data:`equations.EQUATIONS` (those of functions defined in ``modname`` if given)."""
    return [row for row in EQUATIONS if modname is None or row[2].rsplit(".", 1)[0] == modname]


def check_equation_rows() -> None:
    """Warn (an error under ``-W``) about rows whose function cannot be found."""
    for _, _, name, _ in EQUATIONS:
        modname, attr = name.rsplit(".", 1)
        try:
            ok = hasattr(importlib.import_module(modname), attr)
        except ImportError:
            ok = False
        if not ok:
            logger.warning("bsdocs: _ext/equations.py names %s, which does not exist", name)


def module_page(modname: str, table: dict[tuple[str, str], str], modules: list[str]) -> str:
    """reST source of one module's API page."""
    mod = importlib.import_module(modname)
    title = f"``{modname}``"
    lines = [title, "=" * len(title), "", f".. automodule:: {modname}", "   :no-members:", ""]
    rows = equation_rows(modname)
    if rows:
        lines += [".. rubric:: Theory", "", "Equations of the :doc:`theory page </theory>` implemented here:", ""]
        lines += [f"* {_equation_ref(label, eqs)}: :func:`~{name}` — {what}" for label, eqs, name, what in rows]
        lines += [""]
    own, reexported = [], []
    for name in public_names(mod):
        if inspect.ismodule(getattr(mod, name, None)):
            # a submodule shadows the name (e.g. brakesqueal.simulate): documented as a module
            logger.info("bsdocs: %s.%s is a module; not listed as a member", modname, name)
            continue
        home = table.get((modname, name), modname)
        (own if home == modname else reexported).append((name, home))
    subs = [m for m in modules if m.rsplit(".", 1)[0] == modname and m != modname]
    # the tables use full names; autosummary wants no current module for that
    lines += [".. py:currentmodule:: None", ""]
    if subs:
        lines += [".. rubric:: Modules", "", ".. autosummary::", ""]
        lines += [f"   {m}" for m in subs] + [""]
    if own:
        lines += [".. rubric:: Summary", "", ".. autosummary::", ""]
        lines += [f"   {modname}.{n}" for n, _ in own] + [""]
    if reexported:
        lines += [".. rubric:: Re-exported", "", ".. autosummary::", ""]
        lines += [f"   {home}.{n}" for n, home in reexported] + [""]
    lines += [f".. py:currentmodule:: {modname}", ""]
    if own:
        lines += [".. rubric:: Reference", ""]
    for name, _ in own:
        obj = getattr(mod, name)
        kind = _directive(obj)
        lines.append(f".. {kind}:: {modname}.{name}")
        if kind == "autoclass":
            lines.append("   :members:")
        if kind == "autodata":
            lines.append("   :no-value:")
        lines.append("")
    return "\n".join(lines)


def write_api_pages(app: Sphinx) -> None:
    """Regenerate ``api/*.rst`` (one page per public module) in the source directory."""
    out = Path(app.srcdir) / API_DIR
    if out.exists():
        shutil.rmtree(out)
    out.mkdir()
    modules, errors = public_modules()
    for name, err in sorted(errors.items()):
        logger.warning("bsdocs: module %s cannot be imported: %s", name, err)
    table = canonical_locations(modules)
    check_equation_rows()
    for m in modules:
        (out / f"{m}.rst").write_text(module_page(m, table, modules))


# --------------------------------------------------------------- CLI reference
def _cli_rst() -> list[str]:
    import typer.main

    from brakesqueal.cli import app as typer_app

    root = typer.main.get_command(typer_app)
    ctx_class = type(root).context_class
    lines: list[str] = []

    def walk(cmd: Any, path: list[str], parent: Any) -> None:
        ctx = ctx_class(cmd, info_name=path[-1], parent=parent)
        if getattr(cmd, "hidden", False):
            return
        title = " ".join(path)
        lines.extend([f"``{title}``", "-" * (len(title) + 4), ""])
        help_text = inspect.cleandoc(cmd.help or "")
        lines.extend([help_text, ""] if help_text else [])
        lines.extend(["::", "", "   " + cmd.get_usage(ctx).replace("\n", "\n   "), ""])
        records = [(p, p.get_help_record(ctx)) for p in cmd.params]
        records = [(p, r) for p, r in records if r is not None]
        for p, (opts, text) in records:
            kind = " (argument)" if getattr(p, "param_type_name", "") == "argument" else ""
            lines.extend([f"``{opts}``{kind}", f"   {text.replace(chr(10), ' ')}", ""])
        for name, sub in sorted(getattr(cmd, "commands", {}).items()):
            walk(sub, path + [name], ctx)

    walk(root, ["brakesqueal"], None)
    return lines


class CliDirective(SphinxDirective):
    """Render the help of every command and option of ``brakesqueal.cli.app``."""

    has_content = False

    def run(self) -> list[nodes.Node]:
        node = nodes.section()
        node.document = self.state.document
        nested_parse_with_titles(self.state, StringList(_cli_rst(), source="brakesqueal.cli.app"), node)
        return node.children


class GalleryDirective(SphinxDirective):
    """One figure per ``figures/*.png`` next to this page, sorted by name."""

    has_content = False

    def run(self) -> list[nodes.Node]:
        here = Path(self.env.doc2path(self.env.docname)).parent
        figs = sorted((here / "figures").glob("*.png"))
        if not figs:
            return [nodes.paragraph(text="No figures yet: run 'brakesqueal reproduce all --out docs/figures'.")]
        lines: list[str] = []
        for f in figs:
            self.env.note_dependency(str(f))
            lines += [f".. figure:: figures/{f.name}", f"   :alt: {f.stem}", "   :width: 90%", "",
                      f"   ``{f.name}``", ""]  # fmt: skip
        node = nodes.container()
        self.state.nested_parse(StringList(lines, source="figures/"), self.content_offset, node)
        return node.children


class GuidesDirective(SphinxDirective):
    """A toctree of every top-level page not listed in ``bsdocs_fixed_pages`` (new guides appear by themselves)."""

    has_content = False

    def run(self) -> list[nodes.Node]:
        fixed = set(self.config.bsdocs_fixed_pages) | {self.env.docname}
        pages = sorted(d for d in self.env.found_docs if "/" not in d and d not in fixed)
        lines = [".. toctree::", "   :maxdepth: 1", "   :caption: Guides", ""] + [f"   {d}" for d in pages]
        node = nodes.container()
        self.state.nested_parse(StringList(lines, source="bsdocs"), self.content_offset, node)
        return node.children


class EquationsDirective(SphinxDirective):
    """The table "equation of the theory page → function that implements it" (``_ext/equations.py``)."""

    has_content = False

    def run(self) -> list[nodes.Node]:
        lines = [".. list-table::", "   :header-rows: 1", "   :widths: 18 32 50", "   :class: eq-map", "",
                 "   * - Equations", "     - Function", "     - What it computes"]  # fmt: skip
        for label, eqs, name, what in equation_rows():
            lines += [f"   * - {_equation_ref(label, eqs)}", f"     - :func:`{name}`", f"     - {what}"]
        node = nodes.container()
        self.state.nested_parse(StringList(lines, source="_ext/equations.py"), self.content_offset, node)
        return node.children


def setup(app: Sphinx) -> dict[str, Any]:
    """Register the generator and the directives."""
    app.connect("builder-inited", write_api_pages)
    app.connect("autodoc-process-docstring", clean_docstring)
    app.add_directive("brakesqueal-cli", CliDirective)
    app.add_directive("brakesqueal-gallery", GalleryDirective)
    app.add_directive("brakesqueal-guides", GuidesDirective)
    app.add_directive("brakesqueal-equations", EquationsDirective)
    app.add_config_value("bsdocs_fixed_pages", [], "env")
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
