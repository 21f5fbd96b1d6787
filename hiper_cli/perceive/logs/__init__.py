"""Sensor logs in, one interface: ``open_log(path)`` -> a ``LogReader`` of ``Frame``s.

Formats: TUM RGB-D folders, rosbag1 (``.bag``), rosbag2 folders (sqlite3 or MCAP storage)
and bare ``.mcap`` files. ``poses`` (a TUM trajectory file or a ``Trajectory``) replaces the
log's own poses for any format; ``camera`` (``CameraIntrinsics`` or a ``camera.json`` path)
replaces its intrinsics. ``LogOptions`` bundles every such choice (what the CLI's log flags set):
``open_log(path, LogOptions(preset="fr1", max_dt_s=0.01))``. The simulator's ground truth beside
a log is read by ``truth.load_truth``.

    reader = open_log("rgbd_dataset_freiburg1_xyz")
    print(reader.info().rate_hz)
    for frame in reader:          # Frames in time order, pose_id = index in the log
        ...
    print(reader.skipped)         # [(source, reason)] of frames that could not be read
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

from hiper_cli.errors import ConfigError, LogError
from hiper_cli.perceive.logs.bag_writer import BAG_KINDS, BagLayout, BagWriter
from hiper_cli.perceive.logs.base import LogInfo, StampGap
from hiper_cli.perceive.logs.formats import detect_format
from hiper_cli.perceive.logs.options import DEFAULT_MAX_DT_S, LogOptions
from hiper_cli.perceive.logs.topics import BagTopics
from hiper_cli.perceive.logs.trajectory import Trajectory, read_tum_trajectory, write_tum_trajectory
from hiper_cli.perceive.logs.tum import TUM_PRESETS, load_camera_json
from hiper_cli.perceive.logs.tum_writer import TumWriter
from hiper_cli.types import CameraIntrinsics, Frame

__all__ = [
    "BAG_KINDS",
    "TUM_PRESETS",
    "BagLayout",
    "BagTopics",
    "BagWriter",
    "LogInfo",
    "LogOptions",
    "LogReader",
    "StampGap",
    "Trajectory",
    "TumWriter",
    "describe_log",
    "detect_format",
    "load_camera_json",
    "open_log",
    "read_tum_trajectory",
    "write_tum_trajectory",
]


@runtime_checkable
class LogReader(Protocol):
    """A sensor log: ``Frame``s in time order, its length and a summary."""

    skipped: list[tuple[str, str]]

    def __iter__(self) -> Iterator[Frame]: ...

    def __len__(self) -> int: ...

    def info(self) -> LogInfo: ...

    def read_frame(self, pose_id: int) -> Frame: ...


def open_log(
    path: str | Path,
    options: LogOptions | None = None,
    *,
    poses: str | Path | Trajectory | None = None,
    camera: str | Path | CameraIntrinsics | None = None,
    max_dt_s: float = DEFAULT_MAX_DT_S,
    topics: BagTopics | None = None,
) -> LogReader:
    """Open a sensor log for reading (see the module docstring).

    ``options``: every reading choice in one value. Without it, the keywords give them
    directly: ``poses`` and ``camera`` replace the log's own, ``max_dt_s`` is the tolerance when
    associating colour, depth, camera info, detections and poses by timestamp, ``topics`` the
    bag topic and tf frame choices (ignored for TUM). Both at once is a ``ConfigError``.
    """
    path = Path(path)
    if options is not None:
        if (poses, camera, max_dt_s, topics) != (None, None, DEFAULT_MAX_DT_S, None):
            raise ConfigError("open_log: pass either LogOptions or the poses/camera/max_dt_s/topics "
                              "keywords, not both")
        poses, camera, max_dt_s, topics = (options.poses, options.intrinsics(path), options.max_dt_s,
                                           options.topics())
    kind = detect_format(path)
    trajectory = read_tum_trajectory(poses) if isinstance(poses, str | Path) else poses
    intrinsics = load_camera_json(Path(camera)) if isinstance(camera, str | Path) else camera
    if max_dt_s <= 0:
        raise LogError(f"max_dt_s must be positive, got {max_dt_s}")
    if kind == "tum":
        from hiper_cli.perceive.logs.tum import open_tum

        return open_tum(path, poses=trajectory, camera=intrinsics, max_dt_s=max_dt_s)
    from hiper_cli.perceive.logs.rosbag import open_bag

    return open_bag(path, kind, poses=trajectory, camera=intrinsics, max_dt_s=max_dt_s,
                    topics=topics or BagTopics())


def describe_log(path: str | Path, options: LogOptions | None = None, *, frames: bool = False,
                 check: bool = False) -> dict[str, Any]:
    """What ``hiper info`` shows: ``LogInfo.to_dict(frames)``; ``check`` decodes every frame
    and adds ``readable_frames`` and the ``skipped`` ones."""
    reader = open_log(path, options)
    data = reader.info().to_dict(frames=frames)
    if check:
        data["readable_frames"] = sum(1 for _ in reader)
        data["skipped"] = [{"source": s, "reason": r} for s, r in reader.skipped]
    return data
