"""Every log flag once: a command that opens a sensor log receives them as one ``LogOptions``.

A command that opens a sensor log decorates itself with ``with_log_flags``; typer then shows
every log flag in its ``--help`` and the command receives them as one ``LogOptions``:

    def info(log: Path = LOG_ARGUMENT, *, log_options: LogOptions) -> None:
        reader = open_log(log, log_options)
    app.command("info")(with_log_flags(info))
"""

from __future__ import annotations

import functools
import inspect
import typing
from collections.abc import Callable
from pathlib import Path
from typing import Any

import typer

__all__ = ["LOG_FLAGS", "with_log_flags"]

# LogOptions field -> (type, default, flags, help), in --help order. Typer needs them when the
# CLI starts, before the library is imported; tests/commands/test_cli_common.py checks they match LogOptions.
LOG_FLAGS: dict[str, tuple[Any, Any, tuple[str, ...], str]] = {
    "poses": (Path | None, None, ("--poses",),
              "TUM trajectory (stamp tx ty tz qx qy qz qw) replacing the log's poses."),
    "camera": (Path | None, None, ("--camera",), "camera.json with width, height, fx, fy, cx, cy."),
    "preset": (str | None, None, ("--preset",), "TUM intrinsics preset: fr1, fr2, fr3 or ros."),
    "fx_px": (float | None, None, ("--fx",),
              "Focal length x in pixels (with --fy --cx --cy --width --height)."),
    "fy_px": (float | None, None, ("--fy",), "Focal length y in pixels."),
    "cx_px": (float | None, None, ("--cx",), "Principal point x in pixels."),
    "cy_px": (float | None, None, ("--cy",), "Principal point y in pixels."),
    "width_px": (int | None, None, ("--width",), "Image width in pixels."),
    "height_px": (int | None, None, ("--height",), "Image height in pixels."),
    "depth_scale": (float | None, None, ("--depth-scale",),
                    "Units per metre of 16-bit depth (TUM 5000, ROS 16UC1 1000)."),
    "max_dt_s": (float, 0.02, ("--max-dt-s", "--max-dt"), "Timestamp association tolerance in seconds."),
    "rgb_topic": (str | None, None, ("--rgb-topic",), "Bag topic of the colour images."),
    "depth_topic": (str | None, None, ("--depth-topic",), "Bag topic of the depth images."),
    "info_topic": (str | None, None, ("--info-topic",), "Bag topic of the colour CameraInfo."),
    "pose_topic": (str | None, None, ("--pose-topic",),
                   "Bag topic of the poses: /tf, an Odometry or a PoseStamped topic."),
    "detections_topic": (str | None, None, ("--detections-topic",),
                         "Bag topic of vision_msgs/Detection2DArray detections."),
    "map_frame": (str, "map", ("--map-frame",), "tf parent frame of the poses."),
    "camera_frame": (str | None, None, ("--camera-frame",),
                     "tf child frame of the poses (default: the colour images' frame_id)."),
}


def _log_parameters() -> list[inspect.Parameter]:
    return [
        inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, annotation=kind,
                          default=typer.Option(default, *flags, help=help))
        for name, (kind, default, flags, help) in LOG_FLAGS.items()
    ]


def with_log_flags(func: Callable[..., Any]) -> Callable[..., Any]:
    """Give a command every log flag; it receives their values as ``log_options`` (``LogOptions``).

    The flags are appended to the command's own parameters in the signature typer reads, so
    all commands that open a log share this one definition of them.
    """
    # ``LogOptions`` may be imported for type checking only: resolve it to ``Any`` here.
    hints = typing.get_type_hints(func, localns={"LogOptions": Any}, include_extras=True)
    signature = inspect.signature(func)
    own = [p.replace(annotation=hints.get(name, p.annotation))
           for name, p in signature.parameters.items() if name != "log_options"]

    @functools.wraps(func)
    def command(*args: Any, **kwargs: Any) -> Any:
        from hiper_cli.perceive.logs.options import LogOptions

        values = {name: kwargs.pop(name) for name in LOG_FLAGS}
        return func(*args, log_options=LogOptions(**values), **kwargs)

    parameters = [*own, *_log_parameters()]
    command.__signature__ = signature.replace(parameters=parameters)  # type: ignore[attr-defined]
    command.__annotations__ = {p.name: p.annotation for p in parameters} | {"return": hints.get("return")}
    return command
