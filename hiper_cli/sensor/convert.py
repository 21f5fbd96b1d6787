"""A sensor log rewritten, by its path: in another format (``perceive.logs.convert``), or as a
TUM folder a real sensor would have recorded (``degrade``). What ``hiper convert`` runs."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.logs import LogOptions, open_log

__all__ = ["rewrite_log"]


def rewrite_log(log: Path, out: Path, log_options: LogOptions | None = None, *, to: str | None = None,
                rgb_format: str = "raw", depth_encoding: str = "16UC1", pose_as: str = "tf",
                degrade: str | None = None, seed: int = 0, pose_drift: float | None = None,
                overwrite: bool = False, on_start: Callable[[int], None] | None = None,
                on_frame: Callable[..., None] | None = None) -> dict[str, Any]:
    """Write ``log`` to ``out`` as ``to`` (tum, rosbag1, rosbag2, mcap) with the bag choices, or,
    with ``degrade`` (a sensor profile), as that sensor's TUM folder with its truth in ``out/gt``
    (``seed``; ``pose_drift`` in m per m overrides the profile's). ``on_start(frames)`` is called
    once the log is open. Returns the result's dict with the ``input`` path."""
    from hiper_cli.perceive.logs.convert import bag_layout, convert_log

    if degrade is not None:
        return _degraded(log, out, log_options, to, degrade, seed, pose_drift, overwrite, on_start, on_frame)
    if to is None:
        raise ConfigError("--to is missing; pass --to tum, rosbag1, rosbag2 or mcap (or --degrade PROFILE)")
    layout = bag_layout(to, rgb_format, depth_encoding, pose_as)
    reader = open_log(log, log_options)
    if on_start is not None:
        on_start(len(reader))
    result = convert_log(reader, out, to, layout=layout, overwrite=overwrite, on_frame=on_frame)
    return {**result.to_dict(), "input": str(log)}


def _degraded(log: Path, out: Path, log_options: LogOptions | None, to: str | None, profile_name: str,
              seed: int, pose_drift: float | None, overwrite: bool, on_start: Callable[[int], None] | None,
              on_frame: Callable[..., None] | None) -> dict[str, Any]:
    from hiper_cli.sensor import get_profile
    from hiper_cli.sensor.degrade import degrade_log

    if to not in (None, "tum"):
        raise ConfigError(f"--to {to}: --degrade writes a TUM folder; leave --to out or pass --to tum")
    profile = get_profile(profile_name)
    if pose_drift is not None:
        profile = profile.with_pose_drift(pose_drift)
    reader = open_log(log, log_options)
    if on_start is not None:
        on_start(len(reader))
    result = degrade_log(reader, out, profile, seed, overwrite=overwrite, on_frame=on_frame)
    return {**result.to_dict(), "input": str(log)}
