"""A stand-in remote SPARQL endpoint on 127.0.0.1 that counts the requests it gets.

A ``SERVICE`` bypass would send the query here and get one row back (``?s`` = ``urn:leak``),
so a case checks both that no row leaked and that no request was made at all.
"""

from __future__ import annotations

import json
import threading
from collections.abc import Callable
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

from tests.faults.runner import Result, Workspace

ROW = {"head": {"vars": ["s", "p", "o"]},
       "results": {"bindings": [{v: {"type": "uri", "value": "urn:leak"} for v in ("s", "p", "o")}]}}


class Listener:
    def __init__(self) -> None:
        self.requests: list[str] = []
        listener = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, format: str, *args: Any) -> None:
                pass

            def _answer(self) -> None:
                listener.requests.append(f"{self.command} {self.path}")
                body = json.dumps(ROW).encode()
                self.send_response(200)
                self.send_header("Content-Type", "application/sparql-results+json")
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body)

            do_GET = do_POST = _answer

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.port = int(self.server.server_address[1])
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


def with_listener(ws: Workspace) -> Listener:
    """Start a listener for the case; ``{port}`` in its command line names it."""
    listener = Listener()
    ws.extra["port"] = str(listener.port)
    ws.cleanups.append(listener.close)
    ws.extra["_listener"] = str(id(listener))
    _LIVE[id(listener)] = listener
    ws.cleanups.append(lambda: _LIVE.pop(id(listener), None))
    return listener


_LIVE: dict[int, Listener] = {}


def listener_of(ws: Workspace) -> Listener:
    return _LIVE[int(ws.extra["_listener"])]


def no_request(ws: Workspace, result: Result) -> str | None:
    """The case's check: the listener got no request and no leaked row was printed."""
    listener = listener_of(ws)
    if listener.requests:
        return f"network request made: {listener.requests}"
    if "urn:leak" in result.stdout:
        return "the remote endpoint's rows came back as answers"
    return None


def prepare_listener(ws: Workspace) -> None:
    with_listener(ws)


def then(*steps: Callable[[Workspace], Any]) -> Callable[[Workspace], None]:
    def prepare(ws: Workspace) -> None:
        for step in steps:
            step(ws)

    return prepare
