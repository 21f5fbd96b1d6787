"""A read-only SPARQL 1.1 Protocol endpoint over a knowledge base's scene graph.

``GET /query?query=...`` and ``POST /query`` (body ``application/sparql-query``, or a form
``query=...``) answer SELECT/ASK in SPARQL JSON, XML, CSV or TSV results and CONSTRUCT/
DESCRIBE in Turtle, N-Triples or RDF/XML, chosen by the ``Accept`` header (or a ``format``
parameter: json, xml, csv, tsv); the default graph is the union of all graphs. Updates
(``/update`` or an ``update=`` form) are refused with 403. Stdlib ``http.server`` only, bound
to 127.0.0.1 unless told otherwise.

Requests are answered in parallel (one thread each, at most ``MAX_RUNNING`` queries at once,
each under ``timeout_s``). A web page the user opens must not read the memory: no CORS header
unless ``cors`` names an origin, and a ``Host`` header other than this machine's names or an IP
address (DNS rebinding) is refused with 421. Bodies must declare a ``Content-Length`` of at
most ``MAX_BODY_BYTES`` and arrive within ``READ_TIMEOUT_S``.
"""

from __future__ import annotations

import ipaddress
import socket
import threading
import urllib.parse
from collections.abc import Sequence
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

from hiper_cli.errors import ConfigError, HiperError
from hiper_cli.graph.kb import KnowledgeBase
from hiper_cli.graph.sparql_safety import DEFAULT_TIMEOUT_S, readonly_form, run_with_timeout

MAX_BODY_BYTES = 1 << 20  # a query is text: a megabyte is far beyond any real one
READ_TIMEOUT_S = 10.0  # a client that declares more body than it sends is dropped after this
MAX_RUNNING = 8  # queries evaluated at once; more wait for none and get 503

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


def _is_ip(name: str) -> bool:
    try:
        ipaddress.ip_address(name.strip("[]"))
    except ValueError:
        return False
    return True


def allowed_hosts(bound: str, extra: Sequence[str] = ()) -> frozenset[str]:
    """The ``Host`` names (without port) a request may carry: loopback names, this machine's
    names when bound beyond loopback, and ``extra``. IP addresses are always allowed (a DNS
    rebinding attack needs a name)."""
    names = {"localhost", bound.lower(), *(e.lower() for e in extra)}
    if not (_is_ip(bound) and ipaddress.ip_address(bound).is_loopback):
        names |= {socket.gethostname().lower(), socket.getfqdn().lower()}
    return frozenset(names)


def host_allowed(header: str | None, allowed: frozenset[str]) -> bool:
    """Whether a request's ``Host`` header (``name[:port]``) is one this endpoint answers."""
    if not header:
        return False
    host = header.strip().lower()
    name = host.rsplit(":", 1)[0] if host.count(":") == 1 or (host.startswith("[") and "]:" in host) else host
    return _is_ip(name) or name in allowed


class SparqlEndpoint:
    """Serve ``kb`` at ``http://HOST:PORT/query`` (port 0: any free port; see ``url``).
    ``cors``: the one web origin allowed to read answers (none by default); ``hosts``: more
    ``Host`` names to accept besides this machine's; ``timeout_s``: per query."""

    def __init__(self, kb: KnowledgeBase, host: str = "127.0.0.1", port: int = 7879, *,
                 cors: str | None = None, hosts: Sequence[str] = (),
                 timeout_s: float | None = DEFAULT_TIMEOUT_S) -> None:
        if not host.strip():
            raise ConfigError("--host '': expected an address to bind, such as 127.0.0.1 (this machine "
                              "only) or 0.0.0.0 (every interface)")
        if cors is not None and not cors.startswith(("http://", "https://")):
            raise ConfigError(f"--cors {cors!r}: expected a web origin such as http://localhost:3000")
        self.kb = kb
        self.cors = cors.rstrip("/") if cors else None
        self.timeout_s = timeout_s
        self.hosts = allowed_hosts(host, hosts)
        self._running = threading.BoundedSemaphore(MAX_RUNNING)
        readonly_form("ASK {}")  # loads the SPARQL grammar now, not in the first requests' threads
        try:
            self._server = ThreadingHTTPServer((host, port), _handler(self))
        except (OSError, OverflowError) as err:
            raise ConfigError(f"--host {host} --port {port}: cannot listen there ({err})") from err
        self._server.daemon_threads = True
        self._thread: threading.Thread | None = None

    @property
    def url(self) -> str:
        host, port = self._server.server_address[:2]
        return f"http://{host!s}:{port}/query"

    def answer(self, sparql: str, media_type: str) -> tuple[bytes, str]:
        """Run one query; ``HiperError`` when refused, too slow or too many are running."""
        if not self._running.acquire(blocking=False):
            raise _Busy(f"{MAX_RUNNING} queries are running; try again shortly")

        def evaluate() -> tuple[bytes, str]:  # holds its slot until the evaluation really ends,
            try:  # also after the client was answered 503 (pyoxigraph cannot be interrupted)
                return self.kb.run_readonly(sparql, media_type, timeout_s=None)
            finally:
                self._running.release()

        return run_with_timeout(evaluate, self.timeout_s)

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


class _Busy(HiperError):
    """Every query slot is taken (HTTP 503)."""


def _status(err: HiperError) -> int:
    text = str(err)
    if isinstance(err, _Busy):
        return 503
    if "time limit" in text:
        return 503
    return 403 if "refused" in text else 400


class _Handler(BaseHTTPRequestHandler):
    """One request to the endpoint: a read-only SPARQL query by GET or POST, CORS preflight;
    every error one plain-text line with its HTTP status."""

    endpoint: SparqlEndpoint  # set by ``_handler``
    server_version = "hiper-sparql/1"
    timeout = READ_TIMEOUT_S  # socket timeout: a stalled client does not hold a thread

    def log_message(self, format: str, *args: Any) -> None:  # quiet: no per-request lines
        pass

    def _send(self, code: int, body: bytes, media: str) -> None:
        self.send_response(code)
        self.send_header("Content-Type", f"{media}; charset=utf-8")
        self.send_header("Content-Length", str(len(body)))
        self._cors_headers()
        self.end_headers()
        self.wfile.write(body)

    def _cors_headers(self) -> None:
        if self.endpoint.cors is not None:
            self.send_header("Access-Control-Allow-Origin", self.endpoint.cors)
            self.send_header("Vary", "Origin")

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
            body, media = self.endpoint.answer(query, media)
        except HiperError as err:
            self._error(_status(err), str(err))
            return
        self._send(200, body, media)

    def _host_ok(self) -> bool:
        if host_allowed(self.headers.get("Host"), self.endpoint.hosts):
            return True
        self._error(421, f"Host {self.headers.get('Host')!r} is not this endpoint's; use "
                         "http://127.0.0.1:PORT/query (or serve --allow-host NAME)")
        return False

    def _body(self) -> bytes | None:
        """The request body, or None after answering 4xx for a bad or missing length."""
        declared = self.headers.get("Content-Length")
        if declared is None:
            self._error(411, "a POST needs a Content-Length header")
            return None
        if not declared.strip().isdigit():
            self._error(400, f"Content-Length {declared!r}: expected a non-negative integer")
            return None
        length = int(declared)
        if length > MAX_BODY_BYTES:
            self._error(413, f"Content-Length {length}: a query body may be at most {MAX_BODY_BYTES} "
                             "bytes")
            return None
        try:
            raw = self.rfile.read(length)
        except TimeoutError:
            raw = b""
        if len(raw) != length:
            self.close_connection = True
            self._error(400, f"the body ended after {len(raw)} of {length} declared bytes")
            return None
        return raw

    def do_GET(self) -> None:
        if self._host_ok():
            self._run(urllib.parse.parse_qs(urllib.parse.urlsplit(self.path).query), None)

    def do_POST(self) -> None:
        if not self._host_ok():
            return
        body = self._body()
        if body is None:
            return
        raw = body.decode("utf-8", "replace")
        ctype = (self.headers.get("Content-Type") or "").split(";")[0].strip().lower()
        params = urllib.parse.parse_qs(urllib.parse.urlsplit(self.path).query)
        if ctype == "application/sparql-query":
            self._run(params, raw)
        elif ctype == "application/sparql-update":
            self._error(403, "this endpoint is read-only: SPARQL updates are refused")
        else:
            self._run({**params, **urllib.parse.parse_qs(raw)}, None)

    def do_OPTIONS(self) -> None:
        if not self._host_ok():
            return
        self.send_response(204)
        if self.endpoint.cors is not None:
            self._cors_headers()
            self.send_header("Access-Control-Allow-Methods", "GET, POST, OPTIONS")
            self.send_header("Access-Control-Allow-Headers", "Content-Type, Accept")
        self.send_header("Content-Length", "0")
        self.end_headers()



def _handler(endpoint: SparqlEndpoint) -> type[BaseHTTPRequestHandler]:
    """The request handler class of ``endpoint`` (``http.server`` builds one per request)."""
    return type("Handler", (_Handler,), {"endpoint": endpoint})
