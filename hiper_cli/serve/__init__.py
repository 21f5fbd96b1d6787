"""``hiper serve``: the scene graph as a read-only SPARQL 1.1 Protocol endpoint."""

from hiper_cli.serve.endpoint import SparqlEndpoint

__all__ = ["SparqlEndpoint"]
