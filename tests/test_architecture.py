"""Imports flow one way: perceive -> graph -> analyze -> query/serve -> cli (STYLE.md, 2)."""

import ast
import pathlib

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "hiper_cli"
# A module in the key package may not import from any of the listed packages.
FORBIDDEN = {
    "perceive": ("hiper_cli.graph", "hiper_cli.analyze", "hiper_cli.commands", "hiper_cli.cli",
                 "hiper_cli.pipeline", "typer", "rich", "matplotlib"),
    "graph": ("hiper_cli.analyze", "hiper_cli.commands", "hiper_cli.cli", "typer", "rich"),
    "analyze": ("hiper_cli.commands", "hiper_cli.cli", "typer", "rich"),
}


def _imports(path: pathlib.Path) -> set[str]:
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
    return names


def test_imports_flow_one_way():
    offenders = []
    for package, forbidden in FORBIDDEN.items():
        for path in (PACKAGE / package).rglob("*.py"):
            for name in _imports(path):
                if name.startswith(forbidden):
                    offenders.append(f"{path.relative_to(PACKAGE)} imports {name}")
    assert not offenders, "\n".join(offenders)


def test_core_types_import_no_stage():
    for module in ("types.py", "model.py", "errors.py"):
        for name in _imports(PACKAGE / module):
            assert not name.startswith(("hiper_cli.perceive", "hiper_cli.graph", "hiper_cli.analyze"))
