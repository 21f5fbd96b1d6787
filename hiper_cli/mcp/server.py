"""The MCP server over one knowledge base: the registry's tools (strict input schemas, typed
structured results, a tool error as ``isError`` with a structured ``error``), and two
resources: the class vocabulary and the KB summary. Read-only."""

from __future__ import annotations

import json
from typing import Any

from hiper_cli import __version__
from hiper_cli.agent import TOOLS, ToolContext, call_tool
from hiper_cli.errors import ConfigError

__all__ = ["INSTALL_HINT", "RESOURCES", "build_server", "require_mcp", "run_http", "run_stdio"]

INSTALL_HINT = "pip install 'hiper[mcp]' (the mcp SDK 1.x); in a checkout 'make setup' installs it"
RESOURCES = {
    "hiper://vocabulary": ("vocabulary", "The classes and words hiper's queries understand."),
    "hiper://summary": ("summary", "The knowledge base in brief (hiper describe --json)."),
}
INSTRUCTIONS = (
    "hiper answers questions about a robot's scene memory (a knowledge base built from its RGB-D "
    "log). Times may be given as words ('last 10 minutes', '5 min ago', 'HH:MM'); the server resolves "
    "them against the knowledge base's now. Start with the 'describe' tool or the hiper://summary "
    "resource; 'find', 'count', 'last_seen', 'when' and 'trajectory' are the query verbs."
)


def require_mcp() -> Any:
    """The ``mcp`` package, or a ``ConfigError`` that says how to install it."""
    try:
        import mcp
        import mcp.server.lowlevel
    except ImportError as err:
        raise ConfigError(f"hiper mcp needs the mcp package: {INSTALL_HINT}") from err
    return mcp


def _vocabulary() -> dict[str, Any]:
    from hiper_cli.query.vocabulary import ANY_FOREGROUND, CLASS_NAMES, SYNONYMS

    return {"classes": list(CLASS_NAMES), "synonyms": dict(SYNONYMS), "any_foreground": ANY_FOREGROUND}


def build_server(ctx: ToolContext) -> Any:
    """A low-level ``mcp.server.lowlevel.Server`` serving the tools over ``ctx.kb``."""
    require_mcp()
    from mcp import types
    from mcp.server.lowlevel import Server
    from mcp.server.lowlevel.helper_types import ReadResourceContents

    # The SDK's decorators are untyped, so the handlers are registered by call, not as decorators.
    server: Any = Server("hiper", version=__version__, instructions=INSTRUCTIONS)

    async def list_tools() -> list[Any]:
        return [
            types.Tool(name=t.name, description=t.description, inputSchema=t.input_schema,
                       outputSchema=t.output_schema)
            for t in TOOLS
        ]

    async def call(name: str, arguments: dict[str, Any] | None) -> Any:
        result = call_tool(ctx, name, arguments)
        content: list[Any] = [types.TextContent(type="text", text=json.dumps(result.data))]
        content += [types.ImageContent(type="image", data=_b64(png), mimeType="image/png")
                    for png in result.images]
        return types.CallToolResult(content=content, structuredContent=result.data, isError=result.is_error)

    async def list_resources() -> list[Any]:
        return [types.Resource.model_validate({"uri": uri, "name": name, "description": text,
                                                "mimeType": "application/json"})
                for uri, (name, text) in RESOURCES.items()]

    async def read_resource(uri: Any) -> list[Any]:
        if str(uri) == "hiper://vocabulary":
            data = _vocabulary()
        elif str(uri) == "hiper://summary":
            from hiper_cli.query.describe import describe

            data = describe(ctx.kb).to_dict()
        else:
            raise ValueError(f"no resource {uri}; expected one of {', '.join(RESOURCES)}")
        return [ReadResourceContents(json.dumps(data), "application/json")]

    server.list_tools()(list_tools)
    # The registry validates the arguments itself, so a bad call is a structured error too.
    server.call_tool(validate_input=False)(call)
    server.list_resources()(list_resources)
    server.read_resource()(read_resource)
    return server


def _b64(data: bytes) -> str:
    import base64

    return base64.b64encode(data).decode("ascii")


def run_stdio(ctx: ToolContext) -> None:
    """Serve over stdin/stdout until the client closes them."""
    import anyio
    from mcp.server.stdio import stdio_server

    server = build_server(ctx)

    async def main() -> None:
        async with stdio_server() as (read, write):
            await server.run(read, write, server.create_initialization_options())

    anyio.run(main)


def run_http(ctx: ToolContext, host: str, port: int, on_ready: Any = None) -> None:
    """Serve streamable HTTP at ``http://HOST:PORT/mcp`` (stateless, one session per request)."""
    import contextlib

    import uvicorn
    from mcp.server.streamable_http_manager import StreamableHTTPSessionManager
    from starlette.applications import Starlette
    from starlette.routing import Mount

    manager = StreamableHTTPSessionManager(app=build_server(ctx), stateless=True, json_response=True)

    async def handle(scope: Any, receive: Any, send: Any) -> None:
        await manager.handle_request(scope, receive, send)

    @contextlib.asynccontextmanager
    async def lifespan(_: Any) -> Any:
        async with manager.run():
            if on_ready is not None:
                on_ready()
            yield

    app = Starlette(routes=[Mount("/mcp", app=handle)], lifespan=lifespan)
    uvicorn.run(app, host=host, port=port, log_level="warning")
