"""``hiper tools``: the agent tools as function-calling schemas (OpenAI, Anthropic, MCP)."""

from __future__ import annotations

from typing import Annotated

import typer

from hiper_cli.commands._render import JSON_OPTION, console, print_json

__all__ = ["register"]


def tools_command(
    fmt: Annotated[str, typer.Option("--format", help="openai, anthropic or mcp.")] = "openai",
    as_json: bool = JSON_OPTION,
) -> None:
    """Print the tools of hiper mcp as function-calling schemas for agent frameworks that do not
    speak MCP (docs/agents.md has an agent loop against a local OpenAI-compatible server).

    Example: hiper tools --format openai --json > tools.json
    """
    from hiper_cli.agent import tool_schemas

    schemas = tool_schemas(fmt)
    if as_json:
        print_json(schemas)
        return
    from rich.table import Table

    from hiper_cli.agent import TOOLS

    title = f"{len(TOOLS)} tools ({fmt}; --json for the schemas)"
    table = Table("tool", "inputs", "description", title=title)
    for t in TOOLS:
        table.add_row(t.name, ", ".join(t.input_schema["properties"]), t.description)
    console().print(table)


def register(app: typer.Typer) -> None:
    app.command(name="tools")(tools_command)
