"""``hiper serve`` from a client's side: CORS, Host (DNS rebinding), bad Content-Length,
parallel clients during a slow query, SERVICE and updates over HTTP, bad --host/--cors values.

Each probe starts ``hiper serve --port 0`` on the case's knowledge base, talks raw HTTP to it,
then stops it with Ctrl-C; the server must print no traceback and still answer at the end.
"""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import threading
import time
import urllib.parse
from collections.abc import Callable
from dataclasses import dataclass, field

from tests.faults.case import Case
from tests.faults.listener import listener_of, no_request, prepare_listener
from tests.faults.runner import Result, Workspace, hiper_argv
from tests.faults.sparql import CARTESIAN, SERVICE_SPELLINGS, braces


@dataclass
class Reply:
    status: int
    headers: dict[str, str]
    body: str
    seconds: float


@dataclass
class Server:
    port: int
    problems: list[str] = field(default_factory=list)

    def send(self, raw: bytes, *, hold_open: bool = False, timeout_s: float = 30.0) -> Reply:
        """Send raw request bytes; read the reply until the server closes or ``timeout_s``."""
        start = time.monotonic()
        with socket.create_connection(("127.0.0.1", self.port), timeout=timeout_s) as sock:
            sock.sendall(raw)
            if not hold_open:
                sock.shutdown(socket.SHUT_WR)
            chunks = []
            try:
                while True:
                    data = sock.recv(65536)
                    if not data:
                        break
                    chunks.append(data)
                    if hold_open and b"\r\n\r\n" in b"".join(chunks):
                        break
            except TimeoutError:
                pass
        return _parse(b"".join(chunks), time.monotonic() - start)

    def get(self, query: str, *, host: str | None = None, headers: str = "") -> Reply:
        path = "/query?" + urllib.parse.urlencode({"query": query})
        return self.send(f"GET {path} HTTP/1.1\r\nHost: {host or f'127.0.0.1:{self.port}'}\r\n{headers}"
                         "Connection: close\r\n\r\n".encode())

    def post(self, body: bytes, length: str, *, ctype: str = "application/sparql-query",
             hold_open: bool = False, timeout_s: float = 30.0) -> Reply:
        head = (f"POST /query HTTP/1.1\r\nHost: 127.0.0.1:{self.port}\r\nContent-Type: {ctype}\r\n"
                f"Content-Length: {length}\r\nConnection: close\r\n\r\n").encode()
        return self.send(head + body, hold_open=hold_open, timeout_s=timeout_s)

    def expect(self, what: str, ok: bool) -> None:
        if not ok:
            self.problems.append(what)


def _parse(raw: bytes, seconds: float) -> Reply:
    head, _, body = raw.partition(b"\r\n\r\n")
    lines = head.decode("latin-1").split("\r\n")
    match = re.match(r"HTTP/1\.\d (\d+)", lines[0]) if lines else None
    headers = {}
    for line in lines[1:]:
        name, _, value = line.partition(":")
        headers[name.strip().lower()] = value.strip()
    return Reply(int(match.group(1)) if match else 0, headers, body.decode("utf-8", "replace"), seconds)


def _ctrl_c_as_in_a_shell() -> None:
    """The server starts as a terminal would start it: SIGINT neither ignored nor blocked,
    whatever the test process (or a library it loaded) did to its own signals."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def _serve_probe(talk: Callable[[Server, Workspace], None], *flags: str) -> Callable[[Workspace], Result]:
    def probe(ws: Workspace) -> Result:
        start = time.monotonic()
        proc = subprocess.Popen(hiper_argv(ws.repo, ["serve", "--kb", str(ws.kb), "--port", "0", *flags]),
                                cwd=ws.root, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                env={**os.environ, "COLUMNS": "300", "NO_COLOR": "1"},
                                preexec_fn=_ctrl_c_as_in_a_shell)
        assert proc.stdout is not None
        line = proc.stdout.readline()  # "serving KB read-only at http://127.0.0.1:PORT/query ..."
        found = re.search(r"http://127\.0\.0\.1:(\d+)/query", line)
        server = Server(int(found.group(1)) if found else 0)
        if found is None:
            server.problems.append(f"no URL printed: {line!r}")
        else:
            try:
                talk(server, ws)
                alive = server.get("ASK {}")
                server.expect(f"still answers ASK at the end (got {alive.status})", alive.status == 200)
            except OSError as err:
                server.problems.append(f"connection failed: {err!r}")
        proc.send_signal(signal.SIGINT)
        try:
            out, err = proc.communicate(timeout=15)
        except subprocess.TimeoutExpired:
            proc.kill()
            out, err = proc.communicate()
            server.problems.append("did not stop on Ctrl-C")
        seconds = time.monotonic() - start
        text = "; ".join(server.problems)
        return Result(1 if server.problems else 0, line + out,
                      err + (f"error: {text}\n" if server.problems else ""), seconds)

    return probe


def _no_cors(server: Server, ws: Workspace) -> None:
    reply = server.get("ASK {}", headers="Origin: http://evil.example\r\n")
    server.expect(f"answers 200 (got {reply.status})", reply.status == 200)
    server.expect(f"no CORS header (got {reply.headers.get('access-control-allow-origin')!r})",
                  "access-control-allow-origin" not in reply.headers)
    pre = server.send(f"OPTIONS /query HTTP/1.1\r\nHost: 127.0.0.1:{server.port}\r\nOrigin: http://evil.example"
                      "\r\nAccess-Control-Request-Method: POST\r\nConnection: close\r\n\r\n".encode())
    server.expect("no CORS header on a preflight", "access-control-allow-origin" not in pre.headers)


def _one_origin(server: Server, ws: Workspace) -> None:
    reply = server.get("ASK {}", headers="Origin: http://localhost:3000\r\n")
    server.expect(f"CORS for the one origin (got {reply.headers.get('access-control-allow-origin')!r})",
                  reply.headers.get("access-control-allow-origin") == "http://localhost:3000")


def _rebinding(server: Server, ws: Workspace) -> None:
    reply = server.get("ASK {}", host=f"attacker.example:{server.port}")
    server.expect(f"a foreign Host refused with 421 (got {reply.status})", reply.status == 421)
    for host in (f"localhost:{server.port}", f"127.0.0.1:{server.port}"):
        ok = server.get("ASK {}", host=host)
        server.expect(f"Host {host} answered (got {ok.status})", ok.status == 200)
    missing = server.send(b"GET /query?query=ASK%7B%7D HTTP/1.0\r\n\r\n")
    server.expect(f"no Host header refused (got {missing.status})", missing.status == 421)


def _length(value: str, status: int, body: bytes = b"ASK {}") -> Callable[[Server, Workspace], None]:
    def talk(server: Server, ws: Workspace) -> None:
        reply = server.post(body, value, timeout_s=20)
        server.expect(f"Content-Length {value}: {status} (got {reply.status} after {reply.seconds:.1f} s)",
                      reply.status == status and reply.seconds < 15)

    return talk


def _short_body(server: Server, ws: Workspace) -> None:
    """A client that declares 100 bytes and sends 6 holds only its own connection."""
    stalled: dict[str, Reply] = {}
    thread = threading.Thread(target=lambda: stalled.setdefault(
        "reply", server.post(b"ASK {}", "100", hold_open=True, timeout_s=30)))
    thread.start()
    time.sleep(0.5)
    other = server.get("ASK {}")
    server.expect(f"another client answered at once ({other.seconds:.1f} s)",
                  other.status == 200 and other.seconds < 5)
    thread.join(40)
    reply = stalled.get("reply")
    server.expect(f"the short body dropped with 400 within the read timeout "
                  f"({reply.status if reply else None})", reply is not None and reply.status in (400, 408))


def _parallel(server: Server, ws: Workspace) -> None:
    """While a cartesian product runs (``--timeout 4``) a trivial ASK is answered at once."""
    slow: dict[str, Reply] = {}
    thread = threading.Thread(target=lambda: slow.setdefault(
        "reply", server.post(CARTESIAN.encode(), str(len(CARTESIAN)), timeout_s=60)))
    thread.start()
    time.sleep(1.0)
    quick = server.get("ASK {}")
    server.expect(f"ASK answered during the slow query in {quick.seconds:.2f} s (status {quick.status})",
                  quick.status == 200 and quick.seconds < 3)
    thread.join(90)
    reply = slow.get("reply")
    server.expect(f"the slow query stopped by --timeout with 503 ({reply.status if reply else None}, "
                  f"{reply.seconds if reply else 0:.1f} s, {reply.body[:200] if reply else ''!r})",
                  reply is not None and reply.status == 503
                  and reply.seconds < 30)


def _service(server: Server, ws: Workspace) -> None:
    for name, text in SERVICE_SPELLINGS.items():
        reply = server.get(braces(text).format(**ws.values()))
        server.expect(f"{name}: 403 (got {reply.status})", reply.status == 403)
    got = listener_of(ws).requests
    server.expect(f"no request reached the listener ({got})", not got)


def _update(server: Server, ws: Workspace) -> None:
    body = b"DROP ALL"
    reply = server.post(body, str(len(body)), ctype="application/sparql-update")
    server.expect(f"update refused with 403 (got {reply.status})", reply.status == 403)
    form = b"update=DROP%20ALL"
    reply = server.post(form, str(len(form)), ctype="application/x-www-form-urlencoded")
    server.expect(f"update form refused with 403 (got {reply.status})", reply.status == 403)


def _probe_case(name: str, behaviour: str, talk: Callable[[Server, Workspace], None], *flags: str,
                **extra: object) -> Case:
    return Case(f"serve/{name}", "serve", (), "ok", behaviour, probe=_serve_probe(talk, *flags),
                timeout_s=120.0, **extra)  # type: ignore[arg-type]


def cases() -> list[Case]:
    return [
        _probe_case("no-cors-by-default", "no Access-Control-Allow-Origin, also on a preflight", _no_cors),
        _probe_case("cors-one-origin", "--cors ORIGIN: that origin only", _one_origin,
                    "--cors", "http://localhost:3000"),
        _probe_case("host-rebinding", "a foreign Host header: 421; localhost and IPs answered", _rebinding),
        _probe_case("content-length-negative", "400 at once", _length("-1", 400)),
        _probe_case("content-length-not-a-number", "400, no traceback on the server", _length("abc", 400)),
        _probe_case("content-length-huge", "413 at once", _length("1000000000000", 413)),
        _probe_case("content-length-missing-body", "the stalled client dropped; others answered meanwhile",
                    _short_body),
        _probe_case("parallel-during-slow-query",
                    "ASK answered while a query runs; that one 503 at --timeout",
                    _parallel, "--timeout", "4"),
        _probe_case("service-refused", "every SERVICE spelling 403, no request to the listener", _service,
                    prepare=prepare_listener, check=no_request),
        _probe_case("update-refused", "403 for an update body or form", _update),
        Case("serve/host-empty", "serve", ("serve", "--kb", "{kb}", "--port", "0", "--host", ""), "usage",
             "--host '' refused before listening anywhere"),
        Case("serve/cors-star", "serve", ("serve", "--kb", "{kb}", "--port", "0", "--cors", "*"), "usage",
             "--cors '*' refused: an origin is asked for"),
        Case("serve/timeout-negative", "serve", ("serve", "--kb", "{kb}", "--port", "0", "--timeout", "-1"),
             "usage", "one line: --timeout must be positive"),
    ]
