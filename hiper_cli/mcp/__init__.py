"""``hiper mcp``: the agent tools of ``hiper_cli.agent`` served over the Model Context
Protocol (stdio or streamable HTTP). The ``mcp`` SDK (extra ``hiper[mcp]``, 1.x) is imported
only here, when a server is built."""

from hiper_cli.mcp.server import INSTALL_HINT, build_server, require_mcp, run_http, run_stdio

__all__ = ["INSTALL_HINT", "build_server", "require_mcp", "run_http", "run_stdio"]
