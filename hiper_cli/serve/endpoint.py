"""A read-only SPARQL 1.1 Protocol endpoint over a knowledge base's scene graph.

``GET /query?query=...`` and ``POST /query`` (body ``application/sparql-query``, or a form
``query=...``) answer SELECT/ASK in SPARQL JSON, XML, CSV or TSV results and CONSTRUCT/
DESCRIBE in Turtle, N-Triples or RDF/XML, chosen by the ``Accept`` header (or a ``format``
parameter: json, xml, csv, tsv); the default graph is the union of all graphs. Updates
(``/update`` or an ``update=`` form) are refused with 403. Stdlib ``http.server`` only, bound
to 127.0.0.1 unless told otherwise.
"""

from __future__ import annotations

import threading
import urllib.parse
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

from hiper_cli.errors import HiperError
from hiper_cli.graph.kb import KnowledgeBase

__all__ = ["SparqlEndpoint", "choose_media_type"]

_BY_NAME = {
    "json": "application/sparql-results+json",
    "xml": "application/sparql-results+xml",
    "csv": "text/csv",
    "tsv": "text/tab-separated-values",
    "turtle": "text/turtle",
    "ntriples": "application/n-triples",
    "rdfxml": "application/rdf+xml",
}
_ACCEPTED = (
    "application/sparql-results+json",
    "application/sparql-results+xml",
    "text/csv",
    "text/tab-separated-values",
    "text/turtle",
    "application/n-triples",
    "application/rdf+xml",
    "application/json",
    "application/xml",
    "text/xml",
)


def choose_media_type(accept: str | None, format_name: str | None) -> str:
    """The results media type for an ``Accept`` header or a ``format`` parameter."""
    if format_name:
        return _BY_NAME.get(format_name.lower(), format_name)
    for part in (accept or "").split(","):
        media = part.split(";")[0].strip().lower()
        if media in _ACCEPTED:
            return {
                "application/json": "application/sparql-results+json",
                "application/xml": "application/sparql-results+xml",
                "text/xml": "application/sparql-results+xml",
            }.get(media, media)
    return "application/sparql-results+json"


class SparqlEndpoint:
    """Serve ``kb`` at ``http://HOST:PORT/query`` (port 0: any free port; see ``url``)."""

    def __init__(self, kb: KnowledgeBase, host: str = "127.0.0.1", port: int = 7879) -> None:
        self.kb = kb
        self._lock = threading.Lock()
        self._server = ThreadingHTTPServer((host, port), _handler(self))
        self._thread: threading.Thread | None = None

    @property
    def url(self) -> str:
        host, port = self._server.server_address[:2]
        return f"http://{host!s}:{port}/query"

    def answer(self, sparql: str, media_type: str) -> tuple[bytes, str]:
        with self._lock:
            return self.kb.run_readonly(sparql, media_type)

    def start(self) -> SparqlEndpoint:
        """Serve in a background thread (tests, notebooks)."""
        self._thread = threading.Thread(target=self._server.serve_forever, daemon=True)
        self._thread.start()
        return self

    def serve_forever(self) -> None:
        self._server.serve_forever()

    def close(self) -> None:
        self._server.shutdown()
        self._server.server_close()
        if self._thread is not None:
            self._thread.join(timeout=5)

    def __enter__(self) -> SparqlEndpoint:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()


def _handler(endpoint: SparqlEndpoint) -> type[BaseHTTPRequestHandler]:
    class Handler(BaseHTTPRequestHandler):
        server_version = "hiper-sparql/1"

        def log_message(self, format: str, *args: Any) -> None:  # quiet: no per-request lines
            pass

        def _send(self, code: int, body: bytes, media: str) -> None:
            self.send_response(code)
            self.send_header("Content-Type", f"{media}; charset=utf-8")
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Access-Control-Allow-Origin", "*")
            self.end_headers()
            self.wfile.write(body)

        def _error(self, code: int, message: str) -> None:
            self._send(code, message.encode("utf-8"), "text/plain")

        def _run(self, params: dict[str, list[str]], body_query: str | None) -> None:
            path = urllib.parse.urlsplit(self.path).path.rstrip("/")
            if path.endswith("/update") or "update" in params:
                self._error(403, "this endpoint is read-only: SPARQL updates are refused")
                return
            if path not in ("/query", "/sparql", ""):
                self._error(404, f"no such resource {path}; send queries to /query")
                return
            query = body_query if body_query is not None else next(iter(params.get("query") or []), None)
            if not query:
                self._error(
                    400, "missing query: GET /query?query=... or POST a application/sparql-query body"
                )
                return
            media = choose_media_type(
                self.headers.get("Accept"), next(iter(params.get("format") or []), None)
            )
            try:
                body, media = endpoint.answer(query, media)
            except HiperError as err:
                refused = "refused" in str(err)
                self._error(403 if refused else 400, str(err))
                return
            self._send(200, body, media)

        def do_GET(self) -> None:
            self._run(urllib.parse.parse_qs(urllib.parse.urlsplit(self.path).query), None)

        def do_POST(self) -> None:
            length = int(self.headers.get("Content-Length") or 0)
            raw = self.rfile.read(length).decode("utf-8", "replace")
            ctype = (self.headers.get("Content-Type") or "").split(";")[0].strip().lower()
            params = urllib.parse.parse_qs(urllib.parse.urlsplit(self.path).query)
            if ctype == "application/sparql-query":
                self._run(params, raw)
            elif ctype == "application/sparql-update":
                self._error(403, "this endpoint is read-only: SPARQL updates are refused")
            else:
                self._run({**params, **urllib.parse.parse_qs(raw)}, None)

        def do_OPTIONS(self) -> None:
            self.send_response(204)
            self.send_header("Access-Control-Allow-Origin", "*")
            self.send_header("Access-Control-Allow-Methods", "GET, POST, OPTIONS")
            self.send_header("Access-Control-Allow-Headers", "Content-Type, Accept")
            self.end_headers()

    return Handler
