"""Structure of the package, read from the source with :mod:`ast` (nothing is imported).

* No private name crosses a subpackage boundary: no ``from ..x._private import``,
  no ``from ..x import _private`` between different subpackages (top-level modules
  such as ``results.py`` count as their own unit).
* No import cycle between subpackages at module import time: the imports executed
  when a module is imported (module level, class bodies, ``try``/``if`` blocks, not
  function bodies nor ``if TYPE_CHECKING:``) form an acyclic graph between units.
"""

from __future__ import annotations

import ast
from pathlib import Path


SRC = Path(__file__).resolve().parents[1] / "src"
ROOT = "brakesqueal"

#: Private cross-package imports tolerated for now (importer unit, imported module), each with its reason.
ALLOWED_PRIVATE: dict[tuple[str, str], str] = {}


def _modules() -> dict[str, Path]:
    out = {}
    for path in sorted((SRC / ROOT).rglob("*.py")):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def _is_package(name: str) -> bool:
    return MODULES[name].name == "__init__.py"


def unit(module: str) -> str:
    """The subpackage (or top-level module) a module belongs to: ``brakesqueal.analysis.linear`` -> ``analysis``."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ROOT


def _private(word: str) -> bool:
    return word.startswith("_") and not (word.startswith("__") and word.endswith("__"))


def _base(module: str, node: ast.ImportFrom) -> str | None:
    """The absolute module of ``from <node.module> import ...`` written in ``module`` (None: outside the package)."""
    if node.level == 0:
        return node.module if node.module and (node.module == ROOT or node.module.startswith(ROOT + ".")) else None
    pkg = module.split(".") if _is_package(module) else module.split(".")[:-1]
    pkg = pkg[: len(pkg) - (node.level - 1)]
    return ".".join(pkg + ([node.module] if node.module else []))


def _imports(module: str, tree: ast.Module, *, import_time: bool) -> list[tuple[str, list[str], int]]:
    """``(imported module, imported names, line)`` of every import (only those run at import time if asked)."""
    found: list[tuple[str, list[str], int]] = []

    def visit(nodes: list[ast.stmt]) -> None:
        for node in nodes:
            if isinstance(node, ast.Import):
                found.extend((a.name, [], node.lineno) for a in node.names
                             if a.name == ROOT or a.name.startswith(ROOT + "."))
            elif isinstance(node, ast.ImportFrom):
                base = _base(module, node)
                if base is not None:
                    found.append((base, [a.name for a in node.names], node.lineno))
            elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                if not import_time:
                    visit(node.body)
            elif isinstance(node, ast.If) and import_time and "TYPE_CHECKING" in ast.unparse(node.test):
                visit(node.orelse)
            else:
                for field in ("body", "orelse", "finalbody", "handlers"):
                    visit([n for n in getattr(node, field, []) if isinstance(n, ast.stmt)]
                          if field != "handlers" else [s for h in getattr(node, field, []) for s in h.body])
                for case in getattr(node, "cases", []):
                    visit(case.body)
    visit(tree.body)
    return found


def _targets(base: str, names: list[str]) -> list[str]:
    """Modules an import executes: ``from pkg import sub`` imports the submodule ``pkg.sub``."""
    subs = [f"{base}.{n}" for n in names if f"{base}.{n}" in MODULES]
    return subs if subs and len(subs) == len(names) else [base, *subs]


TREES = {m: ast.parse(p.read_text(encoding="utf-8"), str(p)) for m, p in MODULES.items()}


def test_modules_found() -> None:
    assert {"brakesqueal.analysis.linear", "brakesqueal.model.parameters", "brakesqueal.results"} <= set(MODULES)
    assert unit("brakesqueal.analysis.linear") == "analysis" and unit("brakesqueal.results") == "results"


def test_no_private_name_across_subpackages() -> None:
    bad, used = [], set()
    for module, tree in TREES.items():
        for base, names, line in _imports(module, tree, import_time=False):
            if unit(base) == unit(module):
                continue
            words = base.split(".")[1:] + names
            if not any(_private(w) for w in words):
                continue
            if (unit(module), base) in ALLOWED_PRIVATE:
                used.add((unit(module), base))
            else:
                bad.append(f"{MODULES[module].relative_to(SRC)}:{line}: from {base} import {', '.join(names)}")
    assert not bad, "private names imported across subpackages:\n" + "\n".join(bad)
    assert set(ALLOWED_PRIVATE) == used, f"exemptions no longer needed: {sorted(set(ALLOWED_PRIVATE) - used)}"


def _unit_graph() -> dict[str, dict[str, str]]:
    """unit -> {imported unit: one example 'file:line'} of the imports run at import time."""
    graph: dict[str, dict[str, str]] = {}
    for module, tree in TREES.items():
        for base, names, line in _imports(module, tree, import_time=True):
            for target in _targets(base, names):
                # importing a.b.c runs the packages a.b and a too: their units are reached as well
                parts = target.split(".")
                for k in range(1, len(parts) + 1):
                    t = ".".join(parts[:k])
                    if t in MODULES and unit(t) != unit(module):
                        graph.setdefault(unit(module), {}).setdefault(
                            unit(t), f"{MODULES[module].relative_to(SRC)}:{line}")
    return graph


def _cycle(graph: dict[str, dict[str, str]]) -> list[str] | None:
    state: dict[str, int] = {}
    stack: list[str] = []

    def dfs(u: str) -> list[str] | None:
        state[u] = 1
        stack.append(u)
        for v in graph.get(u, {}):
            if state.get(v) == 1:
                return stack[stack.index(v):] + [v]
            if v not in state and (c := dfs(v)):
                return c
        stack.pop()
        state[u] = 2
        return None

    for u in sorted(graph):
        if u not in state and (c := dfs(u)):
            return c
    return None


def test_cycle_detection_works() -> None:
    assert _cycle({"a": {"b": ""}, "b": {"c": ""}, "c": {"a": ""}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b": ""}, "b": {"c": ""}}) is None


def test_no_import_cycle_between_subpackages() -> None:
    graph = _unit_graph()
    assert {"analysis", "model", "simulation", "cli"} <= set(graph)  # the graph really covers the package
    cycle = _cycle(graph)
    where = [f"{a} -> {b} ({graph[a][b]})" for a, b in zip(cycle or [], (cycle or [])[1:])]
    assert cycle is None, "import cycle between subpackages at import time:\n" + "\n".join(where)


def test_private_import_detector_sees_relative_forms() -> None:
    tree = ast.parse("from ..simulation._interrupt import check_interrupt\nfrom ..results import _units\n"
                     "def f():\n    from ..model.parameters import _model\n")
    found = _imports("brakesqueal.sweep.runner", tree, import_time=False)
    assert [(b, n) for b, n, _ in found] == [("brakesqueal.simulation._interrupt", ["check_interrupt"]),
                                            ("brakesqueal.results", ["_units"]),
                                            ("brakesqueal.model.parameters", ["_model"])]
    assert [b for b, _, _ in _imports("brakesqueal.sweep.runner", tree, import_time=True)] == [
        "brakesqueal.simulation._interrupt", "brakesqueal.results"]


# ------------------------------------------------------------------ layering, every import (function level too)
#: The layers, lowest first.  A module may import its own unit and lower layers only, at module level or inside a
#: function alike (``if TYPE_CHECKING:`` imports are annotations and do not count).  ``results`` (result types,
#: their files and figures) sits below the computations that construct them and imports none of them.
LAYERS: dict[str, int] = {
    "brakesqueal": 0, "errors": 0, "status": 0, "suggest": 0, "fingerprint": 0, "outputs": 0, "interrupts": 0,
    "inputs": 0, "validation": 0,
    "model": 1, "symbolic": 2, "codegen": 3, "labels": 4, "results": 4, "plotting": 4, "analysis": 5,
    "simulation": 6, "export": 6, "nonlinear": 7, "sweep": 7, "uq": 7, "region": 7, "robust": 7, "render": 8,
    "reproduce": 8, "design": 8,
    "api": 8, "api_nonlinear": 8, "cli": 9, "explorer": 9, "demo": 9, "__main__": 9,
}


def _runtime_imports(module: str, tree: ast.Module) -> list[tuple[str, list[str], int]]:
    """Every import that can run (module level and inside functions), not those under ``if TYPE_CHECKING:``."""
    found: list[tuple[str, list[str], int]] = []

    def visit(nodes: list[ast.stmt]) -> None:
        for node in nodes:
            if isinstance(node, ast.Import):
                found.extend((a.name, [], node.lineno) for a in node.names
                             if a.name == ROOT or a.name.startswith(ROOT + "."))
            elif isinstance(node, ast.ImportFrom):
                base = _base(module, node)
                if base is not None:
                    found.append((base, [a.name for a in node.names], node.lineno))
            elif isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
                visit(node.orelse)
            else:
                for child in ast.iter_child_nodes(node):
                    if isinstance(child, ast.stmt):
                        visit([child])
                    elif isinstance(child, ast.excepthandler):
                        visit(child.body)
    visit(tree.body)
    return found


def test_every_unit_has_a_layer() -> None:
    units = {unit(m) for m in MODULES}
    assert units <= set(LAYERS), f"units without a layer: {sorted(units - set(LAYERS))}"


def test_imports_follow_the_layers_at_every_depth() -> None:
    bad = []
    for module, tree in TREES.items():
        u = unit(module)
        for base, names, line in _runtime_imports(module, tree):
            for target in _targets(base, names):
                v = unit(target)
                if v != u and LAYERS[v] > LAYERS[u]:
                    bad.append(f"{MODULES[module].relative_to(SRC)}:{line}: {u} (layer {LAYERS[u]}) imports "
                               f"{target} ({v}, layer {LAYERS[v]})")
    assert not bad, "imports against the layers:\n" + "\n".join(sorted(set(bad)))


def test_layer_check_sees_function_level_imports() -> None:
    tree = ast.parse("def f():\n    from ..cli import main\nif TYPE_CHECKING:\n    from ..api import engine\n")
    assert [b for b, _, _ in _runtime_imports("brakesqueal.analysis.maps", tree)] == ["brakesqueal.cli"]


# ------------------------------------------------------------------ one engine, one dispatcher
#: Where an engine may be built (``build``/``compile_model`` called): the entry points.  A sweep's chunk runs in a
#: worker process and its study file names a model: both build the model they read; ``export`` writes a model it
#: builds.  Everything else receives the engine as a value.
ENTRY_MODULES = {
    "brakesqueal.api", "brakesqueal.api_nonlinear", "brakesqueal.sweep.compute", "brakesqueal.sweep.study",
    "brakesqueal.export.model", "brakesqueal.codegen.engine",
}
ENTRY_UNITS = {"cli", "explorer"}
#: Modules still building their own engine while their package moves onto the engine (none when done).
PENDING_BUILD: set[str] = set()


def _calls(tree: ast.AST, names: set[str]) -> list[int]:
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            f = node.func
            name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else ""
            if name in names:
                out.append(node.lineno)
    return out


def test_engines_are_built_only_at_entry_points() -> None:
    bad, pending = [], set()
    for module, tree in TREES.items():
        if module in ENTRY_MODULES or unit(module) in ENTRY_UNITS:
            continue
        lines = _calls(tree, {"build", "compile_model"})
        if not lines:
            continue
        if module in PENDING_BUILD:
            pending.add(module)
            continue
        bad += [f"{MODULES[module].relative_to(SRC)}:{ln}" for ln in lines]
    assert not bad, "an engine built below the entry points (pass it down instead):\n" + "\n".join(bad)
    assert pending == PENDING_BUILD, f"no longer pending: {sorted(PENDING_BUILD - pending)}"


#: The certified primitives a route runs; only route modules (and the primitives' own module) may call them.
VERDICT_PRIMITIVES = {
    "routh_verdicts", "routh_exact", "quartic_interval", "state_verdicts", "state_analysis", "eigen_verdicts",
    "descriptor_verdicts", "extended_descriptor_verdict", "extended_analysis", "charpoly_verdicts", "classify",
    "run_classify", "_exact_point",
}
PRIMITIVE_HOMES = {"brakesqueal.analysis.robust", "brakesqueal.analysis.kernels", "brakesqueal.codegen.stability"}


def test_exactly_one_function_chooses_verdict_routes() -> None:
    """Routes are run in one place (``_choose``); nothing outside the route modules calls a verdict primitive."""
    runners = []
    for module, tree in TREES.items():
        for fn in ast.walk(tree):
            if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            text = ast.unparse(fn)
            if "ROUTES" in text and ".run(" in text:
                runners.append(f"{module}.{fn.name}")
    assert runners == ["brakesqueal.analysis.verdict._dispatch._choose"], runners
    bad = []
    for module, tree in TREES.items():
        if module in PRIMITIVE_HOMES or module.startswith("brakesqueal.analysis.verdict."):
            continue
        for ln in _calls(tree, VERDICT_PRIMITIVES):
            bad.append(f"{MODULES[module].relative_to(SRC)}:{ln}")
    assert not bad, "verdict primitives called outside the routes (ask the dispatcher):\n" + "\n".join(bad)
