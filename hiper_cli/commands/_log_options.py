"""The options every command that opens a sensor log takes, and the call that opens it.

A command takes all of them by decorating itself with ``with_log_flags``; it then receives
their values as one ``log_flags`` dict for ``open_log_from_flags``:

    @with_log_flags
    def perceive(log: Path = LOG_ARGUMENT, *, log_flags: dict[str, Any], ...):
        reader = open_log_from_flags(log, **log_flags)
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from hiper_cli.errors import ConfigError

if TYPE_CHECKING:
    from hiper_cli.perceive.logs import LogReader

LOG_ARGUMENT = typer.Argument(..., help="TUM RGB-D folder, rosbag1 .bag, rosbag2 folder or .mcap file.")
POSES_OPTION = typer.Option(
    None, "--poses", help="TUM trajectory (stamp tx ty tz qx qy qz qw) replacing the log's poses."
)
CAMERA_OPTION = typer.Option(None, "--camera", help="camera.json with width, height, fx, fy, cx, cy.")
PRESET_OPTION = typer.Option(None, "--preset", help="TUM intrinsics preset: fr1, fr2, fr3 or ros.")
FX_OPTION = typer.Option(
    None, "--fx", help="Focal length x in pixels (with --fy --cx --cy --width --height)."
)
FY_OPTION = typer.Option(None, "--fy", help="Focal length y in pixels.")
CX_OPTION = typer.Option(None, "--cx", help="Principal point x in pixels.")
CY_OPTION = typer.Option(None, "--cy", help="Principal point y in pixels.")
WIDTH_OPTION = typer.Option(None, "--width", help="Image width in pixels.")
HEIGHT_OPTION = typer.Option(None, "--height", help="Image height in pixels.")
DEPTH_SCALE_OPTION = typer.Option(
    None, "--depth-scale", help="Units per metre of 16-bit depth (TUM 5000, ROS 16UC1 1000)."
)
MAX_DT_OPTION = typer.Option(0.02, "--max-dt", help="Timestamp association tolerance in seconds.")
RGB_TOPIC_OPTION = typer.Option(None, "--rgb-topic", help="Bag topic of the colour images.")
DEPTH_TOPIC_OPTION = typer.Option(None, "--depth-topic", help="Bag topic of the depth images.")
INFO_TOPIC_OPTION = typer.Option(None, "--info-topic", help="Bag topic of the colour CameraInfo.")
POSE_TOPIC_OPTION = typer.Option(
    None, "--pose-topic", help="Bag topic of the poses: /tf, an Odometry or a PoseStamped topic."
)
DETECTIONS_TOPIC_OPTION = typer.Option(
    None, "--detections-topic", help="Bag topic of vision_msgs/Detection2DArray detections."
)
MAP_FRAME_OPTION = typer.Option("map", "--map-frame", help="tf parent frame of the poses.")
CAMERA_FRAME_OPTION = typer.Option(
    None, "--camera-frame", help="tf child frame of the poses (default: the colour images' frame_id)."
)


# (parameter name, type, typer option) of every log flag, in --help order
LOG_FLAGS: tuple[tuple[str, Any, Any], ...] = (
    ("poses", Path | None, POSES_OPTION),
    ("camera", Path | None, CAMERA_OPTION),
    ("preset", str | None, PRESET_OPTION),
    ("fx", float | None, FX_OPTION),
    ("fy", float | None, FY_OPTION),
    ("cx", float | None, CX_OPTION),
    ("cy", float | None, CY_OPTION),
    ("width", int | None, WIDTH_OPTION),
    ("height", int | None, HEIGHT_OPTION),
    ("depth_scale", float | None, DEPTH_SCALE_OPTION),
    ("max_dt", float, MAX_DT_OPTION),
    ("rgb_topic", str | None, RGB_TOPIC_OPTION),
    ("depth_topic", str | None, DEPTH_TOPIC_OPTION),
    ("info_topic", str | None, INFO_TOPIC_OPTION),
    ("pose_topic", str | None, POSE_TOPIC_OPTION),
    ("detections_topic", str | None, DETECTIONS_TOPIC_OPTION),
    ("map_frame", str, MAP_FRAME_OPTION),
    ("camera_frame", str | None, CAMERA_FRAME_OPTION),
)


def with_log_flags(func: Callable[..., Any]) -> Callable[..., Any]:
    """Give a command every log flag; it receives their values as ``log_flags`` (a dict).

    The flags are appended to the command's own parameters in its signature, which is what
    typer reads, so all commands that open a log share one definition of them.
    """
    signature = inspect.signature(func, eval_str=True)
    own = [p for name, p in signature.parameters.items() if name != "log_flags"]
    flags = [
        inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=option, annotation=kind)
        for name, kind, option in LOG_FLAGS
    ]

    @functools.wraps(func)
    def command(*args: Any, **kwargs: Any) -> Any:
        log_flags = {name: kwargs.pop(name) for name, _, _ in LOG_FLAGS}
        return func(*args, log_flags=log_flags, **kwargs)

    command.__signature__ = signature.replace(parameters=[*own, *flags])  # type: ignore[attr-defined]
    return command


def open_log_from_flags(
    log: Path,
    *,
    poses: Path | None = None,
    camera: Path | None = None,
    preset: str | None = None,
    fx: float | None = None,
    fy: float | None = None,
    cx: float | None = None,
    cy: float | None = None,
    width: int | None = None,
    height: int | None = None,
    depth_scale: float | None = None,
    max_dt: float = 0.02,
    rgb_topic: str | None = None,
    depth_topic: str | None = None,
    info_topic: str | None = None,
    pose_topic: str | None = None,
    detections_topic: str | None = None,
    map_frame: str = "map",
    camera_frame: str | None = None,
) -> LogReader:
    """Build the camera and topic choices from the flags and call ``open_log``."""
    from hiper_cli.perceive.logs import TUM_PRESETS, BagTopics, detect_format, load_camera_json, open_log
    from hiper_cli.types import CameraIntrinsics

    pinhole = {"--fx": fx, "--fy": fy, "--cx": cx, "--cy": cy, "--width": width, "--height": height}
    given = [name for name, value in pinhole.items() if value is not None]
    if sum(x is not None for x in (camera, preset)) + bool(given) > 1:
        raise ConfigError("choose one of --camera, --preset or the --fx/--fy/--cx/--cy/--width/--height "
                          "flags")
    intrinsics: CameraIntrinsics | None = None
    if camera is not None:
        intrinsics = load_camera_json(camera)
    elif preset is not None:
        if preset not in TUM_PRESETS:
            raise ConfigError(f"--preset {preset}: unknown preset; expected one of {', '.join(TUM_PRESETS)}")
        intrinsics = TUM_PRESETS[preset]
    elif given:
        missing = [name for name, value in pinhole.items() if value is None]
        if missing:
            raise ConfigError(f"camera flags: missing {' '.join(missing)}; give all of "
                              "--fx --fy --cx --cy --width --height, or --camera camera.json")
        intrinsics = CameraIntrinsics(width=int(width or 0), height=int(height or 0), fx=float(fx or 0),
                                      fy=float(fy or 0), cx=float(cx or 0), cy=float(cy or 0))
    if intrinsics is None and depth_scale is not None and detect_format(log) == "tum":
        from hiper_cli.perceive.logs.tum import tum_camera

        intrinsics = tum_camera(log)[0]
    if intrinsics is not None and depth_scale is not None:
        from dataclasses import replace

        intrinsics = replace(intrinsics, depth_scale=depth_scale)
    topics = BagTopics(
        rgb_topic=rgb_topic, depth_topic=depth_topic, info_topic=info_topic, pose_topic=pose_topic,
        detections_topic=detections_topic, map_frame=map_frame, camera_frame=camera_frame,
        depth_scale=1000.0 if depth_scale is None else depth_scale,
    )
    return open_log(log, poses=poses, camera=intrinsics, max_dt_s=max_dt, topics=topics)
