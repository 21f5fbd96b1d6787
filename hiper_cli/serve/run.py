"""``hiper serve`` as a function: a knowledge base's scene graph served until Ctrl-C."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from hiper_cli.errors import ConfigError

__all__ = ["serve_kb"]


def serve_kb(kb: str, *, docs_dir: Path | None = None, host: str = "127.0.0.1", port: int = 7879,
             cors: str | None = None, hosts: Sequence[str] = (), timeout_s: float = 30.0,
             on_ready: Callable[[str, str], None] | None = None) -> None:
    """Serve ``kb`` read-only over the SPARQL 1.1 Protocol (``SparqlEndpoint``) until Ctrl-C;
    ``on_ready(kb location, url)`` once it listens."""
    from hiper_cli.graph import open_kb_for_reading
    from hiper_cli.serve.endpoint import SparqlEndpoint

    if not host.strip():  # before the knowledge base is opened
        raise ConfigError("--host '': expected an address to bind, such as 127.0.0.1 (this machine "
                          "only) or 0.0.0.0 (every interface)")
    with open_kb_for_reading(kb, docs_dir=docs_dir) as knowledge:
        endpoint = SparqlEndpoint(knowledge, host, port, cors=cors, hosts=hosts, timeout_s=timeout_s)
        if on_ready is not None:
            on_ready(knowledge.location, endpoint.url)
        try:
            endpoint.serve_forever()
        except KeyboardInterrupt:
            pass
        finally:
            endpoint.close()
