"""``hiper info LOG``: what a sensor log holds (frames, rate, camera, poses, detections, gaps)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated

import typer

from hiper_cli.cmdline import HiperTyper, Json, Log, with_log_flags
from hiper_cli.render import emit
from hiper_cli.render.perceive import show_log_info

if TYPE_CHECKING:
    from hiper_cli.perceive.logs import LogOptions

HELP = (
    "Show what a sensor log holds: frames, rate, duration, resolution, intrinsics, pose source, "
    "detections and stamp gaps.\n\n"
    "Example: hiper info rgbd_dataset_freiburg1_xyz --poses slam.txt --json"
)
Frames = Annotated[bool, typer.Option("--frames", help="Also list every frame's stamp and pose.")]
Check = Annotated[bool, typer.Option(
    "--check", help="Decode every image and report the frames that cannot be read.")]


def info(log: Log, json_out: Json = False, frames: Frames = False, check: Check = False, *,
         log_options: LogOptions) -> None:
    from hiper_cli.perceive.logs import describe_log

    emit(describe_log(log, log_options, frames=frames, check=check), json_out, show_log_info)


def register(app: HiperTyper) -> None:
    app.command(name="info", help=HELP)(with_log_flags(info))
