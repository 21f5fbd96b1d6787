"""``hiper convert LOG OUT --to FORMAT``: rewrite a sensor log as TUM, rosbag1, rosbag2 or MCAP."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from hiper_cli.commands._log_options import LOG_ARGUMENT, open_log_from_flags, with_log_flags
from hiper_cli.commands._render import JSON_OPTION, console, print_json
from hiper_cli.errors import ConfigError

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
        "16UC1", "--depth-encoding", help="Bag depth: 16UC1 (mm) or 32FC1 (m)."
    ),
    pose_as: str = typer.Option("tf", "--pose-as", help="Bag poses: tf, odometry or pose."),
    overwrite: bool = typer.Option(False, "--overwrite", help="Write a TUM folder into a non-empty folder."),
    json_out: bool = JSON_OPTION,
    log_flags: dict[str, Any] | None = None,
) -> None:
    from hiper_cli.perceive.logs.bag_writer import BagLayout
    from hiper_cli.perceive.logs.convert import CONVERT_TARGETS, convert_log

    choices = {"--to": (to, CONVERT_TARGETS), "--rgb-format": (rgb_format, ("raw", "png", "jpeg")),
               "--depth-encoding": (depth_encoding, ("16UC1", "32FC1")),
               "--pose-as": (pose_as, ("tf", "odometry", "pose"))}
    for flag, (value, allowed) in choices.items():
        if value not in allowed:
            raise ConfigError(f"{flag} {value}: unknown; expected one of {', '.join(allowed)}")
    reader = open_log_from_flags(log, **(log_flags or {}))
    pose_topic_out = {"tf": "/tf", "odometry": "/odom", "pose": "/pose"}[pose_as]
    layout = BagLayout(rgb_format=rgb_format, depth_encoding=depth_encoding, pose_as=pose_as,  # type: ignore[arg-type]
                       pose_topic=pose_topic_out)
    if json_out:
        result = convert_log(reader, out, to, layout=layout, overwrite=overwrite)
    else:
        from rich.progress import Progress

        with Progress(console=console(), transient=True) as progress:
            task = progress.add_task(f"writing {out}", total=len(reader))
            result = convert_log(reader, out, to, layout=layout, overwrite=overwrite,
                                 on_frame=lambda _: progress.advance(task))
    data = {"input": str(log), "output": result.output, "to": result.to,
            "frames_written": result.frames_written,
            "skipped": [{"source": s, "reason": r} for s, r in result.skipped]}
    if json_out:
        print_json(data)
        return
    out_console = console()
    out_console.print(f"wrote {result.frames_written} frames to {result.output} ({result.to})")
    for source, reason in result.skipped:
        out_console.print(f"[yellow]skipped[/] {source}: {reason}")


def register(app: typer.Typer) -> None:
    app.command(name="convert", help=HELP)(with_log_flags(convert))
