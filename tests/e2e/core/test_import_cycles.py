"""No import cycle inside hiyari: the modules' imports, lazy ones inside functions included
(they run too, only later), form a graph without cycles; imports under ``if TYPE_CHECKING:``
are left out (they never run)."""

from __future__ import annotations

import ast
from pathlib import Path

from paths import REPO_ROOT

#: Top folders of the repository as the installed packages (pyproject's package-dir).
PACKAGES = {"hiyari": "hiyari", "net": "hiyari.net", "traffic": "hiyari.traffic",
            "sensors": "hiyari.sensors", "risk": "hiyari.risk", "bridge": "hiyari.bridge"}  # fmt: skip


def _modules() -> dict[str, Path]:
    """Every module of the package by its dotted name."""
    out = {}
    for folder, package in PACKAGES.items():
        for path in sorted((REPO_ROOT / folder).rglob("*.py")):
            parts = path.relative_to(REPO_ROOT / folder).with_suffix("").parts
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join((package, *parts))] = path
    return out


def _is_type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def _runtime_imports(tree: ast.AST, module: str, known: dict[str, Path]) -> set[str]:
    """The hiyari modules ``tree`` imports when it runs (``from a import b``: module a.b when
    there is one, else a; relative imports resolved against ``module``)."""
    found: set[str] = set()

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and _is_type_checking(node):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                is_pkg = known[module].name == "__init__.py"
                anchor = module.split(".")[: len(module.split(".")) - node.level + is_pkg]
                base = ".".join([*anchor, *([base] if base else [])])
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                found.add(sub if sub in known else base)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return {name for name in found if name in known and name != module}


def _cycles(graph: dict[str, set[str]]) -> list[frozenset[str]]:
    """The import cycles of ``graph``: its strongly connected parts of more than one module
    (Tarjan's algorithm), each as the set of its modules."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    out = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        for nxt in sorted(graph[node]):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            part = stack[stack.index(node) :]
            del stack[stack.index(node) :]
            if len(part) > 1:
                out.append(frozenset(part))

    for start in sorted(graph):
        if start not in index:
            visit(start)
    return out


#: Cycles there were when this test came, to be broken (the list only shrinks): the reader's
#: positions and trajectories follow the format's recursion (a RoutePosition holds a route of
#: positions: one module, or the reader of each passed to the other).
KNOWN = {
    frozenset({"hiyari.bridge.openscenario.xosc.elements.read_positions",
               "hiyari.bridge.openscenario.xosc.elements.read_trajectories"}),
}  # fmt: skip


def test_no_runtime_import_cycle_inside_hiyari():
    known = _modules()
    graph = {
        name: _runtime_imports(ast.parse(path.read_text(encoding="utf-8")), name, known)
        for name, path in known.items()
    }
    cycles = set(_cycles(graph))
    assert cycles <= KNOWN, [sorted(c) for c in cycles - KNOWN]
    assert KNOWN <= cycles, f"broken, take them off KNOWN: {[sorted(c) for c in KNOWN - cycles]}"


def test_a_cycle_is_found_and_type_checking_imports_are_not():
    """The check itself: a lazy import back is a cycle, one under TYPE_CHECKING is not."""
    known = {"hiyari.a": Path("a.py"), "hiyari.b": Path("b.py")}
    a = ast.parse("from hiyari.b import f\n")
    lazy = ast.parse("def g():\n    from hiyari import a\n")
    typed = ast.parse("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import hiyari.a\n")
    graph = {"hiyari.a": _runtime_imports(a, "hiyari.a", known)}
    assert graph == {"hiyari.a": {"hiyari.b"}}
    graph["hiyari.b"] = _runtime_imports(lazy, "hiyari.b", known)
    assert _cycles(graph) == [frozenset({"hiyari.a", "hiyari.b"})]
    graph["hiyari.b"] = _runtime_imports(typed, "hiyari.b", known)
    assert _cycles(graph) == []
