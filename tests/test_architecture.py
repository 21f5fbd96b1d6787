"""Imports flow one way: perceive -> graph -> analyze -> query/serve -> cli (STYLE.md, 2).

``LAYERS`` puts every package and top-level module of ``hiper_cli`` (a unit) in a layer, lowest
first. A unit imports only units of lower layers: never one of its own layer, never one above.
The order is the whole rule; there are no exemptions. A new package must take its place here
before its first test run passes (docs/architecture.md draws the same order).

Beside the layers: the side branches only some may import (the simulator, the benchmark), the
third-party packages only some may import, no import cycle between modules or packages, and no
private name (``_x``) imported from another package. Imports inside functions and under
``TYPE_CHECKING`` count like any other: a cycle hidden in a function is still a cycle.
"""

from __future__ import annotations

import ast
import pathlib
from collections.abc import Iterator

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "hiper_cli"

LAYERS: tuple[tuple[str, ...], ...] = (
    ("__init__", "errors"),  # the package's version, the exception hierarchy: import nothing
    ("types", "model", "validate", "files", "clock"),  # the core: entities and checks every layer shares
    ("learned",),  # the typed learned features: analyze writes them, perceive reads them
    ("perceive",),  # recognition: log readers (the simulator's truth format included), stages, detectors
    ("sensor",),  # sensor profiles: what a real camera and pose source make of a log
    ("sim",),  # the simulator writes logs, never reads a knowledge base
    ("graph",),  # the knowledge base: documents, scene graph, ontology, export
    ("session_align", "reanchor"),  # a session aligned into its place; observations re-anchored
    ("pipeline",),  # runs of perception into a knowledge base
    ("live",),  # live runs of perception into a knowledge base (a robot on rmw_zenoh)
    ("evaluate",),  # perception runs and knowledge bases scored against ground truth
    ("analyze",),  # interpretation: features, heatmaps, costmaps; the feedback of features
    ("view", "query", "serve"),  # drawing a knowledge base; questions over it; its SPARQL endpoint
    ("agent",),  # the query verbs and analyses as named, schema'd, read-only tools
    ("mcp", "qa"),  # the tools over MCP; questions from a log's truth, asked and scored
    ("bench",),  # simulates, perceives, scores and runs tasks on top of all the library
    ("render",),  # how results look on a terminal (rich): shows result dicts, parses no command line
    ("cmdline",),  # the command line's shared parts (typer): app class, shared options, usage errors
    ("commands",),  # one module per command: parse options, call the library, render
    ("cli",),  # the app
    ("__main__",),  # ``python -m hiper_cli``
)
RANK = {unit: k for k, layer in enumerate(LAYERS) for unit in layer}

# side branches: a unit here is imported only by the units named, though a layer above may sit
# beside it (the graph is above the simulator in the order, and still never runs it)
ONLY_IMPORTED_BY: dict[str, tuple[str, ...]] = {
    "sensor": ("sim", "commands"),
    "sim": ("bench", "commands"),
    "bench": ("commands",),
    "render": ("cmdline", "commands", "cli"),
    "cmdline": ("commands", "cli"),
    "commands": ("cli",),
}
# third-party packages only these units import: the maths never draws, prints or serves; only
# graph/ touches the stores (DESIGN.md, "Only graph/ touches the stores")
THIRD_PARTY: dict[str, tuple[str, ...]] = {
    "typer": ("cmdline", "commands", "cli"),
    "click": ("cmdline", "commands", "cli"),
    "rich": ("render", "commands", "cli"),
    "matplotlib": ("analyze", "bench", "commands"),
    "rerun": ("view", "commands"),
    "mcp": ("mcp",),
    "sqlite3": ("graph",),
    "pyoxigraph": ("graph",),
}


def _module_name(path: pathlib.Path) -> str:
    return ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts).removesuffix(".__init__")


def _package_of(path: pathlib.Path) -> str:
    name = _module_name(path)
    return name if path.name == "__init__.py" else name.rpartition(".")[0]


MODULES = {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _imported(path: pathlib.Path, source: str | None = None) -> Iterator[tuple[str, str | None]]:
    """(module, name) per imported name; name is None for ``import x``. Relative imports are
    resolved against ``path``'s package."""
    for node in ast.walk(ast.parse(path.read_text() if source is None else source)):
        if isinstance(node, ast.Import):
            yield from ((alias.name, None) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            module = node.module or ""
            if node.level:
                base = _package_of(path).split(".")
                base = base[: len(base) - node.level + 1]
                module = ".".join([*base, module] if module else base)
            yield from ((module, alias.name) for alias in node.names)


def _targets(path: pathlib.Path, source: str | None = None) -> set[str]:
    """The ``hiper_cli`` modules ``path`` imports: ``from pkg import sub`` is the submodule."""
    out: set[str] = set()
    for module, name in _imported(path, source):
        sub = f"{module}.{name}"
        if sub in MODULES:
            out.add(sub)
        elif module in MODULES:
            out.add(module)
    out.discard(_module_name(path))
    return out


def _unit_of(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _units() -> list[str]:
    return sorted(p.stem if p.is_file() else p.name for p in PACKAGE.iterdir()
                  if (p.is_file() and p.suffix == ".py") or (p.is_dir() and (p / "__init__.py").exists()))


def _paths(unit: str) -> list[pathlib.Path]:
    folder = PACKAGE / unit
    return sorted(folder.rglob("*.py")) if folder.is_dir() else [PACKAGE / f"{unit}.py"]


def layer_offences(unit: str, path: pathlib.Path, source: str | None = None) -> list[str]:
    """The imports of ``path`` (of ``unit``) that break the order or a side branch."""
    out = []
    for target in sorted(_targets(path, source)):
        other = _unit_of(target)
        if other == unit:
            continue
        if RANK[other] >= RANK[unit]:
            where = "its own layer" if RANK[other] == RANK[unit] else "a higher layer"
            out.append(f"{path.relative_to(PACKAGE)} imports {target} ({other}: {where})")
        elif unit not in ONLY_IMPORTED_BY.get(other, (unit,)):
            out.append(f"{path.relative_to(PACKAGE)} imports {target} (only {ONLY_IMPORTED_BY[other]} may)")
    for module, _ in _imported(path, source):
        top = module.split(".")[0]
        if top in THIRD_PARTY and unit not in THIRD_PARTY[top]:
            out.append(f"{path.relative_to(PACKAGE)} imports {module} (only {THIRD_PARTY[top]} may)")
    return out


def private_offences(path: pathlib.Path, source: str | None = None) -> list[str]:
    """``from hiper_cli.a.b import _name`` (or a ``_module``) where the private part belongs to a
    package other than the importer's (or one above it)."""
    importer = _package_of(path)
    out = []
    for module, name in _imported(path, source):
        parts = [*module.split("."), *([name] if name else [])]
        if parts[0] != "hiper_cli":
            continue
        private = next((k for k, p in enumerate(parts) if p.startswith("_") and not p.startswith("__")), None)
        if private is None:
            continue
        owner = ".".join(parts[:private])
        is_package = (PACKAGE.parent / owner.replace(".", "/")).is_dir()
        owner_package = owner if is_package else owner.rpartition(".")[0]
        if importer != owner_package and not importer.startswith(owner_package + "."):
            out.append(f"{path.relative_to(PACKAGE)}: from {module} import {name} "
                       f"(private to {owner_package})")
    return out


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` (node -> the nodes it imports), or None."""
    done: set[str] = set()
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        if node in path:
            return [*path[path.index(node):], node]
        if node in done:
            return None
        path.append(node)
        for dep in sorted(graph.get(node, ())):
            found = visit(dep)
            if found:
                return found
        path.pop()
        done.add(node)
        return None

    for node in sorted(graph):
        found = visit(node)
        if found:
            return found
    return None


def _module_graph() -> dict[str, set[str]]:
    return {name: _targets(path) for name, path in MODULES.items()}


def test_every_package_has_a_layer():
    missing = [unit for unit in _units() if unit not in RANK]
    assert not missing, f"put {missing} in a layer of LAYERS"
    assert len(RANK) == sum(len(layer) for layer in LAYERS), "a unit sits in two layers"


@pytest.mark.parametrize("unit", _units())
def test_imports_flow_one_way(unit):
    offenders = [o for path in _paths(unit) for o in layer_offences(unit, path)]
    assert not offenders, "\n".join(offenders)


def test_no_private_name_of_another_package_is_imported():
    offenders = [o for path in MODULES.values() for o in private_offences(path)]
    assert not offenders, "\n".join(offenders)


def test_no_module_imports_itself_round_a_cycle():
    cycle = _cycle(_module_graph())
    assert cycle is None, "import cycle: " + " -> ".join(cycle or [])


def test_no_package_imports_itself_round_a_cycle():
    """Between sibling packages (``perceive.detect`` and ``perceive.foreground``, ...): a package
    and its own subpackages are one concept and may import each other's modules."""
    graph: dict[str, set[str]] = {}
    for name, targets in _module_graph().items():
        here = _package_of(MODULES[name])
        for target in targets:
            there = _package_of(MODULES[target])
            if not (here == there or here.startswith(there + ".") or there.startswith(here + ".")):
                graph.setdefault(here, set()).add(there)
    cycle = _cycle(graph)
    assert cycle is None, "package import cycle: " + " -> ".join(cycle or [])


def test_the_rules_fail_on_planted_imports():
    """The checks catch what they are for: the simulator imported by perceive, the CLI by the
    maths, a private helper across packages, a cycle."""
    stage = PACKAGE / "perceive" / "stage.py"
    assert layer_offences("perceive", stage, "from hiper_cli.sim import simulate\n")
    assert layer_offences("perceive", stage, "def f():\n    import hiper_cli.graph.kb\n")
    assert layer_offences("graph", PACKAGE / "graph" / "kb.py", "from hiper_cli import sim\n")
    assert layer_offences("analyze", PACKAGE / "analyze" / "stats.py", "import rich\n")
    assert not layer_offences("query", PACKAGE / "query" / "ask.py", "from hiper_cli.graph import open_kb\n")
    feedback = PACKAGE / "analyze" / "feedback.py"
    assert private_offences(feedback, "from hiper_cli.evaluate.foreground import _score\n")
    assert private_offences(feedback, "from hiper_cli.perceive.logs import _private_module\n")
    same_package = PACKAGE / "evaluate" / "kb.py"
    assert not private_offences(same_package, "from hiper_cli.evaluate.scene import _match\n")
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set()}) is None


def test_query_builds_on_what_is_below_it():
    """The query layer reads perceive types, the graph and the analyses; never the CLI."""
    for allowed in ("perceive", "graph", "analyze", "model"):
        assert RANK[allowed] < RANK["query"]
    for denied in ("commands", "cli", "serve", "agent", "mcp", "qa"):
        assert RANK[denied] >= RANK["query"]


def test_view_sits_above_what_it_draws():
    """hiper view reads perceive types and the graph, and no stage below it imports it."""
    for below in ("perceive", "graph", "analyze"):
        assert RANK[below] < RANK["view"]
    assert RANK["query"] == RANK["view"]
