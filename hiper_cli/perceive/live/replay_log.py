"""``hiper replay`` as a function: a recorded log, by its path, published as a live robot."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.logs import LogOptions, open_log

__all__ = ["replay_log"]


def replay_log(log: Path, url: str, log_options: LogOptions | None = None, *, rate: float = 1.0,
               hz: float | None = None, wait_s: float = 30.0, depth_encoding: str = "32FC1",
               on_start: Callable[[int, str], None] | None = None) -> dict[str, Any]:
    """Publish ``log`` on the Zenoh endpoint of ``url`` (``replay_frames``); depth as 32FC1
    metres or 16UC1 mm. ``on_start(frames, endpoint)`` before the first frame goes out."""
    from hiper_cli.perceive.live.replay import REPLAY_LAYOUT, replay_frames
    from hiper_cli.perceive.live.rmw import parse_endpoint

    if depth_encoding not in ("32FC1", "16UC1"):
        raise ConfigError(f"--depth-encoding {depth_encoding}: expected 32FC1 or 16UC1")
    endpoint = parse_endpoint(url)
    reader = open_log(log, log_options)
    layout = replace(REPLAY_LAYOUT, depth_encoding="16UC1" if depth_encoding == "16UC1" else "32FC1")
    if on_start is not None:
        on_start(len(reader), endpoint)
    summary = replay_frames(reader, reader.info().camera, endpoint, rate=rate, hz=hz, layout=layout,
                            wait_s=wait_s)
    return summary.to_dict()
