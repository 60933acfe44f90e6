"""The railway package's own import graph (issue 22, "The house, for the next engineer").

Every module of ``railway/`` is parsed with :mod:`ast` (nothing is executed); its imports of
other railway modules -- at module level and inside functions, absolute and relative,
``importlib.import_module("railway...")`` with a literal name -- are the edges of the graph.  A
``from package import name`` is an edge to the sub-module ``package.name`` where that is a
module, else to the package.  The implicit import of a module's parent package is not an edge (a
package's ``__init__`` re-exports its children; that is not a circle of dependencies).

Rules: no import circles; ``railway.contact`` (contact mechanics) never imports
``railway.vehicles`` (vehicle dynamics); no railway module imports a pre-issue-22 path (those
only warn, see :mod:`railway.moved_modules`).
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
RAILWAY = REPO / "railway"

#: circles that are known and scheduled to go (none left: issue 22 broke scenes <-> vehicle_scenes by
#: moving the scenes' bodies to examples/)
ALLOWED_CYCLES: list[set[str]] = []


def module_names(root: Path = RAILWAY) -> dict[str, Path]:
    """Dotted module name -> file of every module under ``root`` (packages by their __init__)."""
    out = {}
    for path in sorted(root.rglob("*.py")):
        parts = list(path.relative_to(root.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def imported_modules(source: str, name: str, is_package: bool, known) -> list[tuple[int, str]]:
    """``(line, dotted name)`` of every railway import in ``source`` (module ``name``).

    ``known`` is the set of module names that exist; an imported name that is neither a known
    module nor an attribute of one is reported as it is (e.g. an old path).
    """
    package = name.split(".") if is_package else name.split(".")[:-1]
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names if a.name.split(".")[0] == "railway"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            if mod.split(".")[0] != "railway":
                continue
            for a in node.names:
                sub = f"{mod}.{a.name}"
                found.append((node.lineno, sub if sub in known else mod))
        elif isinstance(node, ast.Call) and node.args:
            func = node.func
            fname = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
            first = node.args[0]
            if (fname in ("import_module", "__import__") and isinstance(first, ast.Constant)
                    and isinstance(first.value, str) and first.value.split(".")[0] == "railway"):
                found.append((node.lineno, first.value))
    return found


def import_graph(root: Path = RAILWAY):
    """``{module: {imported module: first line}}`` over the railway modules."""
    mods = module_names(root)
    graph = {}
    for name, path in mods.items():
        edges = {}
        for line, target in imported_modules(path.read_text(encoding="utf-8"), name,
                                             path.name == "__init__.py", set(mods)):
            if target != name:
                edges.setdefault(target, line)
        graph[name] = edges
    return graph


def cycles(graph) -> list[set[str]]:
    """Strongly connected components with more than one module (Tarjan), over known modules."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = set()
            while True:
                w = stack.pop()
                on.discard(w)
                comp.add(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(comp)

    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, 10 * len(graph) + 100))
    try:
        for v in graph:
            if v not in index:
                visit(v)
    finally:
        sys.setrecursionlimit(limit)
    return out


def test_checker_sees_function_level_imports_and_finds_circles():
    """Guards against a vacuous rule: the walk resolves relative and lazy imports."""
    src = (
        "from ..contact.search import ContactSearch\n"
        "from . import wheel_rail_rules\n"
        "def f():\n"
        "    from .vehicle import GRAVITY\n"
        "    import importlib\n"
        "    importlib.import_module('railway.track')\n"
    )
    known = {"railway.contact.search", "railway.vehicles.wheel_rail_rules", "railway.vehicles.vehicle",
             "railway.track", "railway.vehicles"}
    got = {t for _, t in imported_modules(src, "railway.vehicles.x", False, known)}
    assert got == known - {"railway.vehicles"}
    assert cycles({"a": {"b": 1}, "b": {"c": 1}, "c": {"a": 1}, "d": {"a": 1}}) == [{"a", "b", "c"}]


def test_the_graph_holds_the_edges_we_know():
    g = import_graph()
    assert "railway.contact.search.contact_search" in g["railway.vehicles.wheel_rail"] or \
        "railway.contact.search" in g["railway.vehicles.wheel_rail"]
    assert "railway.vehicles.wheel_rail" in g["railway.vehicles.wheel_rail_compiled"]
    # the numpy force element reaches its kernels by registration, not by an import back
    assert "railway.vehicles.wheel_rail_compiled" not in g["railway.vehicles.wheel_rail"]


def test_no_import_cycles():
    found = [c for c in cycles(import_graph()) if c not in ALLOWED_CYCLES]
    assert found == [], f"import circles in railway/: {found}"


def test_contact_never_imports_vehicles():
    bad = [f"{m}:{line} imports {t}" for m, edges in import_graph().items() if m.startswith("railway.contact")
           for t, line in edges.items() if t == "railway.vehicles" or t.startswith("railway.vehicles.")]
    assert bad == []


def test_no_railway_module_imports_an_old_path():
    from railway.moved_modules import MOVED

    bad = [f"{m}:{line} imports {t} (moved to {MOVED[t]})" for m, edges in import_graph().items()
           for t, line in edges.items() if t in MOVED]
    assert bad == []
