"""``hiper serve``: the scene graph as a read-only SPARQL 1.1 Protocol endpoint (``serve.run``)."""

from __future__ import annotations

from typing import Annotated

import typer

from hiper_cli.cmdline import DEFAULT_KB, HiperTyper, Kb, KbDocs
from hiper_cli.render.serve import show_serving

__all__ = ["register"]

Host = Annotated[str, typer.Option("--host", help="Address to bind (0.0.0.0 exposes it to the network).")]
Port = Annotated[int, typer.Option("--port", help="TCP port (0: any free one).")]
Cors = Annotated[str | None, typer.Option(
    "--cors", help="Let web pages of this origin read answers (none by default).")]
AllowHost = Annotated[list[str] | None, typer.Option(
    "--allow-host", help="Accept requests naming this host (besides this machine's names).")]
Timeout = Annotated[float, typer.Option("--timeout", help="Give up on a query after this many seconds.")]


def serve_command(kb: Kb = DEFAULT_KB, kb_docs: KbDocs = None, host: Host = "127.0.0.1", port: Port = 7879,
                  cors: Cors = None, allow_host: AllowHost = None, timeout_s: Timeout = 30.0) -> None:
    """Serve the knowledge base's scene graph read-only over the SPARQL 1.1 Protocol:
    GET/POST /query, results as JSON, XML, CSV or TSV (Accept header), updates refused.
    Queries run in parallel, each for at most --timeout seconds; web pages cannot read the
    answers unless --cors names their origin.

    Example: hiper serve --kb house.hiper --port 7879
    """
    from hiper_cli.serve.run import serve_kb

    serve_kb(kb, docs_dir=kb_docs, host=host, port=port, cors=cors, hosts=allow_host or (),
             timeout_s=timeout_s, on_ready=show_serving)


def register(app: HiperTyper) -> None:
    app.command(name="serve")(serve_command)
