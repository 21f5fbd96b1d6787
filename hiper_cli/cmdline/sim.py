"""The options of ``hiper sim``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

HELP = (
    "Simulate a robot driving through a house, hospital or office: a TUM RGB-D log (rgb, depth, poses) "
    "plus ground truth in OUT/gt (instances, people tracks, per-pixel ids, noisy truth detections). A "
    "mapping phase without people comes first. --sensor records it as a real camera and pose "
    "source would (structured-light by default; ideal gives the exact render).\n\n"
    "Example: hiper sim --world hospital --seconds 60 --seed 1 -o out/hospital\n\n"
    "Several sessions of one place with changes between them: hiper sim --sessions 3 --changes 6 -o out/days"
)
Opt = typer.Option
Out = Annotated[Path, Opt("--out", "-o", help="Output folder (created; must be empty).")]
World = Annotated[str, Opt("--world", "-w", help="World preset: house, hospital or office.")]
Seconds = Annotated[float, Opt("--seconds", "-s", help="Length of the log in seconds.")]
Seed = Annotated[int, Opt("--seed", help="Seed: the same seed gives identical output.")]
RateHz = Annotated[float, Opt("--rate-hz", help="Frame rate.")]
Width = Annotated[int, Opt("--width", help="Image width in pixels.")]
Height = Annotated[int, Opt("--height", help="Image height in pixels.")]
MaxRangeM = Annotated[float, Opt("--max-range-m", help="No depth returns beyond this range.")]
MappingS = Annotated[float | None, Opt(
    "--mapping-s", help="Length of the mapping phase (no people); default a third, at most 60 s.")]
SpeedMps = Annotated[float, Opt("--speed-mps", help="Robot speed (at most 0.9 m/s).")]
DepthNoise = Annotated[bool, Opt("--depth-noise/--no-depth-noise", help="Range-dependent depth noise.")]
MissRate = Annotated[float, Opt("--miss-rate", help="Truth detector: chance to miss an object.")]
Jitter = Annotated[float, Opt("--jitter", help="Truth detector: box jitter, fraction of box size.")]
FalsePositives = Annotated[float, Opt(
    "--false-positives", help="Truth detector: random false boxes per image (mean).")]
Confusion = Annotated[float, Opt("--confusion", help="Truth detector: chance of a wrong class.")]
PngCompression = Annotated[int, Opt("--png-compression", help="PNG compression level 0-9.")]
Sensor = Annotated[str, Opt("--sensor", help=(
    "Sensor profile: structured-light, tof, stereo or ideal (exact depth with --depth-noise, exact "
    "poses); see docs/sensors.md."))]
Overwrite = Annotated[bool, Opt("--overwrite", help="Write into a non-empty output folder.")]
Sessions = Annotated[int, Opt(
    "--sessions", help="Logs of one place, each in its own odometry frame (OUT/session_K).")]
Changes = Annotated[int, Opt(
    "--changes", help="Objects moved, removed or added between sessions (truth: OUT/changes.json).")]
