"""What ``hiper serve`` and ``hiper mcp`` say once they listen."""

from __future__ import annotations

import sys

from hiper_cli.render.text import console, safe_text

__all__ = ["show_mcp_ready", "show_serving"]


def show_serving(location: str, url: str) -> None:
    """``hiper serve``: which knowledge base, at which URL (stdout)."""
    console().print(f"serving {safe_text(location)} read-only at [bold]{safe_text(url)}[/] (Ctrl-C stops)")


def show_mcp_ready(location: str, url: str) -> None:
    """``hiper mcp --http``: on stderr, since stdout may carry the protocol."""
    print(f"hiper mcp: serving {safe_text(location, markup=False)} at {url}", file=sys.stderr, flush=True)
