"""``hiper tools``: the agent tools as function-calling schemas (OpenAI, Anthropic, MCP)."""

from __future__ import annotations

from typing import Annotated

import typer

from hiper_cli.cmdline import HiperTyper, Json
from hiper_cli.render import emit
from hiper_cli.render.agent import show_tools

__all__ = ["register"]

Format = Annotated[str, typer.Option("--format", help="openai, anthropic or mcp.")]


def tools_command(fmt: Format = "openai", as_json: Json = False) -> None:
    """Print the tools of hiper mcp as function-calling schemas for agent frameworks that do not
    speak MCP (docs/agents.md has an agent loop against a local OpenAI-compatible server).

    Example: hiper tools --format openai --json > tools.json
    """
    from hiper_cli.agent import tool_schemas

    emit(tool_schemas(fmt), as_json, lambda out, _: show_tools(out, fmt))


def register(app: HiperTyper) -> None:
    app.command(name="tools")(tools_command)
