"""Imports flow one way: perceive -> graph -> analyze -> query/serve -> cli (STYLE.md, 2).

Every package and top-level module of ``hiper_cli`` has a rule here, so a new package must say
where it sits before its first test run passes. A rule lists what its modules may not import.
"""

import ast
import pathlib

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "hiper_cli"

_UI = ("hiper_cli.commands", "hiper_cli.cli", "hiper_cli.cmdline", "hiper_cli.render", "typer", "rich")
_ABOVE_PERCEIVE = ("hiper_cli.graph", "hiper_cli.analyze", "hiper_cli.query", "hiper_cli.pipeline",
                   "hiper_cli.reanchor", "hiper_cli.sim", "hiper_cli.evaluate", "hiper_cli.view",
                   "hiper_cli.agent", "hiper_cli.mcp", "hiper_cli.qa")
_CORE_FORBIDDEN = ("hiper_cli.perceive", *_ABOVE_PERCEIVE, *_UI)

# package (folder) or module (file stem) -> prefixes its modules may not import
FORBIDDEN: dict[str, tuple[str, ...]] = {
    # the core: entities and errors every layer shares
    "types": _CORE_FORBIDDEN,
    "model": _CORE_FORBIDDEN,
    "errors": _CORE_FORBIDDEN,
    # shared checks and safe file writes every layer may use
    "validate": _CORE_FORBIDDEN,
    "files": _CORE_FORBIDDEN,
    # the log's clock: how a stamp is shown (log time or ISO 8601 UTC)
    "clock": _CORE_FORBIDDEN,
    # the typed learned features: analyze writes them, perceive reads them
    "learned": _CORE_FORBIDDEN,
    # recognition: log readers (the simulator's truth format included), stages, detectors
    "perceive": (*_ABOVE_PERCEIVE, *_UI, "matplotlib", "rerun"),
    # the knowledge base stores what perceive produced
    "graph": ("hiper_cli.analyze", "hiper_cli.query", "hiper_cli.serve", "hiper_cli.pipeline",
              "hiper_cli.reanchor", "hiper_cli.sim", "hiper_cli.evaluate", "hiper_cli.view", *_UI, "rerun"),
    # interpretation of a knowledge base
    "analyze": ("hiper_cli.query", "hiper_cli.pipeline", "hiper_cli.reanchor", "hiper_cli.sim",
                "hiper_cli.view", *_UI, "rerun"),
    # hiper view: draws what a KB holds (perceive types, graph), after graph; never the CLI
    "view": ("hiper_cli.query", "hiper_cli.pipeline", "hiper_cli.reanchor", "hiper_cli.sim",
             "hiper_cli.evaluate", *_UI),
    # questions over perceive types, the graph and the analyses
    "query": ("hiper_cli.serve", "hiper_cli.pipeline", "hiper_cli.reanchor", "hiper_cli.sim",
              "hiper_cli.evaluate", "hiper_cli.view", "hiper_cli.agent", "hiper_cli.mcp", "hiper_cli.qa",
              *_UI),
    # the SPARQL endpoint over a knowledge base's graph
    "serve": ("hiper_cli.query", "hiper_cli.pipeline", "hiper_cli.reanchor", "hiper_cli.sim",
              "hiper_cli.evaluate", "hiper_cli.view", *_UI),
    # the agent tools: the query verbs and analyses as named, schema'd, read-only tools
    "agent": ("hiper_cli.mcp", "hiper_cli.qa", "hiper_cli.pipeline", "hiper_cli.reanchor", "hiper_cli.sim",
              "hiper_cli.evaluate", "hiper_cli.view", "hiper_cli.serve", *_UI, "mcp"),
    # hiper mcp: the agent tools over the Model Context Protocol (the only user of the mcp SDK)
    "mcp": ("hiper_cli.qa", "hiper_cli.pipeline", "hiper_cli.reanchor", "hiper_cli.sim",
            "hiper_cli.evaluate", "hiper_cli.view", *_UI),
    # hiper eval qa: questions from a log's truth, asked through the query layer, scored
    "qa": ("hiper_cli.agent", "hiper_cli.mcp", "hiper_cli.serve", "hiper_cli.view", *_UI),
    # the simulator writes logs (perceive.logs writers), never reads a knowledge base
    "sim": ("hiper_cli.graph", "hiper_cli.analyze", "hiper_cli.query", "hiper_cli.pipeline",
            "hiper_cli.reanchor", "hiper_cli.evaluate", *_UI),
    # sensor profiles: what a real camera and pose source make of a log (reads and writes logs)
    "sensor": ("hiper_cli.graph", "hiper_cli.analyze", "hiper_cli.query", "hiper_cli.pipeline",
               "hiper_cli.reanchor", "hiper_cli.sim", "hiper_cli.evaluate", *_UI),
    # scoring perception against simulator truth
    "evaluate": ("hiper_cli.graph", "hiper_cli.analyze", "hiper_cli.query", "hiper_cli.pipeline",
                 "hiper_cli.reanchor", *_UI),
    # runs of perception into a knowledge base
    "pipeline": ("hiper_cli.analyze", "hiper_cli.query", "hiper_cli.sim", "hiper_cli.evaluate", *_UI),
    # live runs of perception into a knowledge base (a robot on rmw_zenoh)
    "live": ("hiper_cli.analyze", "hiper_cli.query", "hiper_cli.sim", "hiper_cli.evaluate", *_UI),
    "reanchor": ("hiper_cli.analyze", "hiper_cli.query", "hiper_cli.sim", "hiper_cli.evaluate", *_UI),
    # a session's log aligned to its place's map before perception (a part of the pipeline)
    "session_align": ("hiper_cli.analyze", "hiper_cli.query", "hiper_cli.sim", "hiper_cli.evaluate", *_UI),
    # hiper bench: simulates, perceives, scores and runs tasks on top of all the library
    "bench": ("hiper_cli.serve", "hiper_cli.view", "hiper_cli.reanchor", *_UI),
    # how results look on a terminal (rich): shows result dicts, never parses a command line
    "render": ("hiper_cli.commands", "hiper_cli.cli", "hiper_cli.cmdline", "typer", "click"),
    # the command line's shared parts (typer): app class, shared options, usage errors
    "cmdline": ("hiper_cli.commands", "hiper_cli.cli"),
    # the command line sits on top of everything
    "commands": (),
    "cli": (),
    "__init__": ("hiper_cli.",),
    "__main__": (),
}


def _imports(path: pathlib.Path) -> set[str]:
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
    return names


def _units() -> list[str]:
    return sorted(p.stem if p.is_file() else p.name for p in PACKAGE.iterdir()
                  if (p.is_file() and p.suffix == ".py") or (p.is_dir() and (p / "__init__.py").exists()))


def _modules(unit: str) -> list[pathlib.Path]:
    folder = PACKAGE / unit
    return sorted(folder.rglob("*.py")) if folder.is_dir() else [PACKAGE / f"{unit}.py"]


def test_every_package_has_a_rule():
    missing = [unit for unit in _units() if unit not in FORBIDDEN]
    assert not missing, f"add an import rule to FORBIDDEN for {missing}"


@pytest.mark.parametrize("unit", _units())
def test_imports_flow_one_way(unit):
    forbidden = FORBIDDEN[unit]
    offenders = [
        f"{path.relative_to(PACKAGE)} imports {name}"
        for path in _modules(unit)
        for name in _imports(path)
        if forbidden and name.startswith(forbidden)
    ]
    assert not offenders, "\n".join(offenders)


def test_query_rule_allows_what_it_builds_on():
    """The coming query layer may read perceive types, the graph and the analyses."""
    for allowed in ("hiper_cli.perceive.logs", "hiper_cli.graph", "hiper_cli.analyze", "hiper_cli.model"):
        assert not allowed.startswith(FORBIDDEN["query"])
    for denied in ("hiper_cli.commands._common", "hiper_cli.cli", "typer", "rich.table"):
        assert denied.startswith(FORBIDDEN["query"])


def test_view_rule_allows_what_it_draws_from():
    """hiper view reads perceive types and the graph, and is itself imported by no stage below it."""
    for allowed in ("hiper_cli.perceive.logs", "hiper_cli.graph", "hiper_cli.model", "rerun"):
        assert not allowed.startswith(FORBIDDEN["view"])
    for below in ("perceive", "graph", "analyze", "query"):
        assert "hiper_cli.view".startswith(FORBIDDEN[below])


def test_only_the_cli_imports_the_bench():
    """The benchmark sits on top: no library unit imports it."""
    for unit in FORBIDDEN:
        if unit in ("bench", "commands", "cli", "__main__"):
            continue
        offenders = [p for p in _modules(unit) if any(n.startswith("hiper_cli.bench") for n in _imports(p))]
        assert not offenders, f"{unit} imports hiper_cli.bench: {offenders}"


def _imports_within(folder: pathlib.Path, prefix: str) -> dict[str, set[str]]:
    """Module -> the modules of ``prefix`` it imports, type-only imports included."""
    graph: dict[str, set[str]] = {}
    for path in folder.rglob("*.py"):
        name = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts).removesuffix(".__init__")
        graph[name] = {
            node.module for node in ast.walk(ast.parse(path.read_text()))
            if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith(prefix)
        }
    return graph


def test_the_foreground_stage_has_no_import_cycle():
    """Issue 53: its parts import the track (``track.py``), not the tracker that runs them."""
    graph = _imports_within(PACKAGE / "perceive" / "foreground", "hiper_cli.perceive.foreground")
    done: set[str] = set()

    def visit(name: str, path: tuple[str, ...]) -> None:
        if name in path:
            raise AssertionError(f"import cycle: {' -> '.join((*path[path.index(name):], name))}")
        if name in done:
            return
        for dep in sorted(graph.get(name, ())):
            visit(dep, (*path, name))
        done.add(name)

    for name in sorted(graph):
        visit(name, ())
