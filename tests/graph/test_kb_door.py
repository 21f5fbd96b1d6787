"""The knowledge base behind one door: only ``hiper_cli/graph/`` touches SQLite, Oxigraph or the
store's internals, and the API that docs/kb.md documents works as its examples show (each
``python`` block of its "The API" part runs here against a small knowledge base)."""

import ast
import pathlib
import re

import numpy as np
import pytest

from tests import REPO_ROOT
from tests.kb_helpers import small_kb

ROOT = REPO_ROOT
PACKAGE = ROOT / "hiper_cli"
DOC = ROOT / "docs" / "kb.md"

STORE_MODULES = ("sqlite3", "pyoxigraph")
# graph modules that are the store itself: nothing outside graph/ imports them
STORE_INTERNALS = ("hiper_cli.graph.sqlite_guard", "hiper_cli.graph.scenegraph", "hiper_cli.graph.sync",
                   "hiper_cli.graph.track_cache", "hiper_cli.graph.trajectories", "hiper_cli.graph.changes",
                   "hiper_cli.graph.lookups", "hiper_cli.graph.codec", "hiper_cli.graph.grid")
STORE_NAMES = {"DocumentStore", "GuardedConnection", "LocalGraph", "SparqlGraph", "DetachedGraph"}
# a knowledge base's stores, as attributes of it
STORE_ATTRIBUTES = {"docs", "graph", "connection", "_db"}


def _offences(path: pathlib.Path) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found += [f"imports {a.name}" for a in node.names if a.name.split(".")[0] in STORE_MODULES
                      or a.name.startswith(STORE_INTERNALS)]
        elif isinstance(node, ast.ImportFrom) and node.module:
            if node.module.split(".")[0] in STORE_MODULES or node.module.startswith(STORE_INTERNALS):
                found.append(f"imports {node.module}")
            found += [f"imports {a.name} from {node.module}" for a in node.names
                      if node.module.startswith("hiper_cli.graph") and a.name in STORE_NAMES]
        elif isinstance(node, ast.Attribute) and node.attr in STORE_ATTRIBUTES:
            found.append(f"line {node.lineno}: .{node.attr}")
    return found


def _outside_graph() -> list[pathlib.Path]:
    return [p for p in sorted(PACKAGE.rglob("*.py")) if p.relative_to(PACKAGE).parts[0] != "graph"]


def test_nothing_outside_graph_reaches_the_stores():
    """No sqlite3 or pyoxigraph import, no store module or type, no ``.docs``/``.graph``/
    ``.connection`` of a knowledge base anywhere outside ``graph/``. (The rosbag2 readers in
    perceive/logs read a log format, not the knowledge base; they go through ``rosbags``.)"""
    offenders = [f"{p.relative_to(PACKAGE)}: {o}" for p in _outside_graph() for o in _offences(p)]
    assert not offenders, "\n".join(offenders)


def test_the_check_catches_a_planted_reach_around(tmp_path):
    planted = tmp_path / "planted.py"
    planted.write_text("import sqlite3\nfrom pyoxigraph import Store\n"
                       "from hiper_cli.graph.documents import DocumentStore\n"
                       "def f(kb):\n    return kb.docs.find(type='instance'), kb.graph.query('')\n")
    assert len(_offences(planted)) == 5


def _api_blocks() -> list[str]:
    text = DOC.read_text()
    api = text[text.index("## The API"):]
    api = api[: api.index("\n## ", 4)] if "\n## " in api[4:] else api
    return re.findall(r"```python\n(.*?)```", api, flags=re.S)


def test_docs_kb_md_shows_the_api():
    assert len(_api_blocks()) >= 5


@pytest.mark.parametrize("block", range(len(_api_blocks())))
def test_the_api_examples_of_docs_kb_md_run(tmp_path, block):
    """Each example runs against the small knowledge base as ``kb``; its ``assert`` lines are
    the documented answers."""
    kb = small_kb(tmp_path / "flat.hiper")
    try:
        exec(compile(_api_blocks()[block], f"docs/kb.md block {block}", "exec"),
             {"kb": kb, "np": np, "tmp_path": tmp_path})
    finally:
        kb.close()
