"""``hiper mcp`` with the SDK's own client: it lists the tools, calls each one in-process and
over stdio against ``hiper mcp``, and gets the answers ``hiper ... --json`` prints."""

from __future__ import annotations

import json
import shutil
import sys
import tempfile
from pathlib import Path
from typing import Any

import jsonschema
import pytest
from typer.testing import CliRunner

from hiper_cli.agent import TOOLS, ToolContext, tool_named
from hiper_cli.cli import app
from hiper_cli.graph import open_kb_for_reading

mcp = pytest.importorskip("mcp", reason="the mcp extra is not installed (pip install 'hiper[mcp]')")
anyio = pytest.importorskip("anyio")

runner = CliRunner()
COUNT_QUERY = "SELECT ?class (COUNT(?i) AS ?n) WHERE { GRAPH ?g { ?i a hiper:Instance ; hiper:className ?class } } GROUP BY ?class ORDER BY ?class"  # noqa: E501


@pytest.fixture(scope="module")
def kb_path(house_kb_path: str) -> str:
    return house_kb_path


def _cli(*args: str) -> Any:
    result = runner.invoke(app, [*args, "--json"])
    assert result.exit_code == 0, result.output
    return json.loads(result.output)


def _person_uuid(kb_path: str) -> str:
    return str(_cli("query", "how long was the person in view", "--kb", kb_path)["hits"][0]["uuid"])


def _calls(kb_path: str) -> list[tuple[str, dict[str, Any]]]:
    uuid = _person_uuid(kb_path)
    return [
        ("find", {"what": "chairs"}),
        ("find", {"what": "objects", "near": "table", "sort": "last_seen", "limit": 3}),
        ("count", {"what": "chairs"}),
        ("count", {"what": "people", "since": "last 10 seconds"}),
        ("last_seen", {"what": "bottle"}),
        ("when", {"uuid": uuid}),
        ("trajectory", {"uuid": uuid}),
        ("workspace", {"center_m": [1.7, 1.9, 0.8], "size_m": 1.0}),
        ("describe", {}),
        ("features", {"classes": ["person"]}),
        ("heatmap", {"class": "person"}),
        ("sparql", {"query": COUNT_QUERY}),
        ("ask", {"question": "where was the bottle last seen"}),
    ]


def _expected(kb_path: str, name: str, args: dict[str, Any], tmp: Path) -> Any:
    """What the CLI's --json says for the same question, in the tool's result's terms."""
    kb = ["--kb", kb_path]
    if name == "find" and args.get("near"):
        return {"hits": _cli("query", "3 objects near the table last seen", *kb)["hits"]}
    if name == "find":
        return {"hits": _cli("query", "chairs", *kb)["hits"]}
    if name == "count" and "since" in args:
        return {"count": _cli("query", "how many people in the last 10 seconds", *kb)["count"]}
    if name == "count":
        return {"count": _cli("query", "how many chairs", *kb)["count"]}
    if name == "last_seen":
        return {"hit": _cli("query", "where was the bottle last seen", *kb)["hits"][0]}
    if name == "when":
        return {"time_in_view_s": _cli("query", "how long was the person in view", *kb)["duration_s"]}
    if name == "trajectory":
        from hiper_cli.query import trajectory

        with open_kb_for_reading(kb_path) as k:
            return trajectory(k, args["uuid"]).to_dict()
    if name == "workspace":
        return _cli("query", "workspace", "--center", "1.7,1.9,0.8", "--size", "1.0", *kb)
    if name == "describe":
        return _cli("describe", *kb)
    if name == "features":
        data = _cli("analyze", "features", "--class", "person", "--no-store", *kb)
        return {"classes": data["classes"]}
    if name == "heatmap":  # the CLI stores an analysis: run it on a copy
        copy = tmp / "copy.hiper"
        shutil.copytree(kb_path, copy)
        data = _cli("analyze", "heatmap", "--class", "person", "--kb", str(copy), "-o", str(tmp / "cli"))
        return {k: v for k, v in data.items() if k not in ("files", "seconds")}
    if name == "sparql":
        query = tmp / "q.rq"
        query.write_text(COUNT_QUERY)
        return {"results": _cli("query", "--sparql", str(query), *kb)}
    if name == "ask":
        return {k: v for k, v in _cli("query", args["question"], *kb).items()}
    raise AssertionError(name)


def _check(name: str, data: dict[str, Any], expected: dict[str, Any]) -> None:
    jsonschema.validate(data, tool_named(name).output_schema)
    for key, value in expected.items():
        if key in ("seconds", "plot", "stored"):
            continue
        assert data[key] == value, f"{name}.{key}"


async def _session_calls(session: Any, calls: list[tuple[str, dict[str, Any]]]) -> list[Any]:
    await session.initialize()
    listed = await session.list_tools()
    assert [t.name for t in listed.tools] == [t.name for t in TOOLS]
    for t in listed.tools:
        assert t.inputSchema["additionalProperties"] is False and t.outputSchema is not None
    return [await session.call_tool(name, args) for name, args in calls]


def _in_process(kb_path: str, calls: list[tuple[str, dict[str, Any]]]) -> list[Any]:
    from mcp.shared.memory import create_connected_server_and_client_session

    from hiper_cli.mcp import build_server

    async def main() -> list[Any]:
        with open_kb_for_reading(kb_path) as kb:
            server = build_server(ToolContext(kb, Path(tempfile.mkdtemp())))
            async with create_connected_server_and_client_session(server) as session:
                return await _session_calls(session, calls)

    return anyio.run(main)


def test_in_process_client_gets_the_cli_answers(kb_path, tmp_path):
    calls = _calls(kb_path)
    results = _in_process(kb_path, calls)
    for (name, args), result in zip(calls, results, strict=True):
        assert not result.isError, (name, result.content)
        _check(name, result.structuredContent, _expected(kb_path, name, args, tmp_path))
        assert json.loads(result.content[0].text) == result.structuredContent
    heatmap = results[[n for n, _ in calls].index("heatmap")]
    assert heatmap.content[1].type == "image" and heatmap.content[1].mimeType == "image/png"
    assert Path(heatmap.structuredContent["files"]["png"]).exists()


def test_stdio_client_against_hiper_mcp(kb_path):
    from mcp import StdioServerParameters
    from mcp.client.session import ClientSession
    from mcp.client.stdio import stdio_client

    calls = _calls(kb_path)
    params = StdioServerParameters(command=sys.executable, args=["-m", "hiper_cli", "mcp", "--kb", kb_path])

    async def main() -> tuple[list[Any], Any, Any]:
        async with stdio_client(params) as (read, write), ClientSession(read, write) as session:
            results = await _session_calls(session, calls)
            resources = await session.list_resources()
            summary = await session.read_resource("hiper://summary")  # type: ignore[arg-type]
            return results, resources, summary

    results, resources, summary = anyio.run(main)
    local = _in_process(kb_path, calls)
    for (name, _), remote, here in zip(calls, results, local, strict=True):
        assert not remote.isError, (name, remote.content)
        a, b = dict(remote.structuredContent), dict(here.structuredContent)
        if name == "heatmap":
            a.pop("files"), b.pop("files"), a.pop("seconds"), b.pop("seconds")
        if name == "features":
            a.pop("seconds"), b.pop("seconds")
        assert a == b, name
    assert {str(r.uri) for r in resources.resources} == {"hiper://vocabulary", "hiper://summary"}
    assert json.loads(summary.contents[0].text)["format"] == "hiper-describe"


@pytest.mark.parametrize(
    ("name", "args", "kind", "match"),
    [
        ("find", {"what": "chiars"}, "QueryError", "unknown class"),
        ("find", {"what": "chairs", "colour": "red"}, "invalid_arguments", "colour"),
        ("count", {"what": "chairs", "since": "the day before"}, "QueryError", "time"),
        ("when", {"uuid": "nope"}, "QueryError", "no instance"),
        ("sparql", {"query": "DELETE WHERE { ?s ?p ?o }"}, "QueryError", ""),
        ("teleport", {}, "QueryError", "no tool"),
    ],
)
def test_a_tool_error_is_a_structured_error(kb_path, name, args, kind, match):
    results = _in_process(kb_path, [(name, args)])
    assert results[0].isError
    error = results[0].structuredContent["error"]
    assert error["type"] == kind and match in error["message"]


def test_tools_formats_list_the_same_tools():
    for fmt in ("openai", "anthropic", "mcp"):
        data = _cli("tools", "--format", fmt)
        names = [d["function"]["name"] if fmt == "openai" else d["name"] for d in data]
        assert names == [t.name for t in TOOLS]
    result = runner.invoke(app, ["tools", "--format", "yaml"])
    assert result.exit_code == 2 and "expected one of openai" in result.output


def test_relative_times_are_resolved_by_the_server():
    from hiper_cli.agent.times import resolve_span_s, resolve_time

    assert resolve_time("last 10 minutes", 1000.0) == 400.0
    assert resolve_time("5 min ago", 1000.0) == 700.0
    assert resolve_time("now", 1000.0) == 1000.0
    assert resolve_time(12.5, 1000.0) == 12.5
    assert resolve_span_s("2 h") == 7200.0


def test_streamable_http_serves_the_same_tools(kb_path):
    import socket
    import subprocess
    import time

    from mcp.client import streamable_http
    from mcp.client.session import ClientSession

    # newer 1.x: streamable_http_client; older 1.x: streamablehttp_client (deprecated)
    client = getattr(streamable_http, "streamable_http_client", None) or streamable_http.streamablehttp_client

    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    proc = subprocess.Popen(
        [sys.executable, "-m", "hiper_cli", "mcp", "--kb", kb_path, "--http", f"127.0.0.1:{port}"],
        stderr=subprocess.PIPE, text=True,
    )
    try:
        assert proc.stderr is not None
        line = proc.stderr.readline()
        assert f"127.0.0.1:{port}/mcp" in line, line
        time.sleep(0.2)

        async def main() -> Any:
            async with client(f"http://127.0.0.1:{port}/mcp") as (read, write, *_), \
                    ClientSession(read, write) as session:
                await session.initialize()
                return await session.call_tool("count", {"what": "chairs"})

        result = anyio.run(main)
        assert result.structuredContent["count"] == _cli("query", "how many chairs", "--kb", kb_path)["count"]
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def test_without_the_mcp_package_the_command_says_how_to_install_it(monkeypatch):
    from hiper_cli.errors import ConfigError
    from hiper_cli.mcp import require_mcp

    monkeypatch.setitem(sys.modules, "mcp", None)
    with pytest.raises(ConfigError, match=r"pip install 'hiper\[mcp\]'"):
        require_mcp()


def test_the_tools_leave_the_knowledge_base_as_it_is(kb_path, tmp_path):
    copy = tmp_path / "kb.hiper"
    shutil.copytree(kb_path, copy)

    def state() -> Any:
        with open_kb_for_reading(str(copy)) as kb:
            envs = [e.to_dict() for e in kb.environments()]
            return kb.info()["counts"], json.dumps(envs, sort_keys=True, default=str)

    before = state()
    results = _in_process(str(copy), [("heatmap", {"class": "person"}), ("features", {}), ("describe", {})])
    assert not any(r.isError for r in results)
    assert state() == before
