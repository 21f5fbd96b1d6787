"""``hiper replay LOG zenoh://...``: publish a recorded log as a live ROS 2 robot on rmw_zenoh."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from hiper_cli.cmdline import HiperTyper, Json, with_log_flags
from hiper_cli.render import console, emit
from hiper_cli.render.perceive import show_replay_start, show_replayed

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
                   depth_encoding: Depth = "32FC1", as_json: Json = False, *,
                   log_options: LogOptions) -> None:
    """Publish a log's frames on Zenoh as a ROS 2 robot running rmw_zenoh would, at the log's rate.

    Colour and depth images, CameraInfo and the pose on /tf go out on the topics hiper perceive
    zenoh:// reads by default (realsense-ros names), with rmw_zenoh's key expressions, CDR
    payloads and attachments. It listens on the endpoint when it is free, else connects to it.

    Example: hiper replay fixtures/house_small zenoh://tcp/127.0.0.1:7447 --hz 30
    """
    from hiper_cli.perceive.live.replay_log import replay_log

    start = None if as_json else lambda frames, endpoint: show_replay_start(console(), log, frames, endpoint)
    data = replay_log(log, url, log_options, rate=rate, hz=hz, wait_s=wait, depth_encoding=depth_encoding,
                      on_start=start)
    emit(data, as_json, show_replayed)


def register(app: HiperTyper) -> None:
    app.command("replay")(with_log_flags(replay_command))
