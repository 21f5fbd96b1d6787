"""LLM-ready tools: the query layer's verbs as named tools with strict JSON schemas (one
registry for ``hiper mcp`` and ``hiper tools``), and relative-time resolution for agents."""

from hiper_cli.agent.formats import FORMATS, tool_schemas
from hiper_cli.agent.tools import TOOLS, Tool, ToolContext, ToolResult, call_tool, tool_named

__all__ = ["FORMATS", "TOOLS", "Tool", "ToolContext", "ToolResult", "call_tool", "tool_named", "tool_schemas"]
