"""``hiper convert LOG OUT --to FORMAT``: rewrite a sensor log as TUM, rosbag1, rosbag2 or MCAP."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from hiper_cli.commands._common import JSON_OPTION, LOG_ARGUMENT, with_log_flags
from hiper_cli.commands._render import console, frame_progress, print_json, safe_text

if TYPE_CHECKING:
    from hiper_cli.perceive.logs import LogOptions

HELP = (
    "Rewrite a sensor log as a TUM RGB-D folder, a rosbag1 .bag, a rosbag2 (sqlite3) folder or an "
    "MCAP bag, with the poses (also those given by --poses) and detections.\n\n"
    "Example: hiper convert rgbd_dataset_freiburg1_xyz fr1_xyz.bag --to rosbag1"
)

OUT_ARGUMENT = typer.Argument(..., help="Output path (a folder for tum, rosbag2 and mcap; a .bag file).")


def convert(
    log: Path = LOG_ARGUMENT,
    out: Path = OUT_ARGUMENT,
    to: str = typer.Option(..., "--to", help="Output format: tum, rosbag1, rosbag2 or mcap."),
    rgb_format: str = typer.Option("raw", "--rgb-format", help="Bag colour images: raw, png or jpeg."),
    depth_encoding: str = typer.Option(
        "16UC1", "--depth-encoding", help="Bag depth: 16UC1 (mm) or 32FC1 (m)."),
    pose_as: str = typer.Option("tf", "--pose-as", help="Bag poses: tf, odometry or pose."),
    overwrite: bool = typer.Option(False, "--overwrite", help="Write a TUM folder into a non-empty folder."),
    json_out: bool = JSON_OPTION,
    *,
    log_options: LogOptions,
) -> None:
    from hiper_cli.perceive.logs import open_log
    from hiper_cli.perceive.logs.convert import bag_layout, convert_log

    layout = bag_layout(to, rgb_format, depth_encoding, pose_as)
    reader = open_log(log, log_options)
    screen = console()
    with frame_progress(f"writing {safe_text(out)}", screen, enabled=not json_out, total=len(reader)) as bar:
        result = convert_log(reader, out, to, layout=layout, overwrite=overwrite,
                             on_frame=bar.advance if bar else None)
    if json_out:
        print_json({**result.to_dict(), "input": str(log)})
        return
    screen.print(f"wrote {result.frames_written} frames to {safe_text(result.output)} "
                 f"({safe_text(result.to)})")
    for source, reason in result.skipped:
        screen.print(f"[yellow]skipped[/] {safe_text(source)}: {safe_text(reason)}")


def register(app: typer.Typer) -> None:
    app.command(name="convert", help=HELP)(with_log_flags(convert))
