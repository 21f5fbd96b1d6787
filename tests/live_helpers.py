"""Helpers of the live-mode tests: free ports, hiper processes, the instances of a knowledge base."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
FIXTURE = ROOT / "fixtures" / "house_small"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def hiper(*args: str, stdout: int | None = subprocess.PIPE) -> subprocess.Popen[str]:
    """``hiper ARGS`` of this checkout in a child process."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), "COLUMNS": "200"}
    return subprocess.Popen([sys.executable, "-m", "hiper_cli", *args], cwd=ROOT, env=env, text=True,
                            stdout=stdout, stderr=subprocess.STDOUT)


def wait_listening(port: int, timeout_s: float = 60.0) -> None:
    """Until something accepts TCP connections on ``port`` (a hiper process listening there)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.1)
    raise TimeoutError(f"nothing listens on port {port} after {timeout_s} s")


def instances(kb: Path, env: str | None = None) -> list[tuple[str, str, np.ndarray]]:
    """(layer, class, centre) of every live instance of ``env`` (default: the only one), sorted."""
    from hiper_cli.graph import open_kb_for_reading

    with open_kb_for_reading(str(kb)) as knowledge:
        envs = [d["name"] for d in knowledge.docs.find(type="environment")]
        world = knowledge.load_world(knowledge.environment(env or envs[0]))
    rows = [(layer, inst.class_name, np.asarray(inst.box.center_m))
            for layer in ("background", "foreground") for inst in world.layer(layer).values()]
    return sorted(rows, key=lambda r: (r[0], r[1], *np.round(r[2], 2)))
