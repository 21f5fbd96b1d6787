"""``hiper serve``: the scene graph as a read-only SPARQL 1.1 Protocol endpoint."""

from __future__ import annotations

from typing import Annotated

import typer

from hiper_cli.commands._common import DEFAULT_KB, KbDocsOption, KbOption
from hiper_cli.commands._render import console, safe_text
from hiper_cli.errors import ConfigError

__all__ = ["register"]


def serve_command(
    kb: KbOption = DEFAULT_KB,
    kb_docs: KbDocsOption = None,
    host: Annotated[
        str, typer.Option("--host", help="Address to bind (0.0.0.0 exposes it to the network).")
    ] = "127.0.0.1",
    port: Annotated[int, typer.Option("--port", help="TCP port (0: any free one).")] = 7879,
    cors: Annotated[
        str | None,
        typer.Option("--cors", help="Let web pages of this origin read answers (none by default)."),
    ] = None,
    allow_host: Annotated[
        list[str] | None,
        typer.Option("--allow-host", help="Accept requests naming this host (besides this machine's names)."),
    ] = None,
    timeout_s: Annotated[
        float, typer.Option("--timeout", help="Give up on a query after this many seconds.")
    ] = 30.0,
) -> None:
    """Serve the knowledge base's scene graph read-only over the SPARQL 1.1 Protocol:
    GET/POST /query, results as JSON, XML, CSV or TSV (Accept header), updates refused.
    Queries run in parallel, each for at most --timeout seconds; web pages cannot read the
    answers unless --cors names their origin.

    Example: hiper serve --kb house.hiper --port 7879
    """
    from hiper_cli.graph import open_kb_for_reading
    from hiper_cli.serve import SparqlEndpoint

    if not host.strip():  # before the knowledge base is opened
        raise ConfigError("--host '': expected an address to bind, such as 127.0.0.1 (this machine "
                          "only) or 0.0.0.0 (every interface)")
    with open_kb_for_reading(kb, docs_dir=kb_docs) as knowledge:
        endpoint = SparqlEndpoint(knowledge, host, port, cors=cors, hosts=allow_host or (),
                                  timeout_s=timeout_s)
        console().print(
            f"serving {safe_text(knowledge.location)} read-only at [bold]{safe_text(endpoint.url)}[/] "
            "(Ctrl-C stops)",
        )
        try:
            endpoint.serve_forever()
        except KeyboardInterrupt:
            pass
        finally:
            endpoint.close()


def register(app: typer.Typer) -> None:
    app.command(name="serve")(serve_command)
