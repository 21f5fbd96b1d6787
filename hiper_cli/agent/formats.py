"""The tool registry as function-calling schemas: OpenAI ``tools``, Anthropic ``tools`` and
MCP ``tools/list`` entries, for agent frameworks that do not speak MCP."""

from __future__ import annotations

from typing import Any

__all__ = ["FORMATS", "tool_schemas"]

FORMATS = ("openai", "anthropic", "mcp")


def tool_schemas(fmt: str = "openai") -> list[dict[str, Any]]:
    """Every tool in the format ``fmt`` (``openai``, ``anthropic`` or ``mcp``)."""
    from hiper_cli.agent.tools import TOOLS
    from hiper_cli.errors import ConfigError

    if fmt == "openai":
        return [{"type": "function", "function": {"name": t.name, "description": t.description,
                                                  "parameters": t.input_schema, "strict": False}}
                for t in TOOLS]
    if fmt == "anthropic":
        return [{"name": t.name, "description": t.description, "input_schema": t.input_schema} for t in TOOLS]
    if fmt == "mcp":
        return [{"name": t.name, "description": t.description, "inputSchema": t.input_schema,
                 "outputSchema": t.output_schema} for t in TOOLS]
    raise ConfigError(f"--format {fmt!r}: expected one of {', '.join(FORMATS)}")
