"""``hiper serve``: the scene graph as a read-only SPARQL 1.1 Protocol endpoint."""

from __future__ import annotations

from typing import Annotated

import typer

from hiper_cli.commands._common import DEFAULT_KB, KbDocsOption, KbOption
from hiper_cli.commands._render import console

__all__ = ["register"]


def serve_command(
    kb: KbOption = DEFAULT_KB,
    kb_docs: KbDocsOption = None,
    host: Annotated[
        str, typer.Option("--host", help="Address to bind (0.0.0.0 exposes it to the network).")
    ] = "127.0.0.1",
    port: Annotated[int, typer.Option("--port", help="TCP port (0: any free one).")] = 7879,
) -> None:
    """Serve the knowledge base's scene graph read-only over the SPARQL 1.1 Protocol:
    GET/POST /query, results as JSON, XML, CSV or TSV (Accept header), updates refused.

    Example: hiper serve --kb house.hiper --port 7879
    """
    from hiper_cli.graph import open_kb_for_reading
    from hiper_cli.serve import SparqlEndpoint

    with open_kb_for_reading(kb, docs_dir=kb_docs) as knowledge:
        endpoint = SparqlEndpoint(knowledge, host, port)
        console().print(
            f"serving {knowledge.location} read-only at [bold]{endpoint.url}[/] (Ctrl-C stops)",
        )
        try:
            endpoint.serve_forever()
        except KeyboardInterrupt:
            pass
        finally:
            endpoint.close()


def register(app: typer.Typer) -> None:
    app.command(name="serve")(serve_command)
