"""SPARQL from the user's side: federated SERVICE in every spelling, updates, CONSTRUCT and
DESCRIBE, queries past their time limit; through ``hiper query --sparql`` and the MCP tool.

Every SERVICE case points at a local listener (``{port}``): it must get no request at all.
"""

from __future__ import annotations

import json
import subprocess
import time
from collections.abc import Callable

from tests.faults.case import Case
from tests.faults.listener import no_request, prepare_listener
from tests.faults.runner import Result, Workspace, hiper_argv

REMOTE = "<http://127.0.0.1:{port}/sparql>"
# the four-way cartesian product of the probe: minutes without a limit
CARTESIAN = "SELECT (COUNT(*) AS ?n) WHERE { ?a ?b ?c . ?d ?e ?f . ?g ?h ?i . ?j ?k ?l }"

SERVICE_SPELLINGS = {
    "service-no-space": f"SELECT * WHERE {{ SERVICE{REMOTE} {{ ?s ?p ?o }} }}",
    "service-prefixed-name": "PREFIX ex: <http://127.0.0.1:{port}/sparql> "
                             "SELECT * WHERE { SERVICE ex: { ?s ?p ?o } }",
    "service-comment-between": f"SELECT * WHERE {{ SERVICE #x\n {REMOTE} {{ ?s ?p ?o }} }}",
    "service-lower-case": f"select * where {{ service {REMOTE} {{ ?s ?p ?o }} }}",
    "service-silent": f"SELECT * WHERE {{ SERVICE SILENT {REMOTE} {{ ?s ?p ?o }} }}",
    "service-unicode-escape": f"SELECT * WHERE {{ \\u0053ERVICE {REMOTE} {{ ?s ?p ?o }} }}",
    "service-in-optional": f"SELECT * WHERE {{ ?x a ?t OPTIONAL {{ SERVICE {REMOTE} {{ ?s ?p ?o }} }} }}",
    "service-in-subquery": f"SELECT * WHERE {{ {{ SELECT * WHERE {{ SERVICE {REMOTE} {{ ?s ?p ?o }} }} }} }}",
    "service-variable": "SELECT * WHERE { BIND(<http://127.0.0.1:{port}/sparql> AS ?u) "
                        "SERVICE ?u { ?s ?p ?o } }",
    "service-in-construct": f"CONSTRUCT {{ ?s ?p ?o }} WHERE {{ SERVICE {REMOTE} {{ ?s ?p ?o }} }}",
    "service-in-ask": f"ASK {{ SERVICE {REMOTE} {{ ?s ?p ?o }} }}",
}
UPDATES = {
    "update-insert": "INSERT DATA { GRAPH <urn:x> { <urn:a> <urn:b> <urn:c> } }",
    "update-drop": "DROP ALL",
    "update-load": "LOAD <http://127.0.0.1:{port}/data.ttl>",
    "update-after-query": "SELECT * WHERE { ?s ?p ?o } ; DROP ALL",
}


def braces(text: str) -> str:
    """``text`` for a case's command line, which is filled with ``str.format``: its braces
    doubled, ``{port}`` kept."""
    return text.replace("{", "{{").replace("}", "}}").replace("{{port}}", "{port}")


def _query(text: str, *extra: str) -> tuple[str, ...]:
    return ("query", "--sparql", braces(text), "--kb", "{kb}", *extra)


def _turtle(ws: Workspace, result: Result) -> str | None:
    if result.returncode != 0:
        return None
    if "<urn:" not in result.stdout or result.stdout.lstrip().startswith("{"):
        return f"expected Turtle triples, got {result.stdout[:120]!r}"
    return None


def _took_at_most(seconds: float) -> Callable[[Workspace, Result], str | None]:
    def check(ws: Workspace, result: Result) -> str | None:
        return f"took {result.seconds:.1f} s (limit {seconds} s)" if result.seconds > seconds else None

    return check


def _mcp_probe(query: str, *flags: str, expect: str) -> Callable[[Workspace], Result]:
    """Call the MCP ``sparql`` tool over stdio; the result must be an error result naming
    ``expect`` (and, for SERVICE, the listener gets nothing)."""
    def probe(ws: Workspace) -> Result:
        text = braces(query).format(**ws.values())
        start = time.monotonic()
        proc = subprocess.Popen(hiper_argv(ws.repo, ["mcp", "--kb", str(ws.kb), *flags]), cwd=ws.root,
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True)
        messages = [
            {"jsonrpc": "2.0", "id": 1, "method": "initialize",
             "params": {"protocolVersion": "2025-06-18", "capabilities": {},
                        "clientInfo": {"name": "faults", "version": "1"}}},
            {"jsonrpc": "2.0", "method": "notifications/initialized"},
            {"jsonrpc": "2.0", "id": 2, "method": "tools/call",
             "params": {"name": "sparql", "arguments": {"query": text}}},
        ]
        assert proc.stdin is not None and proc.stdout is not None
        answer: dict[str, object] = {}
        try:
            for message in messages:
                proc.stdin.write(json.dumps(message) + "\n")
                proc.stdin.flush()
                if "id" in message:
                    while True:
                        line = proc.stdout.readline()
                        if not line:
                            break
                        reply = json.loads(line)
                        if reply.get("id") == message["id"]:
                            answer = reply
                            break
        finally:
            try:
                _, err = proc.communicate(timeout=30)  # closes stdin: the server ends
            except subprocess.TimeoutExpired:
                proc.kill()
                _, err = proc.communicate()
        seconds = time.monotonic() - start
        result = answer.get("result") or {}
        shown = json.dumps(result)[:300]
        ok = isinstance(result, dict) and result.get("isError") and expect in shown
        return Result(0 if ok else 1, shown, err + ("" if ok else f"error: expected an error result naming "
                                                                  f"{expect!r}, got {shown}\n"), seconds)

    return probe


def cases() -> list[Case]:
    out = [
        Case(f"sparql/{name}", "sparql", _query(text), "error",
             "refused from the parsed query: one line, no request reaches the listener",
             prepare=prepare_listener, check=no_request, kb="unchanged")
        for name, text in SERVICE_SPELLINGS.items()
    ]
    out += [
        Case(f"sparql/{name}", "sparql", _query(text), "error", "refused: the scene graph is read-only",
             prepare=prepare_listener, check=no_request, kb="unchanged")
        for name, text in UPDATES.items()
    ]
    out += [
        Case("sparql/construct", "sparql", _query("CONSTRUCT { ?s ?p ?o } WHERE { ?s ?p ?o } LIMIT 3"), "ok",
             "Turtle triples on stdout", check=_turtle),
        Case("sparql/describe", "sparql", _query("DESCRIBE ?s WHERE { ?s a hiper:Instance } LIMIT 1"), "ok",
             "Turtle triples on stdout", check=_turtle),
        Case("sparql/construct-json", "sparql",
             _query("CONSTRUCT { ?s ?p ?o } WHERE { ?s ?p ?o } LIMIT 3", "--json"), "ok",
             "--json: the media type and the Turtle text"),
        Case("sparql/cartesian-timeout", "sparql", _query(CARTESIAN, "--timeout", "3"), "error",
             "one line: past its time limit, after about 3 s", check=_took_at_most(20.0), timeout_s=60.0),
        Case("sparql/timeout-zero", "sparql", _query("ASK {}", "--timeout", "0"), "usage",
             "one line: --timeout must be positive", kb=None),
        Case("sparql/timeout-nan", "sparql", _query("ASK {}", "--timeout", "nan"), "usage",
             "one line: --timeout must be finite", kb=None),
        Case("sparql/with-plain-words", "sparql", ("query", "cups", "--sparql", "ASK {{}}", "--kb", "{kb}"),
             "error", "one line: one or the other"),
        Case("sparql/does-not-parse", "sparql", _query("SELECT WHERE {"), "error",
             "one line: does not parse"),
        Case("sparql/deeply-nested", "sparql", _query("SELECT * WHERE " + "{" * 3000 + "}" * 3000), "error",
             "one line: does not parse or nested too deeply"),
        Case("sparql/mcp-service", "sparql", (), "ok",
             "the MCP sparql tool answers an error result, no request reaches the listener",
             prepare=prepare_listener, check=no_request,
             probe=_mcp_probe(SERVICE_SPELLINGS["service-prefixed-name"], expect="SERVICE")),
        Case("sparql/mcp-timeout", "sparql", (), "ok", "the MCP sparql tool gives up after --timeout",
             probe=_mcp_probe(CARTESIAN, "--timeout", "3", expect="time limit"), check=_took_at_most(30.0),
             timeout_s=60.0),
    ]
    return out
