"""``hiper replay LOG zenoh://...``: publish a recorded log as a live ROS 2 robot on rmw_zenoh."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from hiper_cli.commands._common import JSON_OPTION, with_log_flags
from hiper_cli.commands._render import console, print_json, safe_text

if TYPE_CHECKING:
    from hiper_cli.perceive.logs import LogOptions

__all__ = ["register"]

Log = Annotated[Path, typer.Argument(help="Sensor log: TUM folder, .bag, rosbag2 folder or .mcap.")]
Url = Annotated[str, typer.Argument(
    help="Where to publish: zenoh://tcp/HOST:PORT (zenoh:// = 127.0.0.1:7447).")]
Rate = Annotated[float, typer.Option(
    "--rate", help="Speed factor on the log's own timing (2 = twice as fast).")]
Hz = Annotated[float | None, typer.Option(
    "--hz", help="Publish at this frame rate instead of the log's timing.")]
Wait = Annotated[float, typer.Option("--wait", help="Seconds to wait for the endpoint to answer.")]
Depth = Annotated[str, typer.Option("--depth-encoding", help="Depth images as 32FC1 metres or 16UC1 mm.")]


def replay_command(log: Log, url: Url, rate: Rate = 1.0, hz: Hz = None, wait: Wait = 30.0,
                   depth_encoding: Depth = "32FC1", as_json: bool = JSON_OPTION, *,
                   log_options: LogOptions) -> None:
    """Publish a log's frames on Zenoh as a ROS 2 robot running rmw_zenoh would, at the log's rate.

    Colour and depth images, CameraInfo and the pose on /tf go out on the topics hiper perceive
    zenoh:// reads by default (realsense-ros names), with rmw_zenoh's key expressions, CDR
    payloads and attachments. It listens on the endpoint when it is free, else connects to it.

    Example: hiper replay fixtures/house_small zenoh://tcp/127.0.0.1:7447 --hz 30
    """
    from dataclasses import replace

    from hiper_cli.errors import ConfigError
    from hiper_cli.perceive.live.replay import REPLAY_LAYOUT, replay_frames
    from hiper_cli.perceive.live.rmw import parse_endpoint
    from hiper_cli.perceive.logs import open_log

    if depth_encoding not in ("32FC1", "16UC1"):
        raise ConfigError(f"--depth-encoding {depth_encoding}: expected 32FC1 or 16UC1")
    endpoint = parse_endpoint(url)
    reader = open_log(log, log_options)
    layout = replace(REPLAY_LAYOUT, depth_encoding="16UC1" if depth_encoding == "16UC1" else "32FC1")
    out = console()
    if not as_json:
        out.print(f"replaying {safe_text(log)} ({len(reader)} frames) on zenoh://{safe_text(endpoint)}")
    summary = replay_frames(reader, reader.info().camera, endpoint, rate=rate, hz=hz, layout=layout,
                            wait_s=wait)
    if as_json:
        print_json(summary.to_dict())
    else:
        out.print(f"published {summary.frames} frames in {summary.seconds:.1f} s ({summary.how}); "
                  f"{summary.late_frames} late")


def register(app: typer.Typer) -> None:
    app.command("replay")(with_log_flags(replay_command))
