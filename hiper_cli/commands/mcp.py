"""``hiper mcp``: a Model Context Protocol server over a knowledge base, stdio or HTTP (``mcp.run``)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.cmdline import DEFAULT_KB, HiperTyper, Kb, KbDocs
from hiper_cli.render.serve import show_mcp_ready

__all__ = ["register"]

Http = Annotated[str | None, typer.Option(
    "--http", help="Serve streamable HTTP at HOST:PORT (path /mcp) instead of stdio.")]
OutDir = Annotated[Path | None, typer.Option(
    "--out", "-o", help="Folder for the heatmap tool's files (default: a temp dir).")]
Timeout = Annotated[float, typer.Option(
    "--timeout", help="Give up on a sparql tool query after this many seconds.")]


def mcp_command(kb: Kb = DEFAULT_KB, kb_docs: KbDocs = None, http: Http = None, out_dir: OutDir = None,
                timeout_s: Timeout = 30.0) -> None:
    """Serve the query verbs as MCP tools (find, count, last_seen, when, trajectory, workspace,
    describe, features, heatmap, sparql, ask) and resources (vocabulary, summary); read-only.
    Needs the mcp extra: pip install 'hiper\\[mcp]'.

    Example: hiper mcp --kb house.hiper   (stdio; or --http 127.0.0.1:8765)
    """
    from hiper_cli.mcp.run import serve_mcp

    serve_mcp(kb, docs_dir=kb_docs, http=http, out_dir=out_dir, timeout_s=timeout_s, on_ready=show_mcp_ready)


def register(app: HiperTyper) -> None:
    app.command(name="mcp")(mcp_command)
