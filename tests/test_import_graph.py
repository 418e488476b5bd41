"""The package's import graph has no circles, counting imports inside functions too."""

from __future__ import annotations

import ast
from pathlib import Path

import hiab_sim

PACKAGE = Path(hiab_sim.__file__).resolve().parent


def _modules(root: Path) -> dict[str, Path]:
    """Dotted module name -> file for every module of the package (a package is its __init__)."""
    out = {}
    for path in root.rglob("*.py"):
        parts = list(path.relative_to(root.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _import_graph(root: Path) -> dict[str, set[str]]:
    """Module -> the package's modules it imports anywhere in its source (module level or in functions)."""
    modules = _modules(root)
    package = root.name

    def resolve(name: str) -> str | None:
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name or None

    graph: dict[str, set[str]] = {name: set() for name in modules}
    for name, path in modules.items():
        is_package = path.name == "__init__.py"
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = name.split(".") if is_package else name.split(".")[:-1]
                    anchor = anchor[: len(anchor) - (node.level - 1)]
                    base = ".".join(anchor + ([base] if base else []))
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names]
            for target in targets:
                found = resolve(target) if target.split(".")[0] == package else None
                if found and found != name:
                    graph[name].add(found)
    return graph


def _components(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan): the import circles."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                components.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return components


def _circles(root: Path) -> list[list[str]]:
    """Import circles of the package at ``root``, less a package ``__init__`` with one re-exported child.

    A package's ``__init__`` that re-exports a submodule, which in turn names a sibling through the
    package path, is the only two-module component that is not a circle of design.
    """
    modules = _modules(root)

    def reexport_only(component: list[str]) -> bool:
        packages = [c for c in component if modules[c].name == "__init__.py"]
        return len(component) == 2 and len(packages) == 1 and all(c.startswith(packages[0]) for c in component)

    return [c for c in _components(_import_graph(root)) if not reexport_only(c)]


def _mutually_reachable(graph: dict[str, set[str]]) -> set[frozenset[str]]:
    """Groups of modules that reach each other, by brute-force reachability (an independent check)."""

    def reach(start: str) -> set[str]:
        seen: set[str] = set()
        todo = [start]
        while todo:
            for w in graph[todo.pop()]:
                if w not in seen:
                    seen.add(w)
                    todo.append(w)
        return seen

    reachable = {v: reach(v) for v in graph}
    groups = {frozenset({v, *(w for w in graph if w in reachable[v] and v in reachable[w])}) for v in graph}
    return {g for g in groups if len(g) > 1}


def test_finder_sees_a_circle_hidden_inside_a_function(tmp_path: Path) -> None:
    """A circle closed by an import inside a function is found; a module that only imports it is not in it."""
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "a.py").write_text("from pkg.b import g\n")
    (package / "b.py").write_text("def g():\n    from . import a\n    return a\n")
    (package / "c.py").write_text("import pkg.a\n")
    (package / "d.py").write_text("from .c import x\n")
    graph = _import_graph(package)
    assert graph["pkg.b"] == {"pkg.a"} and graph["pkg.d"] == {"pkg.c"}
    assert _circles(package) == [["pkg.a", "pkg.b"]]
    assert {frozenset(c) for c in _components(graph)} == _mutually_reachable(graph)


def test_package_has_no_import_circles() -> None:
    """No module of hiab_sim reaches itself through imports, including imports inside functions."""
    circles = _circles(PACKAGE)
    assert not circles, "import circles: " + "; ".join(" <-> ".join(c) for c in circles)
