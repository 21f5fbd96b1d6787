"""What hiper prints of user or stored text shows it as text: rich markup and emoji codes
literal, terminal escape sequences and control characters removed (``safe_text``); SPARQL
safety decided on the parsed query; the SPARQL endpoint's Host allow-list."""

from __future__ import annotations

import time

import pytest
from typer.testing import CliRunner

from hiper_cli.cli import app
from hiper_cli.errors import QueryError
from hiper_cli.graph.sparql_safety import readonly_form, run_with_timeout
from hiper_cli.render import safe_text
from hiper_cli.serve.endpoint import allowed_hosts, host_allowed

runner = CliRunner()
OSC = "\x1b]0;pwned\x07"
HOSTILE = f"[/] [bold]x[/bold] :x: {OSC}\x1b[31mred\x9b2J\x00end"


@pytest.mark.parametrize(("text", "shown"), [
    ("[bold]x[/bold]", "[bold]x[/bold]"),
    ("[/]", "[/]"),
    (":x:", ":x:"),
    (f"a{OSC}b", "ab"),
    ("\x1b]8;;http://evil.example\x1b\\link\x1b]8;;\x1b\\", "link"),
    ("c\x1b[31mred\x1b[0m", "cred"),
    ("tab\tand\nnewline\x07\x00\x7f", "tab\tand\nnewline"),
    ("lone \ud800 surrogate", "lone ? surrogate"),
])
def test_safe_text_prints_as_itself(text, shown):
    from rich.console import Console

    console = Console(record=True, width=200, highlight=False, emoji=False, color_system=None)
    console.print(safe_text(text), end="")
    assert console.export_text() == shown.expandtabs(8)  # rich expands tabs
    assert safe_text(text, markup=False) == shown


def _clean(output: str) -> None:
    assert not [c for c in output if (ord(c) < 32 and c not in "\n\t") or 0x7f <= ord(c) < 0xa0], output
    assert "\u274c" not in output  # ':x:' as an emoji


@pytest.mark.parametrize("args", [
    ["query", HOSTILE, "--kb", "{missing}"],
    ["kb", "info", "--kb", "{missing}"],
    ["describe", "--kb", "{missing}"],
    ["info", "{missing}"],
    ["perceive", "{missing}", "--kb", "{tmp}/new.hiper"],
    ["import", "{missing}", "--kb", "{tmp}/new.hiper"],
    ["export", "{tmp}/out.json", "--kb", "{missing}"],
    ["analyze", "features", "--kb", "{missing}"],
    ["query", "--sparql", "SELECT " + HOSTILE, "--kb", "{missing}"],
])
def test_error_lines_show_hostile_text_as_text(tmp_path, args):
    missing = str(tmp_path / HOSTILE.replace("/", "|").replace("\x00", ""))
    argv = [a.replace("{missing}", missing).replace("{tmp}", str(tmp_path)) for a in args]
    result = runner.invoke(app, argv)
    assert result.exit_code != 0
    lines = [ln for ln in result.output.splitlines() if ln.startswith("error:")]
    assert len(lines) == 1, result.output
    _clean(result.output)
    assert ":x:" in lines[0] or "SPARQL" in lines[0]


@pytest.mark.parametrize("query", [
    "SELECT * WHERE { SERVICE<http://127.0.0.1:9/sparql> { ?s ?p ?o } }",
    "PREFIX ex: <http://127.0.0.1:9/sparql> SELECT * WHERE { SERVICE ex: { ?s ?p ?o } }",
    "SELECT * WHERE { SERVICE # a comment\n <http://127.0.0.1:9/> { ?s ?p ?o } }",
    "SELECT * WHERE { \\u0053ERVICE <http://127.0.0.1:9/> { ?s ?p ?o } }",
    "ASK { OPTIONAL { SERVICE SILENT ?u { ?s ?p ?o } } }",
])
def test_service_refused_from_the_parse_tree(query):
    with pytest.raises(QueryError, match="SERVICE"):
        readonly_form(query)


def test_forms_and_updates():
    assert readonly_form("CONSTRUCT { ?s ?p ?o } WHERE { ?s ?p ?o } LIMIT 3") == "CONSTRUCT"
    assert readonly_form("DESCRIBE <urn:x>") == "DESCRIBE"
    assert readonly_form("ASK {}") == "ASK"
    assert readonly_form("SELECT ?s WHERE { ?s ?p 'service' }") == "SELECT"  # the word, not the pattern
    with pytest.raises(QueryError, match="update refused"):
        readonly_form("DROP ALL")
    with pytest.raises(QueryError, match="does not parse"):
        readonly_form("SELECT WHERE {")


def test_run_with_timeout_gives_up():
    start = time.monotonic()
    with pytest.raises(QueryError, match=r"time limit of 0\.2 s"):
        run_with_timeout(lambda: time.sleep(5), 0.2)
    assert time.monotonic() - start < 2
    assert run_with_timeout(lambda: 7, 1.0) == 7
    with pytest.raises(ZeroDivisionError):
        run_with_timeout(lambda: 1 / 0, 1.0)


def test_host_allow_list():
    loopback = allowed_hosts("127.0.0.1")
    assert host_allowed("127.0.0.1:7879", loopback)
    assert host_allowed("localhost:7879", loopback)
    assert host_allowed("[::1]:7879", loopback)
    assert not host_allowed("attacker.example:7879", loopback)
    assert not host_allowed(None, loopback)
    assert host_allowed("robot.lan", allowed_hosts("127.0.0.1", ["robot.lan"]))


def test_parsing_is_safe_from_many_threads():
    """rdflib's grammar is not thread-safe; a threaded server parses under a lock (without it,
    concurrent parses fail with TypeError and good queries were refused)."""
    import threading

    errors: list[str] = []

    def parse(query: str) -> None:
        try:
            readonly_form(query)
        except QueryError as err:
            errors.append(str(err))

    threads = [threading.Thread(target=parse, args=(q,))
               for q in ["SELECT (COUNT(*) AS ?n) WHERE { ?a ?b ?c . ?d ?e ?f }", "ASK {}"] * 10]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
