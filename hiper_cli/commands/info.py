"""``hiper info LOG``: what a sensor log holds (frames, rate, camera, poses, detections, gaps)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from hiper_cli.commands._common import JSON_OPTION, LOG_ARGUMENT, with_log_flags
from hiper_cli.commands._render import console, print_json

if TYPE_CHECKING:
    from hiper_cli.perceive.logs import LogOptions

HELP = (
    "Show what a sensor log holds: frames, rate, duration, resolution, intrinsics, pose source, "
    "detections and stamp gaps.\n\n"
    "Example: hiper info rgbd_dataset_freiburg1_xyz --poses slam.txt --json"
)


def info(
    log: Path = LOG_ARGUMENT,
    json_out: bool = JSON_OPTION,
    frames: bool = typer.Option(False, "--frames", help="Also list every frame's stamp and pose."),
    check: bool = typer.Option(
        False, "--check", help="Decode every image and report the frames that cannot be read."
    ),
    *,
    log_options: LogOptions,
) -> None:
    from hiper_cli.perceive.logs import describe_log

    data = describe_log(log, log_options, frames=frames, check=check)
    if json_out:
        print_json(data)
        return
    from hiper_cli.commands._tables import show_log_info

    show_log_info(console(), data)


def register(app: typer.Typer) -> None:
    app.command(name="info", help=HELP)(with_log_flags(info))
