"""An agent loop against a local OpenAI-compatible server (llama.cpp ``llama-server``, Ollama,
vLLM, ...) that answers a question with hiper's tools. Standard library only; not run in CI.

    python docs/examples/agent_loop.py --kb house.hiper --url http://127.0.0.1:8080/v1 \
        --model qwen2.5-7b-instruct "where was the bottle last seen, and how long ago?"
"""

from __future__ import annotations

import argparse
import json
import urllib.request

from hiper_cli.agent import ToolContext, call_tool, tool_schemas
from hiper_cli.graph import open_kb_for_reading

SYSTEM = (
    "You answer questions about a robot's scene memory with the tools given. Give times as the "
    "tools return them ('ago' fields); never compute dates yourself. Positions are metres, map frame."
)


def chat(url: str, model: str, messages: list[dict], tools: list[dict]) -> dict:
    body = json.dumps({"model": model, "messages": messages, "tools": tools, "temperature": 0}).encode()
    request = urllib.request.Request(f"{url}/chat/completions", body, {"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=300) as response:
        return json.loads(response.read())["choices"][0]["message"]


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("question")
    parser.add_argument("--kb", required=True)
    parser.add_argument("--url", default="http://127.0.0.1:8080/v1")
    parser.add_argument("--model", default="local")
    parser.add_argument("--max-turns", type=int, default=6)
    args = parser.parse_args()
    tools = tool_schemas("openai")
    messages: list[dict] = [{"role": "system", "content": SYSTEM}, {"role": "user", "content": args.question}]
    with open_kb_for_reading(args.kb) as kb:
        ctx = ToolContext(kb)
        for _ in range(args.max_turns):
            reply = chat(args.url, args.model, messages, tools)
            messages.append(reply)
            calls = reply.get("tool_calls") or []
            if not calls:
                print(reply.get("content", ""))
                return
            for call in calls:
                fn = call["function"]
                result = call_tool(ctx, fn["name"], json.loads(fn.get("arguments") or "{}"))
                print(f"-> {fn['name']}({fn.get('arguments')}) {'error' if result.is_error else 'ok'}")
                content = json.dumps(result.data)
                messages.append({"role": "tool", "tool_call_id": call["id"], "content": content})
    print("no final answer after", args.max_turns, "turns")


if __name__ == "__main__":
    main()
