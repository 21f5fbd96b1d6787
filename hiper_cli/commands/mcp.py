"""``hiper mcp``: a Model Context Protocol server over a knowledge base (stdio or HTTP)."""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Annotated

import typer

from hiper_cli.commands._common import DEFAULT_KB, KbDocsOption, KbOption
from hiper_cli.commands._render import safe_text
from hiper_cli.errors import ConfigError

__all__ = ["register"]


def _host_port(text: str) -> tuple[str, int]:
    host, sep, port = text.rpartition(":")
    if not sep or not port.isdigit() or not 0 <= int(port) <= 65535:
        raise ConfigError(f"--http {text!r}: expected HOST:PORT, e.g. 127.0.0.1:8765")
    return host or "127.0.0.1", int(port)


def mcp_command(
    kb: KbOption = DEFAULT_KB,
    kb_docs: KbDocsOption = None,
    http: Annotated[
        str | None,
        typer.Option("--http", help="Serve streamable HTTP at HOST:PORT (path /mcp) instead of stdio."),
    ] = None,
    out_dir: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="Folder for the heatmap tool's files (default: a temp dir)."),
    ] = None,
    timeout_s: Annotated[
        float, typer.Option("--timeout", help="Give up on a sparql tool query after this many seconds.")
    ] = 30.0,
) -> None:
    """Serve the query verbs as MCP tools (find, count, last_seen, when, trajectory, workspace,
    describe, features, heatmap, sparql, ask) and resources (vocabulary, summary); read-only.
    Needs the mcp extra: pip install 'hiper\\[mcp]'.

    Example: hiper mcp --kb house.hiper   (stdio; or --http 127.0.0.1:8765)
    """
    from hiper_cli.agent import ToolContext
    from hiper_cli.graph import open_kb_for_reading
    from hiper_cli.mcp import require_mcp, run_http, run_stdio

    require_mcp()
    address = _host_port(http) if http is not None else None
    with open_kb_for_reading(kb, docs_dir=kb_docs) as knowledge:
        ctx = ToolContext(knowledge, out_dir, timeout_s)
        if address is None:
            run_stdio(ctx)
            return
        import sys

        def ready() -> None:
            print(f"hiper mcp: serving {safe_text(knowledge.location, markup=False)} at http://{address[0]}:{address[1]}/mcp",
                  file=sys.stderr, flush=True)

        with contextlib.suppress(KeyboardInterrupt):
            run_http(ctx, address[0], address[1], on_ready=ready)


def register(app: typer.Typer) -> None:
    app.command(name="mcp")(mcp_command)
