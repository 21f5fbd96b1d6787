"""``hiper convert LOG OUT --to FORMAT``: rewrite a sensor log as TUM, rosbag1, rosbag2 or MCAP.

``--degrade PROFILE`` writes it instead as a TUM folder seen by a real sensor (``hiper_cli.sensor``).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from hiper_cli.commands._common import JSON_OPTION, LOG_ARGUMENT, with_log_flags
from hiper_cli.commands._render import console, frame_progress, print_json, safe_text
from hiper_cli.errors import ConfigError

if TYPE_CHECKING:
    from hiper_cli.perceive.logs import LogOptions

HELP = (
    "Rewrite a sensor log as a TUM RGB-D folder, a rosbag1 .bag, a rosbag2 (sqlite3) folder or an "
    "MCAP bag, with the poses (also those given by --poses) and detections. With --degrade PROFILE "
    "(structured-light, tof, stereo, ideal) it writes a TUM folder as that sensor would have recorded "
    "the log: depth noise, shadows, flying pixels, dropouts, misregistered, blurred JPEG colour and "
    "drifting poses, with the exact trajectory in OUT/gt/groundtruth.txt.\n\n"
    "Example: hiper convert rgbd_dataset_freiburg1_xyz fr1_xyz.bag --to rosbag1\n\n"
    "Example: hiper convert ../shared/worlds/bookstore out/bookstore-sl --degrade structured-light --seed 1"
)

OUT_ARGUMENT = typer.Argument(..., help="Output path (a folder for tum, rosbag2 and mcap; a .bag file).")


def convert(
    log: Path = LOG_ARGUMENT,
    out: Path = OUT_ARGUMENT,
    to: str | None = typer.Option(
        None, "--to", help="Output format: tum, rosbag1, rosbag2 or mcap (tum with --degrade)."),
    rgb_format: str = typer.Option("raw", "--rgb-format", help="Bag colour images: raw, png or jpeg."),
    depth_encoding: str = typer.Option(
        "16UC1", "--depth-encoding", help="Bag depth: 16UC1 (mm) or 32FC1 (m)."),
    pose_as: str = typer.Option("tf", "--pose-as", help="Bag poses: tf, odometry or pose."),
    overwrite: bool = typer.Option(False, "--overwrite", help="Write a TUM folder into a non-empty folder."),
    degrade: str | None = typer.Option(
        None, "--degrade", help="Sensor profile to record the log with: structured-light, tof, stereo, "
        "ideal."),
    seed: int = typer.Option(0, "--seed", help="With --degrade: the same seed gives identical output."),
    pose_drift: float | None = typer.Option(
        None, "--pose-drift", help="With --degrade: pose drift in m per m travelled (0 = exact poses; "
        "default the profile's 0.005)."),
    json_out: bool = JSON_OPTION,
    *,
    log_options: LogOptions,
) -> None:
    from hiper_cli.perceive.logs import open_log
    from hiper_cli.perceive.logs.convert import bag_layout, convert_log

    if degrade is not None:
        _convert_degraded(log, out, degrade, to, seed, pose_drift, overwrite, json_out, log_options)
        return
    if to is None:
        raise ConfigError("--to is missing; pass --to tum, rosbag1, rosbag2 or mcap (or --degrade PROFILE)")
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


def _convert_degraded(log: Path, out: Path, profile_name: str, to: str | None, seed: int,
                      pose_drift: float | None, overwrite: bool, json_out: bool,
                      log_options: LogOptions) -> None:
    from hiper_cli.perceive.logs import open_log
    from hiper_cli.sensor import get_profile
    from hiper_cli.sensor.degrade import degrade_log

    if to not in (None, "tum"):
        raise ConfigError(f"--to {to}: --degrade writes a TUM folder; leave --to out or pass --to tum")
    profile = get_profile(profile_name)
    if pose_drift is not None:
        profile = profile.with_pose_drift(pose_drift)
    reader = open_log(log, log_options)
    screen = console()
    title = f"degrading to {safe_text(out)}"
    with frame_progress(title, screen, enabled=not json_out, total=len(reader)) as bar:
        result = degrade_log(reader, out, profile, seed, overwrite=overwrite,
                             on_frame=bar.advance if bar else None)
    if json_out:
        print_json({**result.to_dict(), "input": str(log)})
        return
    err = result.pose_error
    screen.print(f"wrote {result.convert.frames_written} frames to {safe_text(out)} "
                 f"as a {profile.name} sensor "
                 f"(seed {seed}); pose error RMS {err['rms_m']:.3f} m, final {err['final_m']:.3f} m; "
                 f"truth in {safe_text(out)}/gt")
    for source, reason in result.convert.skipped:
        screen.print(f"[yellow]skipped[/] {safe_text(source)}: {safe_text(reason)}")


def register(app: typer.Typer) -> None:
    app.command(name="convert", help=HELP)(with_log_flags(convert))
