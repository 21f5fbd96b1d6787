"""Imports inside ``hiper_cli/perceive`` flow one way: no module imports itself through others.

Module-level imports, those that run when a module is loaded (under ``if TYPE_CHECKING:`` they
are for annotations; inside a function, loaded on first use). Issue 53: seven foreground
modules once imported each other in a cycle, so none could be read alone.
"""

from __future__ import annotations

import ast
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
PERCEIVE = REPO / "hiper_cli" / "perceive"


def _module_name(path: Path) -> str:
    return ".".join(path.relative_to(REPO).with_suffix("").parts).removesuffix(".__init__")


def import_graph(root: Path, lazy: bool = False) -> dict[str, set[str]]:
    """Module -> the modules under ``root`` it imports when it is loaded (``lazy``: or inside
    a function)."""
    paths = {_module_name(p): p for p in root.rglob("*.py")}
    graph: dict[str, set[str]] = {m: set() for m in paths}
    for module, path in paths.items():
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.dump(node.test):
                continue
            loaded = isinstance(node, (ast.Import, ast.ImportFrom, ast.If, ast.Try))
            for item in ast.walk(node) if lazy or loaded else ():
                if isinstance(item, ast.ImportFrom) and item.module:
                    targets = [item.module, *(f"{item.module}.{a.name}" for a in item.names)]
                elif isinstance(item, ast.Import):
                    targets = [a.name for a in item.names]
                else:
                    continue
                graph[module].update(t for t in targets if t in paths and t != module)
    return graph


def cycles(graph: dict[str, set[str]]) -> list[set[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    out: list[set[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = set()
            while True:
                w = stack.pop()
                component.add(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(component)

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_the_cycle_finder_finds_a_cycle():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [{"a", "b", "c"}]
    assert cycles({"a": {"b"}, "b": set()}) == []


def test_no_import_cycle_in_perceive():
    graph = import_graph(PERCEIVE)
    assert "hiper_cli.perceive.foreground.stage" in graph
    assert "hiper_cli.perceive.foreground.tracking" in graph["hiper_cli.perceive.foreground.stage"]
    assert cycles(graph) == []


def test_no_import_cycle_in_the_foreground_even_through_imports_inside_functions():
    graph = import_graph(PERCEIVE / "foreground", lazy=True)
    assert "hiper_cli.perceive.foreground.tracking" in graph["hiper_cli.perceive.foreground.stage"]
    assert cycles(graph) == []
