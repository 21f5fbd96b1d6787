"""``hiper mcp`` as a function: the agent tools of a knowledge base served over stdio or HTTP."""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from pathlib import Path

from hiper_cli.errors import ConfigError

__all__ = ["host_port", "serve_mcp"]


def host_port(text: str) -> tuple[str, int]:
    """``--http HOST:PORT`` (HOST defaults to 127.0.0.1)."""
    host, sep, port = text.rpartition(":")
    if not sep or not port.isdigit() or not 0 <= int(port) <= 65535:
        raise ConfigError(f"--http {text!r}: expected HOST:PORT, e.g. 127.0.0.1:8765")
    return host or "127.0.0.1", int(port)


def serve_mcp(kb: str, *, docs_dir: Path | None = None, http: str | None = None, out_dir: Path | None = None,
              timeout_s: float = 30.0, on_ready: Callable[[str, str], None] | None = None) -> None:
    """Serve the tools over stdio, or streamable HTTP at ``http`` (HOST:PORT) until Ctrl-C;
    ``on_ready(kb location, url)`` once the HTTP server listens."""
    from hiper_cli.agent import ToolContext
    from hiper_cli.graph import open_kb_for_reading
    from hiper_cli.mcp.server import require_mcp, run_http, run_stdio

    require_mcp()
    address = host_port(http) if http is not None else None
    with open_kb_for_reading(kb, docs_dir=docs_dir) as knowledge:
        ctx = ToolContext(knowledge, out_dir, timeout_s)
        if address is None:
            run_stdio(ctx)
            return
        host, port = address

        def ready() -> None:
            if on_ready is not None:
                on_ready(knowledge.location, f"http://{host}:{port}/mcp")

        with contextlib.suppress(KeyboardInterrupt):
            run_http(ctx, host, port, on_ready=ready)
