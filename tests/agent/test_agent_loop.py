"""The documented agent loop (docs/examples/agent_loop.py) against a stand-in for a local
OpenAI-compatible server: the model asks for one tool call, gets its result, answers."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
from http.server import BaseHTTPRequestHandler, HTTPServer
from typing import ClassVar

from tests import REPO_ROOT
from tests.query_truth_kb import house_truth_kb

EXAMPLE = REPO_ROOT / "docs" / "examples" / "agent_loop.py"


class _FakeModel(BaseHTTPRequestHandler):
    requests: ClassVar[list[dict]] = []

    def do_POST(self) -> None:
        body = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
        _FakeModel.requests.append(body)
        if body["messages"][-1]["role"] == "tool":
            result = json.loads(body["messages"][-1]["content"])
            message = {"role": "assistant", "content": f"I count {result['count']} chairs."}
        else:
            call = {"id": "c1", "type": "function",
                    "function": {"name": "count", "arguments": json.dumps({"what": "chairs"})}}
            message = {"role": "assistant", "content": None, "tool_calls": [call]}
        data = json.dumps({"choices": [{"message": message}]}).encode()
        self.send_response(200)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)

    def log_message(self, *args: object) -> None:
        pass


def test_the_documented_agent_loop_calls_a_tool_and_answers():
    server = HTTPServer(("127.0.0.1", 0), _FakeModel)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        kb = str(house_truth_kb().path)
        url = f"http://127.0.0.1:{server.server_address[1]}/v1"
        out = subprocess.run([sys.executable, str(EXAMPLE), "--kb", kb, "--url", url, "how many chairs?"],
                             capture_output=True, text=True, timeout=120, cwd=EXAMPLE.parents[2])
    finally:
        server.shutdown()
    assert out.returncode == 0, out.stderr
    assert "-> count" in out.stdout and "I count 5 chairs." in out.stdout
    tools = _FakeModel.requests[0]["tools"]
    assert {t["function"]["name"] for t in tools} >= {"find", "count", "heatmap", "sparql"}
