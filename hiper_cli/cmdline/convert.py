"""The options of ``hiper convert``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

__all__ = [
           "HELP",
           "Degrade",
           "DepthEncoding",
           "Out",
           "Overwrite",
           "PoseAs",
           "PoseDrift",
           "RgbFormat",
           "Seed",
           "To",
]

HELP = (
    "Rewrite a sensor log as a TUM RGB-D folder, a rosbag1 .bag, a rosbag2 (sqlite3) folder or an "
    "MCAP bag, with the poses (also those given by --poses) and detections. With --degrade PROFILE "
    "(structured-light, tof, stereo, ideal) it writes a TUM folder as that sensor would have recorded "
    "the log: depth noise, shadows, flying pixels, dropouts, misregistered, blurred JPEG colour and "
    "drifting poses, with the exact trajectory in OUT/gt/groundtruth.txt.\n\n"
    "Example: hiper convert rgbd_dataset_freiburg1_xyz fr1_xyz.bag --to rosbag1\n\n"
    "Example: hiper convert ../shared/worlds/bookstore out/bookstore-sl --degrade structured-light --seed 1"
)
Out = Annotated[Path, typer.Argument(help="Output path (a folder for tum, rosbag2 and mcap; a .bag file).")]
To = Annotated[str | None, typer.Option(
    "--to", help="Output format: tum, rosbag1, rosbag2 or mcap (tum with --degrade).")]
RgbFormat = Annotated[str, typer.Option("--rgb-format", help="Bag colour images: raw, png or jpeg.")]
DepthEncoding = Annotated[str, typer.Option("--depth-encoding", help="Bag depth: 16UC1 (mm) or 32FC1 (m).")]
PoseAs = Annotated[str, typer.Option("--pose-as", help="Bag poses: tf, odometry or pose.")]
Overwrite = Annotated[bool, typer.Option("--overwrite", help="Write a TUM folder into a non-empty folder.")]
Degrade = Annotated[str | None, typer.Option(
    "--degrade", help="Sensor profile to record the log with: structured-light, tof, stereo, ideal.")]
Seed = Annotated[int, typer.Option("--seed", help="With --degrade: the same seed gives identical output.")]
PoseDrift = Annotated[float | None, typer.Option(
    "--pose-drift", help="With --degrade: pose drift in m per m travelled (0 = exact poses; "
    "default the profile's 0.005).")]
